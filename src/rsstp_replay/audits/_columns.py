"""Per-step columns of a long run, reduced without sorting them: the first index of each
value, a block of steps at a time."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["first_indices"]

_BLOCK = 1 << 16
"""Values whose first occurrences :func:`first_indices` finds together."""


def first_indices(
    values: npt.NDArray[np.integer[Any]], *, size: int | None = None
) -> npt.NDArray[np.int64]:
    """For every value ``0 .. size - 1`` (default: the largest value + 1) the first index at
    which ``values`` (non-negative integers) has it, -1 where it never does; a block of
    :data:`_BLOCK` values at a time (a block holding nothing new costs one gather)."""
    if size is None:
        size = int(values.max(initial=-1)) + 1
    first = np.full(size, -1, np.int64)
    for start in range(0, len(values), _BLOCK):
        block = values[start : start + _BLOCK]
        new = np.flatnonzero(first[block] < 0)
        if len(new):
            found, at = np.unique(block[new], return_index=True)
            first[found] = new[at] + start
    return first
