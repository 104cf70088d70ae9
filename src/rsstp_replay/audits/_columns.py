"""Per-step columns of a long run, reduced without sorting them: the first index of each
value, a block of steps at a time; each value's index among the distinct values."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from rsstp_sim.arrays import distinct

__all__ = ["factorized", "first_indices"]

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


def factorized(
    values: npt.NDArray[np.integer[Any]],
) -> tuple[npt.NDArray[np.integer[Any]], npt.NDArray[np.intp]]:
    """``np.unique(values, return_inverse=True)``: the distinct values, sorted (in the dtype of
    ``values``), and each value's index among them. Non-negative integers below four times
    their number (a state, an action, a version number per step) are counted in a table
    instead of sorted; others are sorted (not argsorted, as ``np.unique`` does: the values
    found, then each one's place among them)."""
    if len(values) and int(values.min()) >= 0 and int(values.max()) < 4 * len(values) + 2**16:
        present = np.zeros(int(values.max()) + 1, np.bool_)
        present[values] = True
        index = np.cumsum(present, dtype=np.intp)
        index -= 1
        return np.flatnonzero(present).astype(values.dtype, copy=False), index[values]
    found = distinct(values)
    return found, np.searchsorted(found, values).astype(np.intp, copy=False)
