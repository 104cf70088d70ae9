"""MCAP written by chunks of encoded messages, as the mcap library's ``Writer`` writes it.

The recorder adds a million messages a second run. mcap's ``Writer.add_message`` builds a
``Message`` object, updates the statistics and a message index and writes eight fields
through a ``BytesIO`` for each one (about 4 us). :class:`ChunkedWriter` keeps a message
as its 31-byte record header (one ``struct.pack``) beside its data, in a loop over an
iterable of messages (:meth:`ChunkedWriter.add_messages`: a producer that is a generator
hands each message over without a call); a chunk's message indexes (times and offsets) and
the statistics are computed with numpy when the chunk ends,
and the chunk's CRC, compression and write are handed to the output, which does them on a
second thread (:class:`~rsstp_sim.recording.output.SideFileWriter`: zstd and file writes
release the GIL).

The messages' half is a :class:`ChunkBuilder` of its own, which ends chunks as
:class:`SealedChunk` s: a long run builds and compresses its chunks in a helper process
(:mod:`~rsstp_sim.recording.chunk_process`), and the writer places the :class:`PackedChunk`
s it gets back (:meth:`ChunkedWriter.add_packed`) where it would have placed its own.

The other records (header, schemas, channels, metadata, attachments, the summary and
footer) are the mcap library's own record classes, written where its ``Writer`` writes
them. With the same calls in the same order, the file is the one ``Writer`` (zstd chunks,
every index, statistics, summary offsets, chunk and summary CRCs) writes, byte for byte
(``tests/sim/test_chunks.py``).

A *compact* file (``compact=True``) leaves out the message indexes (the chunk indexes say so
with no message index offsets, as the MCAP specification allows) and compresses its chunks
harder (zstd level :data:`COMPACT_LEVEL`): a long run's file shrinks by more than half, and a
reader finds each message by reading its chunk through. Readers that rely on message indexes
to find a chunk's messages read nothing from such a file (the Python ``mcap`` reader before
1.4: foxglove/mcap#1735), or refuse it (``@mcap/core``'s indexed reader, which Foxglove opens
files with): hence it is not the default.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np
import zstandard
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    McapRecord,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

from rsstp_sim.errors import RecordingError

__all__ = [
    "ChunkBuilder",
    "ChunkOutput",
    "ChunkedWriter",
    "Message",
    "OpenChunk",
    "PackedChunk",
    "SealedChunk",
    "pack",
]

Message = tuple[int, int, bytes, bytes]
"""A message to add: its channel id, log time, and bytes as ``data`` and ``tail``."""

MAGIC = b"\x89MCAP0\r\n"
_MESSAGE = struct.Struct("<BQHIQQ").pack  # opcode, length, channel, sequence, log, publish time
_MESSAGE_HEADER = np.dtype(
    [
        ("opcode", "u1"),
        ("length", "<u8"),
        ("channel", "<u2"),
        ("sequence", "<u4"),
        ("log_time", "<u8"),
        ("publish_time", "<u8"),
    ]
)  # packed: 31 bytes, as _MESSAGE writes them
_MESSAGE_OVERHEAD = 31
_CHUNK = struct.Struct("<BQQQQI").pack  # opcode, length, start/end time, size, crc
_ZSTD = b"\x04\x00\x00\x00zstd"  # the compression, a length-prefixed string
_CHUNK_OVERHEAD = 9 + 8 + 8 + 8 + 4 + len(_ZSTD) + 8
_MESSAGE_INDEX = struct.Struct("<BQHI").pack  # opcode, length, channel, entries' bytes
_LENGTH = struct.Struct("<Q").pack
_ZSTD_LEVEL = 3  # mcap's Writer: zstandard.compress(data), at its default level
COMPACT_LEVEL = 9
"""The zstd level of a compact file's chunks. The 1 MiB chunks of a 2,130,183-step learner run
(1,009 MB of messages) take 62.6 MB at level 3 and 54.0 MB at level 9, compressed at about
545 and 77 MB/s (level 12: 53.4 MB at 49 MB/s)."""


class ChunkOutput(Protocol):
    """Where a :class:`ChunkedWriter` writes: bytes in order, some of them built later."""

    def write(self, data: bytes) -> None:
        """Write ``data`` after everything handed over before."""

    def write_later(self, build: Callable[[int], bytes], end_time: int) -> None:
        """Write ``build(offset)`` after everything handed over before, where ``offset`` is
        the file offset it starts at (on another thread: ``build`` must not touch the
        writer's state); ``end_time``: the latest log time of the chunk it builds."""

    def tell(self) -> int:
        """The file offset after everything handed over so far."""


class OpenChunk(NamedTuple):
    """A chunk being built, as it is: its records (the ``lead`` records, then each message's
    record header, data and tail) and their bytes."""

    records: list[bytes]
    lead: int
    size: int


@dataclass(frozen=True, slots=True)
class SealedChunk:
    """A chunk's records, ended, with what its index, its message indexes and the
    statistics need: the times of its messages, one message index record per channel and
    the messages per channel (both in the order of each channel's first message)."""

    records: bytes
    start: int
    end: int
    indexes: tuple[tuple[int, bytes], ...]
    counts: tuple[tuple[int, int], ...]


@dataclass(frozen=True, slots=True)
class PackedChunk:
    """A :class:`SealedChunk` compressed: its records' CRC, size and zstd frame."""

    data: bytes
    crc: int
    size: int
    start: int
    end: int
    indexes: tuple[tuple[int, bytes], ...]
    counts: tuple[tuple[int, int], ...]


def pack(chunk: SealedChunk, compress: Callable[[bytes], bytes]) -> PackedChunk:
    """``chunk`` compressed (its CRC is of the records before compression)."""
    records = chunk.records
    return PackedChunk(
        compress(records),
        zlib.crc32(records),
        len(records),
        chunk.start,
        chunk.end,
        chunk.indexes,
        chunk.counts,
    )


def compressor(*, compact: bool = False) -> Callable[[bytes], bytes]:
    """The compression of mcap's ``Writer``: ``zstandard.compress(data)``, at its level (a
    compact file's: :data:`COMPACT_LEVEL`)."""
    return zstandard.ZstdCompressor(level=COMPACT_LEVEL if compact else _ZSTD_LEVEL).compress


class ChunkBuilder:
    """Messages into chunks of about ``chunk_size`` bytes, each handed to ``sealed`` when it
    ends: the chunk ends after the message that takes it past ``chunk_size``, as mcap's
    ``Writer`` ends it."""

    def __init__(
        self,
        chunk_size: int,
        sealed: Callable[[SealedChunk], None],
        chunk: OpenChunk | None = None,
    ) -> None:
        self._chunk_size = chunk_size
        self._sealed = sealed
        # Each message is three parts, its record header, data and tail, after the chunk's
        # first ``_lead`` parts (the schemas and channels in the file's first chunk).
        self._records: list[bytes] = [] if chunk is None else list(chunk.records)
        self._lead = 0 if chunk is None else chunk.lead
        self._size = 0 if chunk is None else chunk.size

    def open_chunk(self) -> OpenChunk:
        """The chunk being built, as it is (a builder made from it goes on with it)."""
        return OpenChunk(self._records, self._lead, self._size)

    def add_lead(self, data: bytes) -> None:
        """A record (a schema, a channel) at the start of the chunk, before its messages."""
        if len(self._records) > self._lead:
            raise RecordingError("schemas and channels are registered before any message")
        self._records.append(data)
        self._lead += 1
        self._size += len(data)

    def add_messages(self, messages: Iterable[Message]) -> None:
        """Add each ``(channel_id, log_time, data, tail)`` of ``messages``, in order (publish
        time = log time, sequence 0): its bytes are ``data + tail`` (a tail shared by many
        messages is not copied for each). The record header is the message's whole index
        entry until the chunk ends. The messages taken before an error from ``messages``
        are kept."""
        pack_header, limit = _MESSAGE, self._chunk_size
        records, size = self._records, self._size
        try:
            for channel_id, log_time, data, tail in messages:
                length = len(data) + len(tail)
                records += (
                    pack_header(5, length + 22, channel_id, 0, log_time, log_time),
                    data,
                    tail,
                )
                size += length + _MESSAGE_OVERHEAD
                if size > limit:
                    self._size = size
                    self.seal()
                    records, size = self._records, self._size
        finally:
            if records is self._records:  # (not when the chunk's hand-off failed)
                self._size = size

    def seal(self) -> None:
        """End the chunk and hand it to ``sealed``, if it holds a message (else the lead
        records wait for one)."""
        lead = self._lead
        if len(self._records) == lead:
            return
        heads = np.frombuffer(b"".join(self._records[lead::3]), _MESSAGE_HEADER)
        ends = np.cumsum(heads["length"] + 9, dtype=np.uint64)
        offsets = ends - (heads["length"] + 9) + (self._size - int(ends[-1]))
        times, channels = heads["log_time"], heads["channel"]
        # One message index per channel, in the order of each channel's first message.
        ids, firsts = np.unique(channels, return_index=True)
        indexes: list[tuple[int, bytes]] = []
        counts: list[tuple[int, int]] = []
        for channel in ids[np.argsort(firsts)].tolist():
            mine = channels == channel
            entries = np.empty((int(mine.sum()), 2), "<u8")
            entries[:, 0] = times[mine]
            entries[:, 1] = offsets[mine]
            head = _MESSAGE_INDEX(7, 6 + entries.nbytes, channel, entries.nbytes)
            indexes.append((channel, head + entries.tobytes()))
            counts.append((channel, len(entries)))
        records = b"".join(self._records)
        self._records, self._lead, self._size = [], 0, 0
        self._sealed(
            SealedChunk(records, int(times.min()), int(times.max()), tuple(indexes), tuple(counts))
        )


class ChunkedWriter:
    """The mcap ``Writer``'s file (zstd chunks of about ``chunk_size`` bytes), written from
    encoded messages: :meth:`add_message` takes a message's JSON bytes as they are. ``compact``:
    no message indexes, chunks compressed harder (see the module)."""

    def __init__(self, output: ChunkOutput, *, chunk_size: int, compact: bool = False) -> None:
        self._out = output
        self.chunk_size = chunk_size
        self.compact = compact
        self._compress = compressor(compact=compact)
        self._schemas: list[Schema] = []
        self._channels: list[Channel] = []
        self._attachment_indexes: list[AttachmentIndex] = []
        self._metadata_indexes: list[MetadataIndex] = []
        self._chunk_indexes: list[ChunkIndex] = []  # appended by the output, in file order
        self._message_counts: dict[int, int] = {}  # channel -> messages, in order of the first
        self._messages = 0
        self._start_time = 0
        self._end_time = 0
        self._chunks = 0
        self._builder = ChunkBuilder(chunk_size, self._seal)

    # -- the records outside chunks, and the schemas and channels in the first -----------

    def start(self, *, profile: str, library: str) -> None:
        self._out.write(MAGIC)
        self._write_record(Header(profile, library))

    def _write_record(self, record: McapRecord) -> int:
        """Write ``record`` at once (after the chunks handed over); its file offset."""
        offset = self._out.tell()
        self._out.write(_record_bytes(record))
        return offset

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        schema = Schema(id=len(self._schemas) + 1, data=data, encoding=encoding, name=name)
        self._schemas.append(schema)
        self._builder.add_lead(_record_bytes(schema))
        return schema.id

    def register_channel(self, topic: str, message_encoding: str, schema_id: int) -> int:
        channel = Channel(
            id=len(self._channels) + 1,
            topic=topic,
            message_encoding=message_encoding,
            schema_id=schema_id,
            metadata={},
        )
        self._channels.append(channel)
        self._builder.add_lead(_record_bytes(channel))
        return channel.id

    def add_metadata(self, name: str, data: Mapping[str, str]) -> None:
        metadata = Metadata(name=name, metadata=dict(data))
        offset = self._write_record(metadata)
        self._metadata_indexes.append(
            MetadataIndex(offset=offset, length=self._out.tell() - offset, name=name)
        )

    def add_attachment(
        self, create_time: int, log_time: int, name: str, media_type: str, data: bytes
    ) -> None:
        attachment = Attachment(
            create_time=create_time,
            log_time=log_time,
            name=name,
            media_type=media_type,
            data=data,
        )
        offset = self._write_record(attachment)
        self._attachment_indexes.append(
            AttachmentIndex(
                offset=offset,
                length=self._out.tell() - offset,
                create_time=create_time,
                log_time=log_time,
                data_size=len(data),
                name=name,
                media_type=media_type,
            )
        )

    # -- messages -------------------------------------------------------------------------

    def add_message(self, channel_id: int, log_time: int, data: bytes, tail: bytes = b"") -> None:
        """Add a message (publish time = log time, sequence 0) to the chunk being built: its
        bytes are ``data + tail``."""
        self._builder.add_messages(((channel_id, log_time, data, tail),))

    def add_messages(self, messages: Iterable[Message]) -> None:
        """:meth:`add_message` for each ``(channel_id, log_time, data, tail)`` of
        ``messages``, in order (:meth:`ChunkBuilder.add_messages`). Nothing else may add to
        this writer while ``messages`` runs (a generator hands its messages over here, its
        other messages with them)."""
        self._builder.add_messages(messages)

    def hand_over(self) -> OpenChunk:
        """The chunk being built, for a :class:`ChunkBuilder` elsewhere to go on with; until
        :meth:`take_back`, chunks come as :meth:`add_packed` gives them."""
        chunk = self._builder.open_chunk()
        self._builder = ChunkBuilder(self.chunk_size, self._seal)
        return chunk

    def take_back(self, chunk: OpenChunk) -> None:
        """Go on building ``chunk`` (what the builder :meth:`hand_over` fed left open)."""
        self._builder = ChunkBuilder(self.chunk_size, self._seal, chunk)

    def _seal(self, chunk: SealedChunk) -> None:
        """Count a chunk of ours and hand it over: its CRC and compression follow on the
        output's side."""
        self._count(chunk)
        compress = self._compress
        self._out.write_later(lambda offset: self._placed(pack(chunk, compress), offset), chunk.end)

    def add_packed(self, chunk: PackedChunk) -> None:
        """Write a chunk a builder elsewhere sealed and packed, after those before it."""
        self._count(chunk)
        self._out.write_later(lambda offset: self._placed(chunk, offset), chunk.end)

    def _count(self, chunk: SealedChunk | PackedChunk) -> None:
        """The statistics of a chunk's messages."""
        start, end = chunk.start, chunk.end
        self._start_time = start if self._messages == 0 else min(self._start_time, start)
        self._end_time = max(self._end_time, end)
        for channel, count in chunk.counts:
            self._message_counts[channel] = self._message_counts.get(channel, 0) + count
            self._messages += count
        self._chunks += 1

    def _placed(self, chunk: PackedChunk, offset: int) -> bytes:
        """The chunk record and its message indexes (none in a compact file) at file
        ``offset``; its chunk index (on the output's side, in file order)."""
        data, indexes = chunk.data, () if self.compact else chunk.indexes
        length = _CHUNK_OVERHEAD + len(data)
        index_offsets: dict[int, int] = {}
        at = offset + length
        for channel, part in indexes:
            index_offsets.setdefault(channel, at)
            at += len(part)
        self._chunk_indexes.append(
            ChunkIndex(
                message_start_time=chunk.start,
                message_end_time=chunk.end,
                chunk_start_offset=offset,
                chunk_length=length,
                message_index_offsets=index_offsets,
                message_index_length=at - offset - length,
                compression="zstd",
                compressed_size=len(data),
                uncompressed_size=chunk.size,
            )
        )
        head = _CHUNK(6, length - 9, chunk.start, chunk.end, chunk.size, chunk.crc)
        return b"".join((head, _ZSTD, _LENGTH(len(data)), data, *(p for _, p in indexes)))

    # -- the end ---------------------------------------------------------------------------

    def finish(self) -> None:
        """End the last chunk and write the data end, the summary, the footer and the magic."""
        self._builder.seal()
        self._write_record(DataEnd(0))
        summary_start = self._out.tell()
        summary = RecordBuilder()
        offsets: list[SummaryOffset] = []

        def group(opcode: Opcode, items: list[McapRecord]) -> None:
            begin = summary.count
            for item in items:
                item.write(summary)
            offsets.append(
                SummaryOffset(
                    group_opcode=opcode,
                    group_start=summary_start + begin,
                    group_length=summary.count - begin,
                )
            )

        statistics = Statistics(
            attachment_count=len(self._attachment_indexes),
            channel_count=len(self._channels),
            channel_message_counts=self._message_counts,
            chunk_count=self._chunks,
            message_count=self._messages,
            metadata_count=len(self._metadata_indexes),
            message_start_time=self._start_time,
            message_end_time=self._end_time,
            schema_count=len(self._schemas),
        )
        group(Opcode.SCHEMA, [*self._schemas])
        group(Opcode.CHANNEL, [*self._channels])
        group(Opcode.STATISTICS, [statistics])
        group(Opcode.CHUNK_INDEX, [*self._chunk_indexes])
        group(Opcode.ATTACHMENT_INDEX, [*self._attachment_indexes])
        group(Opcode.METADATA_INDEX, [*self._metadata_indexes])
        offset_start = summary_start + summary.count
        for offset in offsets:
            offset.write(summary)
        data: bytes = summary.end()  # type: ignore[no-untyped-call]
        crc = zlib.crc32(data)
        crc = zlib.crc32(struct.pack("<BQQQ", Opcode.FOOTER, 20, summary_start, offset_start), crc)
        self._out.write(data)
        self._write_record(
            Footer(summary_start=summary_start, summary_offset_start=offset_start, summary_crc=crc)
        )
        self._out.write(MAGIC)


def _record_bytes(record: McapRecord) -> bytes:
    builder = RecordBuilder()
    record.write(builder)
    data: bytes = builder.end()  # type: ignore[no-untyped-call]
    return data
