"""The MCAP container: which records a file holds, and where its chunks are.

A finished file is opened with the ``mcap`` package's seeking reader (its summary: schemas,
channels, statistics, chunk, metadata and attachment indexes), after checking the summary's
CRC. A file without a footer (the writer was killed) is scanned sequentially from its start;
every complete chunk is kept, and the scan stops at the first truncated or invalid record.
A chunk record is read whole, decompressed and checked against its CRC here
(:meth:`Container.chunk_data`); the messages inside it are the business of the layer above,
:mod:`rsstp_replay.reader._chunks`, which this module never calls. Every problem raises a
:mod:`rsstp_replay.errors` exception whose message names the file and the byte offset.
"""

from __future__ import annotations

import io
import os
import struct
import zlib
from collections import deque
from collections.abc import Callable, Generator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

import numpy as np
import numpy.typing as npt
import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import McapError
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Attachment, Channel, Metadata, Schema

from rsstp_replay.errors import CorruptRecording, NotARecording
from rsstp_sim.files import irregular
from rsstp_sim.switching import sooner_switches

__all__ = ["MESSAGE_TIME", "RECORD", "ChunkRef", "Container", "chunk_records", "open_container"]

MAGIC = b"\x89MCAP0\r\n"
_FOOTER = struct.Struct("<BQQQI")  # opcode, length, summary start, summary offset start, crc
RECORD = struct.Struct("<BQ")
"""A record's opcode and the length of its body."""
MESSAGE_TIME = struct.Struct("<BQHIQ")
"""A message record's opcode, length, channel id, sequence and log time."""
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
CHUNK_THREADS = 2
"""The threads that read, decompress and check the chunks ahead of their reader."""
_AHEAD = 3  # chunks in flight: a thread each, and one done and waiting
_PARSE_ERRORS = (
    McapError,
    struct.error,
    ValueError,
    OverflowError,
    UnicodeDecodeError,
    KeyError,
    EOFError,
)


@dataclass(frozen=True, slots=True)
class ChunkRef:
    """Where a chunk record is (``offset`` of its opcode, ``length`` of the whole record), the
    ``log_time`` range of its messages, its channel ids (``None``: unknown) and, from a
    finished file's chunk index, where each channel's message index record is."""

    offset: int
    length: int
    start_ns: int
    end_ns: int
    channels: frozenset[int] | None
    indexes: dict[int, int] | None = None


@dataclass(slots=True)
class Container:
    """What an MCAP file holds, read from its summary or from a sequential scan."""

    path: Path
    size: int
    finished: bool
    schemas: dict[int, Schema] = field(default_factory=dict)
    channels: dict[int, Channel] = field(default_factory=dict)
    chunks: list[ChunkRef] = field(default_factory=list)
    counts: dict[int, int] | None = None
    """Messages per channel id (``None`` when the summary has no statistics)."""
    metadata: list[Metadata] = field(default_factory=list)
    attachments: list[Attachment] = field(default_factory=list)
    data_complete: bool = True
    """A scan reached the end of the data section (always true for a finished file)."""
    recovered_bytes: int = 0
    """Where a scan stopped: the bytes before it were read."""
    tail: dict[int, tuple[int, int]] = field(default_factory=dict)
    """For a scan: channel id -> (its latest ``log_time``, its messages at that time)."""

    def open(self) -> BinaryIO:
        """The file, opened for reading (the caller closes it)."""
        return _open(self.path)

    def chunk_data(self, stream: BinaryIO, ref: ChunkRef) -> bytes:
        """The decompressed records of the chunk ``ref``, CRC-checked."""
        raw = os.pread(stream.fileno(), ref.length, ref.offset)  # no shared file position
        if len(raw) != ref.length:
            raise CorruptRecording(
                f"{self.path}: the chunk at byte {ref.offset} is truncated: expected "
                f"{ref.length} bytes, the file ends after {len(raw)}"
            )
        return chunk_records(self.path, raw, ref.offset)

    def chunks_data(self, refs: Sequence[ChunkRef]) -> Generator[bytes, None, None]:
        """:meth:`chunk_data` of each chunk of ``refs``, in order, the next ones read,
        decompressed and checked on :data:`CHUNK_THREADS` other threads (file reads, zstd and
        CRCs release the GIL; the switch interval is short meanwhile:
        :mod:`rsstp_sim.switching`) while the caller works on this one; an error is raised
        where its chunk comes."""
        if len(refs) < 2:
            with self.open() as stream:
                yield from (self.chunk_data(stream, ref) for ref in refs)
            return
        with (
            self.open() as stream,
            ThreadPoolExecutor(CHUNK_THREADS, thread_name_prefix="rsstp-chunks") as ahead,
            sooner_switches(),
        ):
            coming = deque(ahead.submit(self.chunk_data, stream, ref) for ref in refs[:_AHEAD])
            later = iter(refs[_AHEAD:])
            try:
                for _ in refs:
                    data = coming.popleft().result()
                    following = next(later, None)
                    if following is not None:
                        coming.append(ahead.submit(self.chunk_data, stream, following))
                    yield data
            finally:
                for future in coming:
                    future.cancel()

    def message_offsets(self, stream: BinaryIO, ref: ChunkRef, channel: int) -> _Offsets | None:
        """Where the messages of ``channel`` start in the chunk's records, in order, from the
        chunk's message index (None when the file has none for it)."""
        if ref.indexes is None or channel not in ref.indexes:
            return None
        at = ref.indexes[channel]
        stream.seek(at)
        head = stream.read(_INDEX_HEAD.size)
        if len(head) != _INDEX_HEAD.size:
            return None
        opcode, _, found, size = _INDEX_HEAD.unpack(head)
        if opcode != Opcode.MESSAGE_INDEX or found != channel or size % 16:
            raise CorruptRecording(
                f"{self.path}: the message index at byte {at} is not that of channel {channel} "
                f"(opcode 0x{opcode:02x}, channel {found})"
            )
        body = stream.read(size)
        if len(body) != size:
            raise CorruptRecording(f"{self.path}: the message index at byte {at} is truncated")
        entries = np.frombuffer(body, dtype=np.dtype([("log_time", "<u8"), ("offset", "<u8")]))
        return np.sort(entries["offset"].astype(np.int64))


_INDEX_HEAD = struct.Struct("<BQHI")
"""A message index record's opcode, length, channel id and the byte length of its entries."""
_Offsets = npt.NDArray[np.int64]


def open_container(path: str | os.PathLike[str]) -> Container:
    """Read the structure of the MCAP file at ``path`` (summary, or a sequential scan)."""
    file_path = Path(path)
    with _open(file_path) as stream:
        size = os.fstat(stream.fileno()).st_size
        head = stream.read(len(MAGIC))
        if size == 0:
            raise NotARecording(f"{file_path}: the file is empty, not an MCAP recording")
        if head != MAGIC:
            if MAGIC.startswith(head):
                raise CorruptRecording(
                    f"{file_path}: truncated: the file ends at byte {size}, inside the MCAP magic"
                )
            raise NotARecording(
                f"{file_path}: not an MCAP file (it does not start with the MCAP magic bytes)"
            )
        footer_at = size - len(MAGIC) - _FOOTER.size
        if footer_at > len(MAGIC):
            stream.seek(size - len(MAGIC))
            if stream.read() == MAGIC:
                return _read_finished(file_path, stream, size, footer_at)
        return _scan(file_path, stream, size, finished=False)


# ---------------------------------------------------------------------- finished files


def _read_finished(path: Path, stream: BinaryIO, size: int, footer_at: int) -> Container:
    stream.seek(footer_at)
    opcode, length, summary_start, offsets_start, crc = _FOOTER.unpack(stream.read(_FOOTER.size))
    if opcode != Opcode.FOOTER or length != 20:
        raise CorruptRecording(
            f"{path}: expected the footer record at byte {footer_at}, found opcode "
            f"0x{opcode:02x} with length {length}"
        )
    if summary_start == 0:  # a finished file without a summary: read it in order
        return _scan(path, stream, size, finished=True)
    if not len(MAGIC) <= summary_start <= footer_at:
        raise CorruptRecording(
            f"{path}: the footer at byte {footer_at} puts the summary at byte {summary_start}, "
            f"outside the file's data"
        )
    stream.seek(summary_start)
    covered = stream.read(footer_at + _FOOTER.size - 4 - summary_start)
    computed = zlib.crc32(covered)
    if crc != 0 and computed != crc:
        raise CorruptRecording(
            f"{path}: the summary section (bytes {summary_start} to {footer_at}) fails its CRC "
            f"check: expected 0x{crc:08x}, computed 0x{computed:08x}"
        )
    container = Container(path, size, finished=True)
    try:
        stream.seek(0)
        reader = SeekingReader(stream)
        summary = reader.get_summary()
        if summary is None:  # pragma: no cover - summary_start != 0 was checked
            raise McapError("no summary")
        container.metadata = list(reader.iter_metadata())
    except _PARSE_ERRORS as exc:
        raise CorruptRecording(
            f"{path}: the summary section (from byte {summary_start}) is not valid MCAP: {exc}"
        ) from None
    container.schemas = dict(summary.schemas)
    container.channels = dict(summary.channels)
    if summary.statistics is not None:
        container.counts = dict(summary.statistics.channel_message_counts)
    for index in sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset):
        if index.chunk_start_offset + index.chunk_length > footer_at:
            raise CorruptRecording(
                f"{path}: the chunk index says a chunk at byte {index.chunk_start_offset} of "
                f"{index.chunk_length} bytes, past the end of the data section"
            )
        container.chunks.append(
            ChunkRef(
                index.chunk_start_offset,
                index.chunk_length,
                index.message_start_time,
                index.message_end_time,
                frozenset(index.message_index_offsets) or None,
                dict(index.message_index_offsets) or None,
            )
        )
    for attachment in summary.attachment_indexes:
        stream.seek(attachment.offset)
        container.attachments.append(
            _attachment(path, stream.read(attachment.length), attachment.offset)
        )
    container.recovered_bytes = size
    return container


# ------------------------------------------------------------------- sequential scan


def _scan(path: Path, stream: BinaryIO, size: int, *, finished: bool) -> Container:
    """Read the records in order, keeping every complete chunk; stop at the first truncated or
    invalid record (an unfinished file), or at the end of the data section."""
    container = Container(path, size, finished=finished, counts={}, data_complete=False)
    counts = container.counts
    assert counts is not None
    offset = len(MAGIC)
    stream.seek(offset)
    first = True
    while offset + RECORD.size <= size:
        opcode, length = RECORD.unpack(stream.read(RECORD.size))
        end = offset + RECORD.size + length
        if end > size:
            break
        raw = stream.read(length)
        if first and opcode != Opcode.HEADER:
            raise CorruptRecording(
                f"{path}: expected the header record at byte {offset}, found opcode 0x{opcode:02x}"
            )
        first = False
        try:
            if opcode == Opcode.CHUNK:
                data = chunk_records(path, RECORD.pack(opcode, length) + raw, offset)
                container.chunks.append(_scan_chunk(container, data, offset, end - offset))
            elif opcode == Opcode.METADATA:
                container.metadata.append(Metadata.read(_stream(raw)))
            elif opcode == Opcode.ATTACHMENT:
                container.attachments.append(
                    _attachment(path, RECORD.pack(opcode, length) + raw, offset)
                )
            elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
                _register(container, opcode, raw)
            elif opcode in (Opcode.DATA_END, Opcode.FOOTER):
                container.data_complete = True
                offset = end
                break
        except (CorruptRecording, *_PARSE_ERRORS):
            if finished:
                raise
            break
        offset = end
    container.recovered_bytes = offset
    if finished and not container.data_complete:
        raise CorruptRecording(
            f"{path}: the data section is truncated at byte {offset} (expected a data end record)"
        )
    return container


def _register(container: Container, opcode: int, body: bytes) -> None:
    """Keep a schema or channel record, met in the data section or inside a chunk."""
    if opcode == Opcode.SCHEMA:
        schema = Schema.read(_stream(body))
        container.schemas[schema.id] = schema
    else:
        channel = Channel.read(_stream(body))
        container.channels[channel.id] = channel


def _scan_chunk(container: Container, data: bytes, offset: int, length: int) -> ChunkRef:
    """Register the schemas, channels and message counts of a chunk's records."""
    counts = container.counts
    assert counts is not None
    channels: set[int] = set()
    start_ns, end_ns = -1, -1
    position = 0
    while position < len(data):
        opcode, size = RECORD.unpack_from(data, position)
        body = data[position + RECORD.size : position + RECORD.size + size]
        if len(body) != size:
            raise CorruptRecording(f"{container.path}: chunk at byte {offset}: record overrun")
        if opcode == Opcode.MESSAGE:
            _, _, channel, _, log_time = MESSAGE_TIME.unpack_from(data, position)
            channels.add(channel)
            counts[channel] = counts.get(channel, 0) + 1
            last = container.tail.get(channel)
            if last is None or log_time > last[0]:
                container.tail[channel] = (log_time, 1)
            elif log_time == last[0]:
                container.tail[channel] = (log_time, last[1] + 1)
            start_ns = log_time if start_ns < 0 else min(start_ns, log_time)
            end_ns = max(end_ns, log_time)
        elif opcode in (Opcode.SCHEMA, Opcode.CHANNEL):
            _register(container, opcode, body)
        position += RECORD.size + size
    return ChunkRef(offset, length, max(start_ns, 0), max(end_ns, 0), frozenset(channels))


def chunk_records(path: Path, raw: bytes, offset: int) -> bytes:
    """The records inside a whole chunk record (``raw``): decompressed and CRC-checked."""
    where = f"{path}: the chunk at byte {offset}"
    try:
        opcode, length = RECORD.unpack_from(raw)
        _, _, uncompressed, crc, name_length = _CHUNK.unpack_from(raw, RECORD.size)
        position = RECORD.size + _CHUNK.size
        compression = raw[position : position + name_length].decode("utf-8")
        position += name_length
        (data_length,) = struct.unpack_from("<Q", raw, position)
        position += 8
    except (struct.error, UnicodeDecodeError):
        raise CorruptRecording(f"{where} has an unreadable header") from None
    if opcode != Opcode.CHUNK or RECORD.size + length != len(raw):
        raise CorruptRecording(
            f"{where}: expected a chunk record of {len(raw)} bytes, found opcode "
            f"0x{opcode:02x} with length {length}"
        )
    if position + data_length > len(raw):
        raise CorruptRecording(
            f"{where} says {data_length} bytes of data, more than its record holds"
        )
    compressed = raw[position : position + data_length]
    decompress = _DECOMPRESSORS.get(compression)
    if decompress is None:
        raise CorruptRecording(f"{where} uses an unknown compression {compression!r}")
    try:
        data = decompress(compressed, uncompressed)
    except Exception as exc:  # zstandard.ZstdError, lz4's RuntimeError...
        raise CorruptRecording(
            f"{where} does not decompress ({compression}): {exc}".rstrip(": ")
        ) from None
    if len(data) != uncompressed:
        raise CorruptRecording(
            f"{where} decompresses to {len(data)} bytes, its header says {uncompressed}"
        )
    if crc != 0:
        computed = zlib.crc32(data)
        if computed != crc:
            raise CorruptRecording(
                f"{where} fails its CRC check: expected 0x{crc:08x}, computed 0x{computed:08x}"
            )
    return data


def _zstd(data: bytes, size: int) -> bytes:
    result: bytes = zstandard.ZstdDecompressor().decompress(data, max_output_size=max(size, 1))
    return result


def _lz4(data: bytes, size: int) -> bytes:
    import lz4.frame  # type: ignore[import-untyped,import-not-found,unused-ignore]

    result: bytes = lz4.frame.decompress(data)
    return result


_DECOMPRESSORS: dict[str, Callable[[bytes, int], bytes]] = {
    "zstd": _zstd,
    "lz4": _lz4,
    "": lambda data, size: data,
}


def _attachment(path: Path, raw: bytes, offset: int) -> Attachment:
    """An attachment record (``raw``: the whole record), its CRC checked."""
    try:
        opcode, length = RECORD.unpack_from(raw)
        if opcode != Opcode.ATTACHMENT or len(raw) != RECORD.size + length:
            raise McapError(f"expected an attachment record, found opcode 0x{opcode:02x}")
        attachment: Attachment = Attachment.read(_stream(raw[RECORD.size :]))
        (crc,) = struct.unpack_from("<I", raw, len(raw) - 4)
    except _PARSE_ERRORS as exc:
        raise CorruptRecording(
            f"{path}: the attachment at byte {offset} is unreadable: {exc}"
        ) from None
    computed = zlib.crc32(raw[RECORD.size : -4])
    if crc != 0 and crc != computed:
        raise CorruptRecording(
            f"{path}: the attachment at byte {offset} fails its CRC check: expected "
            f"0x{crc:08x}, computed 0x{computed:08x}"
        )
    return attachment


def _stream(body: bytes) -> ReadDataStream:
    return ReadDataStream(io.BytesIO(body))


def _open(path: Path) -> BinaryIO:
    kind = irregular(path)
    if kind is not None:  # a named pipe would block the reader forever
        raise NotARecording(f"{path}: {kind}, not a recording (only regular files are read)")
    try:
        return open(path, "rb")  # the caller closes it
    except FileNotFoundError:
        raise NotARecording(f"{path}: no such file") from None
    except IsADirectoryError:
        raise NotARecording(f"{path}: is a directory, not a recording") from None
    except OSError as exc:
        raise NotARecording(f"{path}: cannot read: {exc.strerror or exc}") from None
