"""The bytes of chunks: decompressed, CRC-checked, and their message records sliced out.

A chunk is read in one piece, decompressed in one call and checked against its CRC; its
message records are then sliced out of its bytes (:func:`split_messages`) for a decoder to
take many at once. This is the hot path of reading a recording: no object per record but the
slice of its data.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import numpy.typing as npt
import zstandard
from mcap.opcode import Opcode

from rsstp_replay.errors import CorruptRecording

__all__ = [
    "MESSAGE_TIME",
    "RECORD",
    "chunk_records",
    "message_channels",
    "message_times",
    "log_times_at",
    "messages_at",
    "split_messages",
]

RECORD = struct.Struct("<BQ")
"""A record's opcode and the length of its body."""
MESSAGE_TIME = struct.Struct("<BQHIQ")
"""A message record's opcode, length, channel id, sequence and log time."""
_MESSAGE = struct.Struct("<BQH")  # opcode, record length, channel id
_MESSAGE_HEAD = 31  # opcode 1, length 8, channel 2, sequence 4, log_time 8, publish_time 8
_LOG_TIME = 15  # where a message record's log_time starts
_CHUNK = struct.Struct("<QQQII")  # start, end, uncompressed size, crc, compression length
_MESSAGE_OP = int(Opcode.MESSAGE)


def messages_at(
    path: Path, data: bytes, offsets: npt.NDArray[np.int64], channel: int, *, where: int
) -> list[memoryview]:
    """The data of the message records of ``channel`` that start at ``offsets`` in ``data``
    (from the chunk's message index: no walk over the other records); each offset is checked
    to hold a message record of that channel inside the chunk."""
    size = len(data)
    if len(offsets) and (int(offsets[0]) < 0 or int(offsets[-1]) + _MESSAGE_HEAD > size):
        raise CorruptRecording(
            f"{path}: the message index of the chunk at byte {where} points outside it"
        )
    raw = np.frombuffer(data, np.uint8)
    head = raw[offsets[:, None] + np.arange(11)]  # opcode, length (8), channel (2)
    lengths = head[:, 1:9].copy().view("<u8").ravel().astype(np.int64)
    channels = head[:, 9:11].copy().view("<u2").ravel()
    ends = offsets + 9 + lengths
    if len(offsets) and (
        (head[:, 0] != _MESSAGE_OP).any()
        or (channels != channel).any()
        or (lengths < _MESSAGE_HEAD - 9).any()
        or int(ends.max()) > size
    ):
        raise CorruptRecording(
            f"{path}: the message index of the chunk at byte {where} does not point at "
            f"messages of channel {channel}"
        )
    view = memoryview(data)
    return [
        view[a:b] for a, b in zip((offsets + _MESSAGE_HEAD).tolist(), ends.tolist(), strict=True)
    ]


def split_messages(
    path: Path,
    data: bytes,
    wanted: dict[int, list[memoryview]],
    *,
    where: int,
    limit_ns: int | None = None,
    times: dict[int, list[int]] | None = None,
) -> None:
    """Append the data of each message record in ``data`` to ``wanted[channel_id]`` (channels
    not in ``wanted`` are skipped; with ``limit_ns``, so are messages logged at or after it),
    and with ``times``, its ``log_time`` to ``times[channel_id]``."""
    view = memoryview(data)
    size = len(data)
    get = wanted.get
    position = 0
    try:
        if limit_ns is None and times is None:
            unpack = _MESSAGE.unpack_from
            while position < size:
                opcode, length, channel = unpack(data, position)
                if opcode == _MESSAGE_OP:
                    found = get(channel)
                    if found is not None:
                        found.append(view[position + _MESSAGE_HEAD : position + 9 + length])
                position += 9 + length
        else:
            limit = limit_ns if limit_ns is not None else 1 << 64
            unpack_time = MESSAGE_TIME.unpack_from
            found_times: dict[int, list[int]] = times if times is not None else {}
            while position < size:
                opcode, length, channel, _, log_time = unpack_time(data, position)
                if opcode == _MESSAGE_OP and log_time < limit:
                    found = get(channel)
                    if found is not None:
                        found.append(view[position + _MESSAGE_HEAD : position + 9 + length])
                        if times is not None:
                            found_times[channel].append(log_time)
                position += 9 + length
    except struct.error:
        position = size + 1
    if position != size:
        raise CorruptRecording(
            f"{path}: the chunk at byte {where} holds a record that overruns its end"
        )


def message_channels(data: bytes) -> list[int]:
    """The channel id of every message record in a chunk's records, in order."""
    channels = []
    position = 0
    while position + _MESSAGE.size <= len(data):
        opcode, length, channel = _MESSAGE.unpack_from(data, position)
        if opcode == _MESSAGE_OP:
            channels.append(channel)
        position += 9 + length
    return channels


def log_times_at(data: bytes, offsets: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """The log times of the message records that start at ``offsets`` in ``data`` (offsets
    that :func:`messages_at` checked)."""
    raw = np.frombuffer(data, np.uint8)
    at = offsets[:, None] + np.arange(_LOG_TIME, _LOG_TIME + 8)
    times: npt.NDArray[np.int64] = raw[at].copy().view("<u8").ravel().astype(np.int64)
    return times


def message_times(data: bytes, channel: int) -> list[int]:
    """The ``log_time`` of every message of ``channel`` in a chunk's records, in order
    (slow: for error messages)."""
    times = []
    position = 0
    while position + MESSAGE_TIME.size <= len(data):
        opcode, length, found, _, log_time = MESSAGE_TIME.unpack_from(data, position)
        if opcode == _MESSAGE_OP and found == channel:
            times.append(log_time)
        position += 9 + length
    return times


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
