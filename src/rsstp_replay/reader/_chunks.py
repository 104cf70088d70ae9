"""The messages inside chunks: found, sliced out and counted.

The reader's second layer, above :mod:`rsstp_replay.reader._container` (which reads each chunk
record, decompressed and CRC-checked) and below :mod:`rsstp_replay.reader._contract`. A chunk's
message records are found in its bytes (:func:`split_bounds`, or through the chunk's
message index, :func:`message_bounds`) and sliced out for a decoder to take many at once;
:func:`topic_chunks` reads a topic chunk by chunk (:func:`topics_chunks` several topics in
one read of each chunk). This is the hot path of reading a recording: no object per record
but the slice of its data, or only where it starts and ends.
"""

from __future__ import annotations

import gc
import struct
from collections.abc import Generator, Iterator, Sequence
from contextlib import closing, contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from mcap.opcode import Opcode

from rsstp_format.schemas import STEP_NS
from rsstp_replay.errors import CorruptRecording
from rsstp_replay.reader._container import MESSAGE_TIME, ChunkRef, Container

__all__ = [
    "count_messages",
    "gc_paused",
    "message_channels",
    "Messages",
    "log_times_at",
    "message_bounds",
    "split_bounds",
    "topic_chunks",
    "topics_chunks",
]

_Ints = npt.NDArray[np.int64]
_MESSAGE = struct.Struct("<BQH")  # opcode, record length, channel id
_MESSAGE_HEAD = 31  # opcode 1, length 8, channel 2, sequence 4, log_time 8, publish_time 8
_LOG_TIME = 15  # where a message record's log_time starts
_MESSAGE_OP = int(Opcode.MESSAGE)


class Messages(NamedTuple):
    """A chunk's messages of one channel: where each one's data starts and ends in the
    chunk's records (no object per message), and each one's log time."""

    starts: list[int]
    ends: list[int]
    times: _Ints

    def views(self, data: bytes) -> list[memoryview]:
        """Each message's data, a slice of the chunk's records ``data`` (no copy)."""
        view = memoryview(data)
        return [view[a:b] for a, b in zip(self.starts, self.ends, strict=True)]


def message_bounds(
    path: Path, data: bytes, offsets: npt.NDArray[np.int64], channel: int, *, where: int
) -> tuple[list[int], list[int]]:
    """Where the data of the message records of ``channel`` that start at ``offsets`` in
    ``data`` starts and ends (from the chunk's message index: no walk over the other
    records); each offset is checked to hold a message record of that channel inside the
    chunk."""
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
    return (offsets + _MESSAGE_HEAD).tolist(), ends.tolist()


def split_bounds(
    path: Path,
    data: bytes,
    wanted: dict[int, tuple[list[int], list[int]]],
    *,
    where: int,
    limit_ns: int | None = None,
    times: dict[int, list[int]] | None = None,
) -> None:
    """Append where the data of each message record in ``data`` starts and ends to
    ``wanted[channel_id]`` (channels not in ``wanted`` are skipped; with ``limit_ns``, so are
    messages logged at or after it), and with ``times``, its ``log_time`` to
    ``times[channel_id]``."""
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
                        found[0].append(position + _MESSAGE_HEAD)
                        found[1].append(position + 9 + length)
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
                        found[0].append(position + _MESSAGE_HEAD)
                        found[1].append(position + 9 + length)
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
    that :func:`message_bounds` checked)."""
    raw = np.frombuffer(data, np.uint8)
    at = offsets[:, None] + np.arange(_LOG_TIME, _LOG_TIME + 8)
    times: npt.NDArray[np.int64] = raw[at].copy().view("<u8").ravel().astype(np.int64)
    return times


def count_messages(container: Container) -> dict[int, int]:
    """Messages per channel id, counted in the chunks (for files without statistics)."""
    counts: dict[int, int] = {}
    with container.open() as stream:
        for ref in container.chunks:
            for channel in message_channels(container.chunk_data(stream, ref)):
                counts[channel] = counts.get(channel, 0) + 1
    return counts


def topic_chunks(
    container: Container,
    channel: int,
    limit_ns: int | None,
    *,
    step: int | None = None,
) -> Generator[tuple[ChunkRef, bytes, list[memoryview], _Ints], None, None]:
    """The chunks with messages of ``channel`` (or only those around ``step``'s log time),
    each with its records, those messages' bytes and their log times (:func:`topics_chunks`
    of one channel)."""
    for ref, data, [found] in topics_chunks(container, (channel,), limit_ns, step=step):
        yield ref, data, found.views(data), found.times


def topics_chunks(
    container: Container,
    channels: Sequence[int],
    limit_ns: int | None,
    *,
    step: int | None = None,
) -> Generator[tuple[ChunkRef, bytes, list[Messages]], None, None]:
    """The chunks with messages of any of ``channels`` (or only those around ``step``'s log
    time), each with its records and, channel by channel, its :class:`Messages`: one read of
    each chunk for several topics. A finished file's messages are
    found through each chunk's message index, anything else by walking the chunk's records;
    an unfinished file's messages stop at ``limit_ns``."""
    path = container.path
    refs = []
    for ref in container.chunks:
        if ref.channels is not None and ref.channels.isdisjoint(channels):
            continue
        if step is not None and not ref.start_ns <= step * STEP_NS <= ref.end_ns:
            continue
        if limit_ns is not None and ref.start_ns >= limit_ns:
            break
        refs.append(ref)
    with container.open() as stream, closing(container.chunks_data(refs)) as chunks:
        for ref, data in zip(refs, chunks, strict=True):
            cut = limit_ns if limit_ns is not None and ref.end_ns >= limit_ns else None
            found: dict[int, Messages] = {}
            for channel in channels if cut is None else ():
                if ref.channels is not None and channel not in ref.channels:
                    found[channel] = Messages([], [], np.empty(0, np.int64))
                    continue
                offsets = container.message_offsets(stream, ref, channel)
                if offsets is not None:
                    starts, ends = message_bounds(path, data, offsets, channel, where=ref.offset)
                    found[channel] = Messages(starts, ends, log_times_at(data, offsets))
            walked = [channel for channel in channels if channel not in found]
            if walked:
                wanted: dict[int, tuple[list[int], list[int]]] = {c: ([], []) for c in walked}
                times: dict[int, list[int]] = {channel: [] for channel in walked}
                split_bounds(path, data, wanted, where=ref.offset, limit_ns=cut, times=times)
                for channel in walked:
                    starts, ends = wanted[channel]
                    found[channel] = Messages(starts, ends, np.array(times[channel], np.int64))
            yield ref, data, [found[channel] for channel in channels]


@contextmanager
def gc_paused() -> Iterator[None]:
    """No garbage collection while a loop over a topic's chunks makes and drops millions of
    acyclic objects (a slice per message, a struct per decoded step): otherwise the
    collector walks every object the process holds, again and again, for nothing."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()
