"""The numpy array types the simulator's signatures use, named once, and :func:`distinct`."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["BoolArray", "FloatArray", "Int32Array", "IntArray", "distinct"]

BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
Int32Array = NDArray[np.int32]


def distinct(values: NDArray[Any]) -> NDArray[Any]:
    """The distinct values of ``values`` (flattened), sorted: ``np.unique(values)``, by a sort.

    numpy 2.3 and later find plain ``np.unique``'s values by hashing, which is about 60 times
    slower than sorting when most of two million int64 values are distinct (2.26 s against
    35 ms, numpy 2.4.6): the audits' per-step pairs are such arrays."""
    ordered = np.sort(values, axis=None)
    if not len(ordered):
        return ordered
    kept = np.empty(len(ordered), np.bool_)
    kept[0] = True
    np.not_equal(ordered[1:], ordered[:-1], out=kept[1:])
    return ordered[kept]
