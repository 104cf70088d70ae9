"""Sending per-step columns to Rerun in chunks of a bounded number of rows.

One ``send_columns`` call per entity would make one chunk of the whole recording. Rerun reads
rows out of a chunk by slicing it, and for nested components (a line strip is a list of
points) that costs time in proportion to the chunk's length: ``rerun rrd verify`` of one
100,000-row ``LineStrips2D`` chunk takes minutes, of the same rows in 1,024-row chunks
seconds. So every per-step entity goes out in slices of :data:`CHUNK_ROWS` rows.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

import numpy as np
import numpy.typing as npt
import rerun as rr

__all__ = ["CHUNK_ROWS", "TIMELINE", "send_rows"]

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
