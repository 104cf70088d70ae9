"""What a file must hold to be a recording: the checks :func:`open_recording` makes.

The ``/rsstp/*`` channels (one per topic, with their schemas, encodings and a ``1.x``
version), the ``rsstp`` metadata record, and the ``scenario.toml`` attachment agreeing with the
``/rsstp/scenario`` message and the metadata (``schemas/README.md`` is the contract).
"""

from __future__ import annotations

import hashlib
import json

from rsstp_replay._container import Container
from rsstp_replay.errors import CorruptRecording, ForeignRecording, UnsupportedVersion
from rsstp_sim.errors import ScenarioError
from rsstp_sim.recording.records import RecordFormatError, ScenarioRecord
from rsstp_sim.recording.schemas import (
    ATTACHMENT_NAME,
    MESSAGE_ENCODING,
    METADATA_KEYS,
    METADATA_NAME,
    SCHEMA_ENCODING,
    SCHEMA_VERSION,
    TOPICS,
    check_schema_version,
    parse_version,
)
from rsstp_sim.scenario import Scenario, parse_scenario

__all__ = ["check_schemas", "cut_time", "read_metadata", "rebuild_scenario", "rsstp_channels"]


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
        raise ForeignRecording(
            f"{path}: an MCAP file, but not an rsstp recording: no /rsstp/* topic "
            f"(its topics: {listed})"
        )
    missing = [topic for topic in TOPICS if topic not in channels]
    if missing:
        raise CorruptRecording(f"{path}: expected the topics {list(TOPICS)}, missing {missing}")
    return channels


def check_schemas(container: Container, channels: dict[str, int]) -> dict[str, str]:
    """Each channel's schema: name, encodings, a known major version; name -> version."""
    path = container.path
    versions: dict[str, str] = {}
    supported, _ = parse_version(SCHEMA_VERSION)
    for topic, channel_id in channels.items():
        channel = container.channels[channel_id]
        name = TOPICS[topic]
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
        except (ValueError, AttributeError, RecordFormatError):
            major = supported
        if major != supported:
            raise UnsupportedVersion(
                f"{where}: schema {name} version {version} is not supported (this reader "
                f"understands {supported}.x)"
            )
        try:
            major, minor = check_schema_version(name, schema.data)
        except RecordFormatError as exc:
            raise CorruptRecording(f"{where}: {exc}") from None
        versions[name] = f"{major}.{minor}"
    return versions


def read_metadata(container: Container) -> dict[str, str]:
    """The ``rsstp`` metadata record, every key present."""
    path = container.path
    found = [m for m in container.metadata if m.name == METADATA_NAME]
    if not found:
        raise CorruptRecording(f"{path}: the {METADATA_NAME!r} metadata record is missing")
    metadata = dict(found[0].metadata)
    missing = [key for key in METADATA_KEYS if key not in metadata]
    if missing:
        raise CorruptRecording(f"{path}: the {METADATA_NAME!r} metadata lacks the keys {missing}")
    return metadata


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
    container: Container, record: ScenarioRecord, metadata: dict[str, str]
) -> Scenario:
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
        scenario = parse_scenario(text, origin=record.origin)
    except ScenarioError as exc:
        raise CorruptRecording(f"{path}: the {ATTACHMENT_NAME} attachment: {exc}") from None
    if scenario.n_joints != record.n_joints or len(scenario.obstacles) != len(record.obstacles):
        raise CorruptRecording(
            f"{path}: the /rsstp/scenario message has {record.n_joints} joints and "
            f"{len(record.obstacles)} obstacles, its scenario file {scenario.n_joints} and "
            f"{len(scenario.obstacles)}"
        )
    if metadata["seed"] != str(record.seed) or metadata["strategy"] != record.strategy.name:
        raise CorruptRecording(
            f"{path}: the metadata says seed {metadata['seed']} and strategy "
            f"{metadata['strategy']!r}, the /rsstp/scenario message {record.seed} and "
            f"{record.strategy.name!r}"
        )
    return scenario
