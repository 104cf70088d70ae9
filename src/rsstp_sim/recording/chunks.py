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

The other records (header, schemas, channels, metadata, attachments, the summary and
footer) are the mcap library's own record classes, written where its ``Writer`` writes
them. With the same calls in the same order, the file is the one ``Writer`` (zstd chunks,
every index, statistics, summary offsets, chunk and summary CRCs) writes, byte for byte
(``tests/sim/test_chunks.py``).
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable, Iterable, Mapping
from typing import Protocol

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

__all__ = ["ChunkOutput", "ChunkedWriter", "Message"]

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


class ChunkOutput(Protocol):
    """Where a :class:`ChunkedWriter` writes: bytes in order, some of them built later."""

    def write(self, data: bytes) -> None:
        """Write ``data`` after everything handed over before."""

    def write_later(self, build: Callable[[int], bytes]) -> None:
        """Write ``build(offset)`` after everything handed over before, where ``offset`` is
        the file offset it starts at (on another thread: ``build`` must not touch the
        writer's state)."""

    def tell(self) -> int:
        """The file offset after everything handed over so far."""


class ChunkedWriter:
    """The mcap ``Writer``'s file (zstd chunks of about ``chunk_size`` bytes), written from
    encoded messages: :meth:`add_message` takes a message's JSON bytes as they are."""

    def __init__(self, output: ChunkOutput, *, chunk_size: int) -> None:
        self._out = output
        self._chunk_size = chunk_size
        self._compress = zstandard.ZstdCompressor(level=_ZSTD_LEVEL).compress
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
        self._new_chunk()

    def _new_chunk(self) -> None:
        # Each message is three parts, its record header, data and tail, after the chunk's
        # first ``_lead`` parts (the schemas and channels in the file's first chunk).
        self._records: list[bytes] = []
        self._lead = 0
        self._size = 0

    # -- the records outside chunks, and the schemas and channels in the first -----------

    def start(self, *, profile: str, library: str) -> None:
        self._out.write(MAGIC)
        self._write_record(Header(profile, library))

    def _write_record(self, record: McapRecord) -> int:
        """Write ``record`` at once (after the chunks handed over); its file offset."""
        offset = self._out.tell()
        self._out.write(_record_bytes(record))
        return offset

    def _chunk_record(self, record: McapRecord) -> None:
        if len(self._records) > self._lead:
            raise RecordingError("schemas and channels are registered before any message")
        data = _record_bytes(record)
        self._records.append(data)
        self._lead += 1
        self._size += len(data)

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        schema = Schema(id=len(self._schemas) + 1, data=data, encoding=encoding, name=name)
        self._schemas.append(schema)
        self._chunk_record(schema)
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
        self._chunk_record(channel)
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
        bytes are ``data + tail`` (a tail shared by many messages is not copied for each).
        The record header is the message's whole index entry until the chunk ends."""
        self.add_messages(((channel_id, log_time, data, tail),))

    def add_messages(self, messages: Iterable[Message]) -> None:
        """:meth:`add_message` for each ``(channel_id, log_time, data, tail)`` of
        ``messages``, in order. Nothing else may add to this writer while ``messages`` runs
        (a generator hands its messages over here, its other messages with them); the
        messages taken before an error from ``messages`` are kept."""
        pack, limit = _MESSAGE, self._chunk_size
        records, size = self._records, self._size
        try:
            for channel_id, log_time, data, tail in messages:
                length = len(data) + len(tail)
                records += (pack(5, length + 22, channel_id, 0, log_time, log_time), data, tail)
                size += length + _MESSAGE_OVERHEAD
                if size > limit:
                    self._size = size
                    self._end_chunk()
                    records, size = self._records, self._size
        finally:
            if records is self._records:  # (not when the chunk's hand-off failed)
                self._size = size

    def _end_chunk(self) -> None:
        """Hand the chunk over (its CRC, compression and write follow on the output's side)."""
        lead = self._lead
        if len(self._records) == lead:  # no message: the schemas and channels wait for one
            return
        heads = np.frombuffer(b"".join(self._records[lead::3]), _MESSAGE_HEADER)
        ends = np.cumsum(heads["length"] + 9, dtype=np.uint64)
        offsets = ends - (heads["length"] + 9) + (self._size - int(ends[-1]))
        times, channels = heads["log_time"], heads["channel"]
        start, end = int(times.min()), int(times.max())
        self._start_time = start if self._messages == 0 else min(self._start_time, start)
        self._end_time = max(self._end_time, end)
        # One message index per channel, in the order of each channel's first message.
        ids, firsts = np.unique(channels, return_index=True)
        indexes: list[tuple[int, bytes]] = []
        for channel in ids[np.argsort(firsts)].tolist():
            mine = channels == channel
            entries = np.empty((int(mine.sum()), 2), "<u8")
            entries[:, 0] = times[mine]
            entries[:, 1] = offsets[mine]
            head = _MESSAGE_INDEX(7, 6 + entries.nbytes, channel, entries.nbytes)
            indexes.append((channel, head + entries.tobytes()))
            self._message_counts[channel] = self._message_counts.get(channel, 0) + len(entries)
        self._messages += len(heads)
        self._chunks += 1
        records = b"".join(self._records)
        self._new_chunk()
        self._out.write_later(self._chunk_bytes(records, start, end, indexes))

    def _chunk_bytes(
        self, records: bytes, start: int, end: int, indexes: list[tuple[int, bytes]]
    ) -> Callable[[int], bytes]:
        """What builds the chunk record and its message indexes, given the chunk's offset."""
        compress, chunk_indexes = self._compress, self._chunk_indexes

        def build(offset: int) -> bytes:
            crc = zlib.crc32(records)
            data = compress(records)
            length = _CHUNK_OVERHEAD + len(data)
            index_offsets: dict[int, int] = {}
            at = offset + length
            for channel, part in indexes:
                index_offsets.setdefault(channel, at)
                at += len(part)
            chunk_indexes.append(
                ChunkIndex(
                    message_start_time=start,
                    message_end_time=end,
                    chunk_start_offset=offset,
                    chunk_length=length,
                    message_index_offsets=index_offsets,
                    message_index_length=at - offset - length,
                    compression="zstd",
                    compressed_size=len(data),
                    uncompressed_size=len(records),
                )
            )
            head = _CHUNK(6, length - 9, start, end, len(records), crc)
            return b"".join((head, _ZSTD, _LENGTH(len(data)), data, *(p for _, p in indexes)))

        return build

    # -- the end ---------------------------------------------------------------------------

    def finish(self) -> None:
        """End the last chunk and write the data end, the summary, the footer and the magic."""
        self._end_chunk()
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
