"""Sending per-step columns to Rerun in chunks of a bounded number of rows.

One ``send_columns`` call per entity would make one chunk of the whole recording. Rerun reads
rows out of a chunk by slicing it, and for nested components (a line strip is a list of
points) that costs time in proportion to the chunk's length: ``rerun rrd verify`` of one
100,000-row ``LineStrips2D`` chunk takes minutes, of the same rows in 1,024-row chunks
seconds. So every per-step entity goes out in slices of :data:`CHUNK_ROWS` rows.

Many items that change now and then (a map's cells, a large model's states) go out in blocks,
an entity each, a row only where an item of the block changed (:func:`latest_rows`): the web
viewer's work grows with the entity paths, and a thousand paths of one point each also drew
points where none was logged (issue 32).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np
import numpy.typing as npt
import rerun as rr

__all__ = ["CHUNK_ROWS", "TIMELINE", "latest_rows", "send_rows"]

TIMELINE = "step"
CHUNK_ROWS = 1024


def send_rows(
    stream: rr.RecordingStream,
    path: str,
    steps: npt.NDArray[np.int64],
    columns: Callable[[slice], Iterable[rr.ComponentColumn]],
) -> int:
    """Send ``columns(rows)`` for every slice ``rows`` of at most :data:`CHUNK_ROWS` rows,
    at the matching ``steps``; returns the number of rows sent."""
    for begin in range(0, len(steps), CHUNK_ROWS):
        rows = slice(begin, begin + CHUNK_ROWS)
        stream.send_columns(
            path,
            indexes=[rr.TimeColumn(TIMELINE, sequence=steps[rows])],
            columns=columns(rows),
        )
    return len(steps)


def latest_rows(
    items: npt.NDArray[np.int64],
    steps: npt.NDArray[np.int64],
    values: npt.NDArray[np.int64],
    *,
    width: int,
    first: int,
    initial: int,
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """A block of ``width`` items, each holding a value (``initial`` until set), set by the
    changes ``values[k]`` of item ``items[k]`` at ``steps[k]`` (in order; a step before
    ``first`` counts at ``first``; the last change of an item at a step wins): the block's
    rows, shape ``(rows, width)``, at ``first`` and at every later step where an item
    changed, and their steps. Memory and time follow the rows times ``width``."""
    at = np.maximum(steps, first)
    times = np.unique(np.r_[first, at])
    row = np.searchsorted(times, at)
    table = np.full((len(times), width), initial, np.int64)
    set_at = np.zeros((len(times), width), np.bool_)
    table[row, items] = values
    set_at[row, items] = True
    # Each item holds the value of the last row that set it (row 0's value before any).
    source = np.maximum.accumulate(np.where(set_at, np.arange(len(times))[:, None], 0), axis=0)
    filled = table[source, np.arange(width)[None, :]]
    differs = np.r_[True, (filled[1:] != filled[:-1]).any(axis=1)]
    return filled[differs], times[differs]
