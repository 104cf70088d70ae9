"""The chunked writer writes the mcap library's ``Writer`` file, byte for byte.

The same calls (header, schemas, channels, metadata, attachments, messages on several
channels with times in any order, a chunk size from the smallest up) go to mcap's ``Writer``
and to :class:`ChunkedWriter`; the files must be equal, and the mcap reader must read every
message back with its CRCs checked. The writer's output on a second thread (the side file
writer) gives the same bytes, and a write error there surfaces at the next hand-off.
"""

from __future__ import annotations

import contextlib
import io
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from unittest import mock

import pytest
import zstandard
from hypothesis import given, settings
from hypothesis import strategies as st
from mcap.reader import make_reader
from mcap.writer import CompressionType, IndexType, Writer

from rsstp_sim.recording.chunks import COMPACT_LEVEL, ChunkedWriter
from rsstp_sim.recording.output import SideFileWriter


class InMemory:
    """A :class:`~rsstp_sim.recording.chunks.ChunkOutput` that builds each chunk at once."""

    def __init__(self) -> None:
        self.data = bytearray()

    def write(self, data: bytes) -> None:
        self.data += data

    def write_later(self, build: Callable[[int], bytes], end_time: int) -> None:
        self.data += build(len(self.data))

    def tell(self) -> int:
        return len(self.data)


@dataclass(frozen=True)
class Plan:
    """What a file holds: the calls, in order."""

    schemas: list[bytes]
    topics: list[int]  # each channel's schema (1-based)
    metadata: list[dict[str, str]]
    attachments: list[bytes]
    messages: list[tuple[int, int, bytes, bytes]]  # channel (0-based), log time, data, tail
    chunk_size: int


def with_mcap(plan: Plan, *, compact: bool = False) -> bytes:
    """The file mcap's own ``Writer`` writes; ``compact``: with every index but the message
    indexes, and zstd at the compact level instead of ``zstandard.compress``'s."""
    out = io.BytesIO()
    indexes = IndexType.ALL & ~IndexType.MESSAGE if compact else IndexType.ALL
    writer = Writer(
        out, chunk_size=plan.chunk_size, compression=CompressionType.ZSTD, index_types=indexes
    )
    harder = zstandard.ZstdCompressor(level=COMPACT_LEVEL).compress
    with mock.patch.object(zstandard, "compress", harder) if compact else contextlib.nullcontext():
        writer.start(profile="", library="test")
        _calls(plan, writer, lambda ch, t, data, tail: writer.add_message(ch, t, data + tail, t))
        writer.finish()
    return out.getvalue()


def with_chunked(plan: Plan, output: InMemory | SideFileWriter, *, compact: bool = False) -> None:
    writer = ChunkedWriter(output, chunk_size=plan.chunk_size, compact=compact)
    writer.start(profile="", library="test")
    _calls(plan, writer, writer.add_message)
    writer.finish()


def _calls(
    plan: Plan, writer: Writer | ChunkedWriter, add: Callable[[int, int, bytes, bytes], None]
) -> None:
    ids = [writer.register_schema(f"s{i}", "jsonschema", s) for i, s in enumerate(plan.schemas)]
    channels = [
        writer.register_channel(f"/t{i}", "json", ids[schema - 1])
        for i, schema in enumerate(plan.topics)
    ]
    for i, data in enumerate(plan.metadata):
        writer.add_metadata(f"m{i}", data)
    for i, data in enumerate(plan.attachments):
        writer.add_attachment(0, i, f"a{i}.txt", "text/plain", data)
    for channel, log_time, data, tail in plan.messages:
        add(channels[channel], log_time, data, tail)


@st.composite
def plans(draw: st.DrawFn) -> Plan:
    schemas = draw(st.lists(st.binary(min_size=1, max_size=200), min_size=1, max_size=3))
    topics = draw(st.lists(st.integers(1, len(schemas)), min_size=1, max_size=4))
    text = st.text(max_size=20)
    metadata = draw(st.lists(st.dictionaries(text, text, max_size=3), max_size=2))
    attachments = draw(st.lists(st.binary(max_size=300), max_size=2))
    message = st.tuples(
        st.integers(0, len(topics) - 1),
        st.integers(0, 10**12),
        st.binary(max_size=400),
        st.binary(max_size=300),
    )
    messages = draw(st.lists(message, min_size=1, max_size=300))
    chunk_size = draw(st.sampled_from([1024, 2000, 4096, 1 << 20]))
    return Plan(schemas, topics, metadata, attachments, messages, chunk_size)


@settings(max_examples=150, deadline=None)
@given(plan=plans())
def test_the_bytes_are_mcaps_writers(plan: Plan) -> None:
    ours = InMemory()
    with_chunked(plan, ours)
    assert bytes(ours.data) == with_mcap(plan)


@settings(max_examples=60, deadline=None)
@given(plan=plans())
def test_a_compact_file_is_mcaps_writers_without_message_indexes(plan: Plan) -> None:
    ours = InMemory()
    with_chunked(plan, ours, compact=True)
    assert bytes(ours.data) == with_mcap(plan, compact=True)
    summary = make_reader(io.BytesIO(bytes(ours.data))).get_summary()
    assert summary is not None
    assert all(not index.message_index_offsets for index in summary.chunk_indexes)


def test_a_long_file_reads_back_with_its_crcs(tmp_path: Path) -> None:
    """Thousands of messages over many chunks, through the side file writer's thread."""
    messages = [(i % 3, (i // 2) * 1000, b'{"i":%d}' % i, b"x" * (i % 97)) for i in range(20_000)]
    plan = Plan([b"{}", b"{ }"], [1, 2, 1], [{"k": "v"}], [b"text"], messages, 4096)
    path = tmp_path / "out.mcap"
    output = SideFileWriter(io.FileIO(path, "w"))
    with_chunked(plan, output)
    output.close()
    assert path.read_bytes() == with_mcap(plan)
    with path.open("rb") as stream:
        reader = make_reader(stream, validate_crcs=True)
        read = [
            (c.topic, m.log_time, m.data) for _, c, m in reader.iter_messages(log_time_order=False)
        ]
        summary = reader.get_summary()
    assert read == [(f"/t{ch}", t, data + tail) for ch, t, data, tail in messages]
    assert summary is not None and len(summary.chunk_indexes) > 100


class FailingFile(io.FileIO):
    """A file whose writes fail once ``limit`` bytes are written, as a full disk does."""

    limit = 0

    def write(self, data: object) -> int:  # type: ignore[override]
        view = memoryview(data)  # type: ignore[arg-type]
        if self.tell() + len(view) > self.limit:
            raise OSError(28, "No space left on device")
        return super().write(view)


def test_a_write_error_on_the_thread_surfaces_at_the_next_hand_off(tmp_path: Path) -> None:
    raw = FailingFile(tmp_path / "out.mcap", "w")
    raw.limit = 3000
    output = SideFileWriter(raw)
    sizes: list[int] = []

    def chunk(size: int) -> Callable[[int], bytes]:
        sizes.append(size)
        return lambda offset: b"c" * size

    output.write(b"h" * 100)
    assert output.safe_steps == 0
    # A chunk whose last message is of step 3 (log time 3 ms) holds steps 1 and 2 whole.
    output.write_later(chunk(1000), 3_000_000)  # written: steps to 2 safe
    output.write_later(chunk(1000), 7_000_000)  # written: steps to 6 safe
    output.write_later(chunk(1000), 9_000_000)  # fails on the thread
    with pytest.raises(OSError, match="No space left") as raised:
        output.write_later(chunk(1000), 12_000_000)
    assert raised.value is output.error
    assert output.safe_steps == 6
    with pytest.raises(OSError, match="No space left"):
        output.tell()
    output.close()
    assert (tmp_path / "out.mcap").read_bytes() == b"h" * 100 + b"c" * 2000
    assert sizes == [1000, 1000, 1000, 1000]
