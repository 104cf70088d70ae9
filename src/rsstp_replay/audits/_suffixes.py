"""Suffix order of an integer sequence, and the queries the consistency audit asks of it:
ranks by prefix doubling, common prefixes of pairs of suffixes, the nearest smaller value
and range minima. All numpy, ``O(n log n)`` time and at most that memory.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["RangeMin", "common_prefix_lengths", "nearest_at_most", "suffix_ranks"]

_IntArray = npt.NDArray[np.int64]


def suffix_ranks(symbols: _IntArray) -> list[npt.NDArray[np.integer[Any]]]:
    """Ranks of every suffix's prefixes of length 1, 2, 4, ...: ``levels[e][p] == levels[e][q]``
    iff the suffixes at ``p`` and ``q`` agree on their first ``2**e`` symbols (shorter suffixes
    sort first). Stops as soon as all ranks differ: the last level is the suffix order."""
    size = len(symbols)
    rank = np.unique(symbols, return_inverse=True)[1].astype(np.int64)
    # Kept as int32 where they fit (ranks < size): the levels are most of the audit's memory.
    store: type[np.integer[Any]] = np.int32 if size < 2**31 else np.int64
    levels: list[npt.NDArray[np.integer[Any]]] = [rank.astype(store)]
    distinct = int(rank.max()) + 1
    half = 1
    while distinct < size:
        following = np.zeros(size, dtype=np.int64)
        following[: size - half] = rank[half:] + 1
        key = rank * (size + 1) + following
        by_key = np.argsort(key)
        sorted_key = key[by_key]
        new_group = np.empty(size, dtype=np.int64)
        new_group[0] = 0
        np.not_equal(sorted_key[1:], sorted_key[:-1], out=new_group[1:])
        rank = np.empty(size, dtype=np.int64)
        rank[by_key] = np.cumsum(new_group)
        levels.append(rank.astype(store))
        distinct = int(rank[by_key[-1]]) + 1
        half *= 2
    return levels


def common_prefix_lengths(
    left: _IntArray, right: _IntArray, rank_levels: list[npt.NDArray[np.integer[Any]]]
) -> _IntArray:
    """Longest common prefix of the suffixes at ``left[x]`` and ``right[x]`` (all distinct),
    by binary lifting over the doubling levels (it is below ``2**(len(rank_levels) - 1)``)."""
    size = len(rank_levels[0])
    lcp = np.zeros(len(left), dtype=np.int64)
    for level in range(len(rank_levels) - 2, -1, -1):
        span = 1 << level
        at_left, at_right = left + lcp, right + lcp
        fits = (at_left + span <= size) & (at_right + span <= size)
        ranks = rank_levels[level]
        fits[fits] = ranks[at_left[fits]] == ranks[at_right[fits]]
        lcp += span * fits
    return lcp


def nearest_at_most(values: _IntArray, wanted: _IntArray, *, step: int) -> _IntArray:
    """For each position ``p`` of ``wanted``, the nearest position ``c`` before it (``step``
    -1) or after it (``step`` 1) with ``values[c] <= values[p]``; one must exist.

    Pointer jumping over every position at once, ``O(n)`` memory: ``near[x]`` starts at the
    neighbour and, while ``values[near[x]] > values[x]``, jumps to ``near[near[x]]`` (every
    value strictly between ``x`` and ``near[x]`` stays above ``values[x]``), so a chain halves
    each round.
    """
    size = len(values)
    index_type = np.int32 if size < 2**31 else np.int64
    near = np.arange(step, size + step, dtype=index_type)
    np.clip(near, 0, size - 1, out=near)
    active = np.flatnonzero(values[near] > values).astype(index_type)
    while active.size:
        near[active] = near[near[active]]
        active = active[values[near[active]] > values[active]]
    return near[wanted].astype(np.int64)


class RangeMin:
    """Range minima in ``O(n)`` memory: minima of blocks of :data:`_BLOCK` values with a sparse
    table over them, each value's minimum to the end and from the start of its block, and a
    sparse table of the first levels for ranges inside one block."""

    def __init__(self, values: _IntArray) -> None:
        dtype = np.int32 if len(values) < 2**31 and values.max(initial=0) < 2**31 else np.int64
        self.values: npt.NDArray[np.integer[Any]] = values.astype(dtype)
        self.near = _sparse_table(self.values, levels=_BLOCK_LEVELS)
        n_blocks = -(-len(values) // _BLOCK)
        padded: npt.NDArray[np.integer[Any]] = np.full(
            n_blocks * _BLOCK, np.iinfo(dtype).max, dtype
        )
        padded[: len(values)] = self.values
        blocks = padded.reshape(n_blocks, _BLOCK)
        self.from_start = np.minimum.accumulate(blocks, axis=1).ravel()
        self.to_end = np.minimum.accumulate(blocks[:, ::-1], axis=1)[:, ::-1].ravel()
        self.blocks = _sparse_table(blocks.min(axis=1), levels=None)

    def query(self, first: _IntArray, last: _IntArray) -> _IntArray:
        """``min(values[first[x] : last[x] + 1])`` for every ``x`` (non-empty ranges)."""
        result = np.empty(len(first), dtype=np.int64)
        block_first, block_last = first // _BLOCK, last // _BLOCK
        inside = block_first == block_last
        result[inside] = _table_min(self.near, first[inside], last[inside])
        across = ~inside
        f, lst = first[across], last[across]
        bf, bl = block_first[across], block_last[across]
        best = np.minimum(self.to_end[f], self.from_start[lst]).astype(np.int64)
        middle = bl - bf > 1
        best[middle] = np.minimum(
            best[middle], _table_min(self.blocks, bf[middle] + 1, bl[middle] - 1)
        )
        result[across] = best
        return result


_BLOCK_LEVELS = 9
_BLOCK = 1 << (_BLOCK_LEVELS - 1)
"""Values per block of :class:`RangeMin` (256): ranges inside a block use the first levels."""


def _sparse_table(
    values: npt.NDArray[np.integer[Any]], *, levels: int | None
) -> list[npt.NDArray[np.integer[Any]]]:
    """``table[e][x] = min(values[x : x + 2**e])`` for ``e`` below ``levels`` (all: None)."""
    table = [values]
    span = 1
    while 2 * span <= len(values) and (levels is None or len(table) < levels):
        previous = table[-1]
        table.append(np.minimum(previous[:-span], previous[span:]))
        span *= 2
    return table


def _table_min(
    table: list[npt.NDArray[np.integer[Any]]], first: _IntArray, last: _IntArray
) -> _IntArray:
    """``min(values[first[x] : last[x] + 1])`` from a sparse table covering those lengths."""
    length = last - first + 1
    level = np.zeros(len(first), dtype=np.int64)
    while True:  # level = floor(log2(length)), exact in integers
        grow = (2 << level) <= length
        if not grow.any():
            break
        level += grow
    result = np.empty(len(first), dtype=np.int64)
    for value in np.unique(level):
        chosen = level == value
        rows = table[int(value)]
        result[chosen] = np.minimum(rows[first[chosen]], rows[last[chosen] - (1 << int(value)) + 1])
    return result
