"""What a file must hold to be a recording: the reader's third layer.

The ``/rsstp/*`` channels (one per topic, with their schemas, encodings and a ``1.x``
version), the ``rsstp`` metadata record, and the ``scenario.toml`` attachment agreeing with the
``/rsstp/scenario`` message and the metadata (``schemas/README.md`` is the contract).

The reader's layers, each importing only those below it: the container
(:mod:`rsstp_replay.reader._container`: the file's records, its chunk records decompressed and
CRC-checked), the chunks (:mod:`rsstp_replay.reader._chunks`: the messages inside them), the
contract (this module) and the recording (:mod:`rsstp_replay.reader.recording`). Opening a
recording goes down them once: :func:`~rsstp_replay.open_recording` takes what
:func:`~rsstp_replay.reader._container.open_container` found to :func:`check_file`, which reads the
scenario message (and, for a file without statistics, the message counts) through the chunks
layer, which reads the chunk records through the container. No call goes back up. After
that, :class:`~rsstp_replay.reader.recording.Recording` reads messages through
:meth:`CheckedFile.chunks`, down the same way.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Generator, Sequence
from contextlib import closing
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import numpy.typing as npt

from rsstp_format.records import (
    RecordFormatError,
    ScenarioMessage,
    decode,
    decode_many,
)
from rsstp_format.schemas import (
    ATTACHMENT_NAME,
    BODY_TOPICS,
    MESSAGE_ENCODING,
    METADATA_CHECKSUM_KEY,
    METADATA_CHECKSUM_SINCE,
    METADATA_KEYS,
    METADATA_NAME,
    READ_MAJORS,
    SCHEMA_ENCODING,
    STEP_NS,
    TOPICS,
    check_schema_version,
    metadata_checksum,
    parse_version,
    version_refusal,
)
from rsstp_replay.errors import CorruptRecording, ForeignRecording, UnsupportedVersion
from rsstp_replay.reader._chunks import Messages, count_messages, topic_chunks, topics_chunks
from rsstp_replay.reader._container import ChunkRef, Container
from rsstp_replay.reader._decode import body_reader
from rsstp_sim.errors import ScenarioError
from rsstp_sim.scenario import AnyScenario, parse_scenario

__all__ = ["CheckedFile", "check_file"]

_Ints = npt.NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class CheckedFile:
    """A file that holds a recording, as :func:`check_file` found it: its channels by topic,
    schema versions, metadata (``metadata_verified``: by its checksum; False for a file older
    than the checksum), message counts per topic (an unfinished file's cut at
    ``limit_ns``, its last recovered step), the last step, and the scenario. It reads the
    messages of a topic chunk by chunk for :class:`~rsstp_replay.reader.recording.Recording`."""

    container: Container
    channels: dict[str, int]
    schema_versions: dict[str, str]
    metadata: dict[str, str]
    metadata_verified: bool
    topic_counts: dict[str, int]
    limit_ns: int | None
    n_steps: int
    scenario_record: ScenarioMessage
    scenario: AnyScenario
    topics: dict[str, str]
    """Topic -> schema name, of the recording's body (:data:`BODY_TOPICS`)."""

    @property
    def body(self) -> str:
        return self.scenario.body

    def chunks(
        self, topic: str, *, step: int | None = None
    ) -> Generator[tuple[ChunkRef, bytes, list[memoryview], _Ints], None, None]:
        """The chunks with messages of ``topic`` (or only those around ``step``'s log time),
        each with its records, those messages' bytes and their log times."""
        return topic_chunks(self.container, self.channels[topic], self.limit_ns, step=step)

    def chunks_of(
        self, topics: Sequence[str], *, step: int | None = None
    ) -> Generator[tuple[ChunkRef, bytes, list[Messages]], None, None]:
        """The chunks with messages of any of ``topics`` (or only those around ``step``'s log
        time), each read once, with its records and, topic by topic, its
        :class:`~rsstp_replay.reader._chunks.Messages`."""
        channels = [self.channels[topic] for topic in topics]
        return topics_chunks(self.container, channels, self.limit_ns, step=step)

    def decode_one(self, topic: str, part: memoryview, log_time: int, ref: ChunkRef) -> Any:
        """The record of one message of ``topic``."""
        return _decode_one(self.container.path, self.topics[topic], topic, part, log_time, ref)

    def decode_many(
        self, topic: str, parts: list[memoryview], log_times: _Ints, ref: ChunkRef
    ) -> list[Any]:
        """The records of a chunk's messages of ``topic``, decoded at once."""
        path = self.container.path
        return _decode_many(path, self.topics[topic], topic, parts, log_times, ref)


def check_file(container: Container) -> CheckedFile:
    """Check what ``container`` holds against the contract (topics, schemas, metadata, the
    scenario message and attachment, at least the reset step); what it found."""
    path = container.path
    if not container.finished and not container.chunks:
        raise CorruptRecording(
            f"{path}: the file was not finished and holds no complete chunk (read "
            f"{container.recovered_bytes} of {container.size} bytes): nothing to recover"
        )
    channels = rsstp_channels(container)
    topics = _body_topics(container, channels)
    schema_versions = check_schemas(container, channels, topics)
    metadata, verified = read_metadata(container, schema_versions)
    counts = container.counts if container.counts is not None else count_messages(container)
    limit_ns: int | None = None
    if not container.data_complete:
        limit_ns = cut_time(container, channels["/rsstp/step"])
        counts = dict(counts)
        for channel, (log_time, at_time) in container.tail.items():
            if log_time >= limit_ns:
                counts[channel] = counts.get(channel, 0) - at_time
    topic_counts = {
        channel.topic: counts.get(channel_id, 0)
        for channel_id, channel in sorted(container.channels.items())
    }
    n_step_messages = counts.get(channels["/rsstp/step"], 0)
    if n_step_messages == 0:
        what = "no complete step" if not container.finished else "no step message"
        raise CorruptRecording(f"{path}: {what} to read (expected step 0, the reset)")
    record = _scenario_message(container, channels, topics, topic_counts, limit_ns)
    return CheckedFile(
        container,
        channels,
        schema_versions,
        metadata,
        verified,
        topic_counts,
        limit_ns,
        n_step_messages - 1,
        record,
        rebuild_scenario(container, record, metadata),
        topics,
    )


def _body_topics(container: Container, channels: dict[str, int]) -> dict[str, str]:
    """The topics' schema names of the body whose scenario schema the scenario channel has."""
    channel = container.channels[channels["/rsstp/scenario"]]
    schema = container.schemas.get(channel.schema_id)
    if schema is None:
        return BODY_TOPICS["arm"]  # (check_schemas names the missing schema)
    for topics in BODY_TOPICS.values():
        if schema.name == topics["/rsstp/scenario"]:
            return topics
    known = " or ".join(repr(t["/rsstp/scenario"]) for t in BODY_TOPICS.values())
    raise CorruptRecording(
        f"{container.path}: channel /rsstp/scenario: expected schema {known}, found {schema.name!r}"
    )


def _scenario_message(
    container: Container,
    channels: dict[str, int],
    topics: dict[str, str],
    counts: dict[str, int],
    limit_ns: int | None,
) -> ScenarioMessage:
    """The one ``/rsstp/scenario`` message."""
    count = counts.get("/rsstp/scenario", 0)
    if count != 1:
        raise CorruptRecording(
            f"{container.path}: expected one /rsstp/scenario message, found {count}"
        )
    channel = channels["/rsstp/scenario"]
    with closing(topic_chunks(container, channel, limit_ns)) as chunks:
        for ref, _, parts, times in chunks:
            if parts:
                name = topics["/rsstp/scenario"]
                record = _decode_one(
                    container.path, name, "/rsstp/scenario", parts[0], times[0], ref
                )
                assert isinstance(record, ScenarioMessage)
                return record
    raise CorruptRecording(f"{container.path}: the /rsstp/scenario message is missing")


def _decode_many(
    path: Path, name: str, topic: str, parts: list[memoryview], log_times: _Ints, ref: ChunkRef
) -> list[Any]:
    try:
        return decode_many(name, parts)
    except (RecordFormatError, msgspec.DecodeError):
        pass
    for part, log_time in zip(parts, log_times, strict=True):  # which one, and why
        _decode_one(path, name, topic, part, int(log_time), ref)
    raise CorruptRecording(
        f"{path}: the {topic} messages of the chunk at byte {ref.offset} decode one by one but "
        f"not together (a message holding more than one JSON value)"
    )


def _decode_one(
    path: Path, name: str, topic: str, part: memoryview, log_time: int, ref: ChunkRef
) -> Any:
    """The record of one message of ``topic``, whose schema is ``name``."""
    try:
        return decode(name, bytes(part))
    except (RecordFormatError, msgspec.DecodeError) as exc:
        raise CorruptRecording(
            f"{path}: the {topic} message at step {log_time / STEP_NS:g} (chunk at byte "
            f"{ref.offset}) is invalid: {exc}"
        ) from None


def rsstp_channels(container: Container) -> dict[str, int]:
    """Topic -> channel id of the four ``/rsstp/*`` topics (other topics are ignored)."""
    path = container.path
    channels: dict[str, int] = {}
    for channel_id, channel in sorted(container.channels.items()):
        if channel.topic in TOPICS:
            if channel.topic in channels:
                raise CorruptRecording(f"{path}: two channels have the topic {channel.topic}")
            channels[channel.topic] = channel_id
    if not channels:
        found = sorted({c.topic for c in container.channels.values()})
        listed = ", ".join(found[:5]) + (", ..." if len(found) > 5 else "") if found else "none"
        what = (
            "a scene file of rsstp-replay export --foxglove: open the recording it was made from"
            if "/rsstp/scene" in found
            else f"none of the topics {', '.join(TOPICS)} (its topics: {listed})"
        )
        raise ForeignRecording(f"{path}: an MCAP file, but not an rsstp recording: {what}")
    # A run whose agent keeps no model (a Gymnasium-driven one) has no model channel.
    missing = [t for t in TOPICS if t not in channels and t != "/rsstp/model"]
    if missing:
        raise CorruptRecording(f"{path}: expected the topics {list(TOPICS)}, missing {missing}")
    return channels


def check_schemas(
    container: Container, channels: dict[str, int], topics: dict[str, str]
) -> dict[str, str]:
    """Each channel's schema (``topics``: topic -> the body's schema name): name, encodings,
    a known major version; name -> version."""
    path = container.path
    versions: dict[str, str] = {}
    for topic, channel_id in channels.items():
        channel = container.channels[channel_id]
        name = topics[topic]
        schema = container.schemas.get(channel.schema_id)
        where = f"{path}: channel {topic}"
        if schema is None:
            raise CorruptRecording(f"{where}: its schema (id {channel.schema_id}) is missing")
        if schema.name != name:
            raise CorruptRecording(f"{where}: expected schema {name!r}, found {schema.name!r}")
        if schema.encoding != SCHEMA_ENCODING or channel.message_encoding != MESSAGE_ENCODING:
            raise CorruptRecording(
                f"{where}: expected {MESSAGE_ENCODING!r} messages with a {SCHEMA_ENCODING!r} "
                f"schema, found {channel.message_encoding!r} with {schema.encoding!r}"
            )
        try:
            version = json.loads(schema.data).get("version")
            major, minor = parse_version(version)
        except (ValueError, AttributeError, RecordFormatError, RecursionError):
            major = READ_MAJORS[-1]  # (check_schema_version names what is wrong)
        if major not in READ_MAJORS:
            raise UnsupportedVersion(f"{where}: schema {name} {version_refusal(version)}")
        try:
            major, minor = check_schema_version(name, schema.data)
        except RecordFormatError as exc:
            raise CorruptRecording(f"{where}: {exc}") from None
        versions[name] = f"{major}.{minor}"
    return versions


def read_metadata(
    container: Container, schema_versions: dict[str, str]
) -> tuple[dict[str, str], bool]:
    """The ``rsstp`` metadata record, every key present, and whether its checksum verified it:
    a file of schema 2.2 or later must carry a checksum that matches; an older one has none,
    and its metadata is read unverified (``schemas/README.md``, "The metadata checksum")."""
    path = container.path
    found = [m for m in container.metadata if m.name == METADATA_NAME]
    if not found:
        raise CorruptRecording(f"{path}: the {METADATA_NAME!r} metadata record is missing")
    metadata = dict(found[0].metadata)
    recorded = metadata.get(METADATA_CHECKSUM_KEY)
    if recorded is not None:
        computed = metadata_checksum(metadata)
        if recorded != computed:
            raise CorruptRecording(
                f"{path}: the {METADATA_NAME!r} metadata record fails its checksum: "
                f"{METADATA_CHECKSUM_KEY} is {recorded[:80]!r}, its other keys hash to "
                f"{computed} (the metadata was changed after it was written)"
            )
    else:
        version = max(parse_version(v) for v in schema_versions.values())
        if version >= METADATA_CHECKSUM_SINCE:
            raise CorruptRecording(
                f"{path}: the {METADATA_NAME!r} metadata record lacks its checksum "
                f"{METADATA_CHECKSUM_KEY} (a schema {version[0]}.{version[1]} file must carry "
                f"it, from {METADATA_CHECKSUM_SINCE[0]}.{METADATA_CHECKSUM_SINCE[1]} on)"
            )
    missing = [key for key in METADATA_KEYS if key not in metadata]
    if missing:
        raise CorruptRecording(f"{path}: the {METADATA_NAME!r} metadata lacks the keys {missing}")
    return metadata, recorded is not None


def cut_time(container: Container, step_channel: int) -> int:
    """The ``log_time`` from which an unfinished file's messages are dropped: its last step
    (whose model and events may have been lost with the next chunk)."""
    last = container.tail.get(step_channel)
    if last is None or last[0] == 0:
        raise CorruptRecording(
            f"{container.path}: the file was not finished and holds no complete step after the "
            f"reset (read {container.recovered_bytes} of {container.size} bytes): nothing to "
            f"recover"
        )
    return last[0]


def rebuild_scenario(
    container: Container, record: ScenarioMessage, metadata: dict[str, str]
) -> AnyScenario:
    path = container.path
    attachments = [a for a in container.attachments if a.name == ATTACHMENT_NAME]
    if not attachments:
        raise CorruptRecording(f"{path}: the {ATTACHMENT_NAME!r} attachment is missing")
    try:
        text = attachments[0].data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise CorruptRecording(f"{path}: the {ATTACHMENT_NAME} attachment: {exc}") from None
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    for what, value in (
        ("the /rsstp/scenario message's sha256", record.sha256),
        ("the metadata's scenario_sha256", metadata["scenario_sha256"]),
    ):
        if value != digest:
            raise CorruptRecording(
                f"{path}: {what} is {value}, but the {ATTACHMENT_NAME} attachment hashes to "
                f"{digest}"
            )
    try:
        # Only parsed: the start pose is the world's to check, where the physics check builds it.
        scenario = parse_scenario(text, origin=record.origin, check_start=False)
    except ScenarioError as exc:
        raise CorruptRecording(f"{path}: the {ATTACHMENT_NAME} attachment: {exc}") from None
    if record.schema_name != BODY_TOPICS[scenario.body]["/rsstp/scenario"]:
        raise CorruptRecording(
            f"{path}: the {ATTACHMENT_NAME} attachment describes a {scenario.body}, the "
            f"/rsstp/scenario message is {record.schema_name}"
        )
    shape = body_reader(scenario.body).shape_difference(record, scenario)
    if shape is not None:
        raise CorruptRecording(f"{path}: {shape}")
    if metadata["seed"] != str(record.seed) or metadata["strategy"] != record.strategy.name:
        raise CorruptRecording(
            f"{path}: the metadata says seed {metadata['seed']} and strategy "
            f"{metadata['strategy']!r}, the /rsstp/scenario message {record.seed} and "
            f"{record.strategy.name!r}"
        )
    return scenario
