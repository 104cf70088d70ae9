"""Suffix order of an integer sequence, and the queries the consistency audit asks of it:
ranks by prefix doubling, common prefixes of pairs of suffixes, the nearest smaller value
and range minima. All numpy, ``O(n log n)`` time.

Memory is what bounds the audit of a long recording, so every array of one value per
position is as narrow as its values allow: positions and ranks in int32 (below ``2**31``
positions), each doubling level in the narrowest unsigned type that holds its ranks (the
first levels of a walk over a few actions fit in a byte), and the common prefixes are
computed a block of pairs at a time.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = [
    "RangeMin",
    "common_prefix_lengths",
    "index_type",
    "nearest_at_most",
    "suffix_ranks",
]

_IntArray = npt.NDArray[np.int64]
_AnyInts = npt.NDArray[np.integer[Any]]
_PAIRS_AT_ONCE = 1 << 18
"""Pairs of suffixes whose common prefix :func:`common_prefix_lengths` computes together."""


def index_type(size: int) -> type[np.integer[Any]]:
    """The integer type of positions and ranks below ``size``: int32 while they fit."""
    return np.int32 if size < 2**31 else np.int64


def _narrowest(distinct: int, size: int) -> type[np.integer[Any]]:
    """The narrowest type of ranks ``0 .. distinct - 1`` (``size`` positions in all)."""
    if distinct <= 2**8:
        return np.uint8
    if distinct <= 2**16:
        return np.uint16
    return index_type(size)


def suffix_ranks(symbols: _AnyInts) -> list[_AnyInts]:
    """Ranks of every suffix's prefixes of length 1, 2, 4, ...: ``levels[e][p] == levels[e][q]``
    iff the suffixes at ``p`` and ``q`` agree on their first ``2**e`` symbols (shorter suffixes
    sort first). Stops as soon as all ranks differ: the last level is the suffix order.

    A round ranks each suffix by the pair (its rank, the rank ``2**e`` further on). While the
    pairs are few (:data:`_COUNTED_PAIRS` per position: the first rounds, over a few
    actions), a count of each pair ranks them, with no sort. Then the pairs are sorted, and
    after the first sorted round only the suffixes that still share their rank with another
    are (Manber and Myers' doubling, skipping the finished groups): in a long walk most
    suffixes are told apart within a few rounds, a few run on for many.

    Each level is kept in :func:`_narrowest` type of its ranks; besides the levels, a round
    holds the ranks (int32), the suffix order, and the 64-bit sort key of the suffixes
    sorted, its order and the sorted keys."""
    size = len(symbols)
    positions = index_type(size)
    inverse = np.unique(symbols, return_inverse=True)[1]
    rank = inverse.astype(positions)
    del inverse
    distinct = int(rank.max()) + 1
    levels: list[_AnyInts] = [rank.astype(_narrowest(distinct, size))]
    half = 1
    order: npt.NDArray[np.integer[Any]] | None = None  # the suffixes in rank order
    while distinct < size:
        if order is None and distinct * (distinct + 1) <= _COUNTED_PAIRS * size:
            rank, distinct = _counted_round(rank, half, distinct)
        elif order is None:
            rank, order, distinct = _sorted_round(rank, half)
        else:
            rank, distinct = _unfinished_round(rank, order, half)
        levels.append(rank.astype(_narrowest(distinct, size), copy=False))
        half *= 2
    return levels


_COUNTED_PAIRS = 1
"""A doubling round counts its pairs of ranks (an array of one count per possible pair)
while there are at most this many possible pairs per position; past that it sorts them."""


def _pair_keys(rank: _AnyInts, half: int, indices: _AnyInts | None = None) -> _IntArray:
    """``rank[p] * (size + 1) + rank[p + half] + 1`` (0 in place of the second past the end)
    for every position, or for ``indices``: ordered as the pairs are."""
    size = len(rank)
    if indices is None:
        key = rank.astype(np.int64)
        key *= size + 1
        key[: size - half] += rank[half:]
        key[: size - half] += 1
        return key
    key = rank[indices].astype(np.int64)
    key *= size + 1
    further = indices.astype(np.int64) + half
    inside = further < size
    key[inside] += rank[further[inside]].astype(np.int64) + 1
    return key


def _counted_round(rank: _AnyInts, half: int, distinct: int) -> tuple[_AnyInts, int]:
    """The next level's ranks when the pairs are few: each pair's rank is the number of
    distinct pairs below it, counted over all ``distinct * (distinct + 1)`` possible pairs."""
    size = len(rank)
    key = rank.astype(np.int64)
    key *= distinct + 1
    key[: size - half] += rank[half:]
    key[: size - half] += 1
    present = np.bincount(key, minlength=distinct * (distinct + 1)) > 0
    ranks_of_keys = np.cumsum(present, dtype=index_type(size))
    ranks_of_keys -= 1
    new_rank: _AnyInts = ranks_of_keys[key]
    return new_rank, int(ranks_of_keys[-1]) + 1


def _sorted_round(rank: _AnyInts, half: int) -> tuple[_AnyInts, _AnyInts, int]:
    """The next level's ranks, every suffix sorted by its pair; and the suffix order."""
    size = len(rank)
    key = _pair_keys(rank, half)
    order = np.argsort(key).astype(rank.dtype, copy=False)
    sorted_key = key[order]
    del key
    head = np.empty(size, dtype=np.bool_)
    head[0] = False
    np.not_equal(sorted_key[1:], sorted_key[:-1], out=head[1:])
    del sorted_key
    new_rank = np.empty(size, dtype=rank.dtype)
    new_rank[order] = np.cumsum(head, dtype=rank.dtype)
    return new_rank, order, int(new_rank[order[-1]]) + 1


def _unfinished_round(rank: _AnyInts, order: _AnyInts, half: int) -> tuple[_AnyInts, int]:
    """The next level's ranks (``order`` kept the suffix order, in place), by sorting only
    the groups of suffixes that share a rank (the others keep their place); and the number of
    distinct ranks."""
    size = len(rank)
    in_order = rank[order]
    head = np.empty(size, dtype=np.bool_)
    head[0] = True
    np.not_equal(in_order[1:], in_order[:-1], out=head[1:])
    del in_order
    # A slot is unfinished when its group has another slot: it is not both a head and
    # followed by a head.
    finished = head.copy()
    finished[:-1] &= head[1:]
    unfinished = np.flatnonzero(~finished)
    del finished
    suffixes = order[unfinished]
    key = _pair_keys(rank, half, suffixes)
    by_key = np.argsort(key)
    sorted_key = key[by_key]
    del key
    order[unfinished] = suffixes[by_key]
    del suffixes, by_key
    # Inside the unfinished slots a new group starts where the pair changes (between two
    # old groups the first rank differs).
    head[unfinished[1:]] = sorted_key[1:] != sorted_key[:-1]
    del sorted_key, unfinished
    new_rank = np.empty(size, dtype=rank.dtype)
    new_rank[order] = np.cumsum(head, dtype=rank.dtype)
    new_rank[order] -= 1
    return new_rank, int(new_rank[order[-1]]) + 1


def common_prefix_lengths(left: _AnyInts, right: _AnyInts, rank_levels: list[_AnyInts]) -> _AnyInts:
    """Longest common prefix of the suffixes at ``left[x]`` and ``right[x]`` (all distinct),
    by binary lifting over the doubling levels (it is below ``2**(len(rank_levels) - 1)``),
    :data:`_PAIRS_AT_ONCE` pairs at a time; in :func:`index_type`."""
    size = len(rank_levels[0])
    lcp = np.empty(len(left), dtype=index_type(size))
    for first in range(0, len(left), _PAIRS_AT_ONCE):
        last = first + _PAIRS_AT_ONCE
        lcp[first:last] = _common_prefix(
            left[first:last].astype(np.int64), right[first:last].astype(np.int64), rank_levels
        )
    return lcp


def _common_prefix(left: _IntArray, right: _IntArray, rank_levels: list[_AnyInts]) -> _IntArray:
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


def nearest_at_most(values: _AnyInts, wanted: _IntArray, *, step: int) -> _IntArray:
    """For each position ``p`` of ``wanted``, the nearest position ``c`` before it (``step``
    -1) or after it (``step`` 1) with ``values[c] <= values[p]``; one must exist.

    Pointer jumping over every position at once, ``O(n)`` memory: ``near[x]`` starts at the
    neighbour and, while ``values[near[x]] > values[x]``, jumps to ``near[near[x]]`` (every
    value strictly between ``x`` and ``near[x]`` stays above ``values[x]``), so a chain halves
    each round.
    """
    size = len(values)
    positions = index_type(size)
    near = np.arange(step, size + step, dtype=positions)
    np.clip(near, 0, size - 1, out=near)
    active = np.flatnonzero(values[near] > values).astype(positions)
    while active.size:
        near[active] = near[near[active]]
        active = active[values[near[active]] > values[active]]
    return near[wanted].astype(np.int64)


class RangeMin:
    """Range minima in ``O(n)`` memory (about eight values per position): minima of blocks of
    :data:`_BLOCK` values with a sparse table over them, each value's minimum to the end and
    from the start of its block, and a sparse table of the first levels for ranges inside
    one block."""

    def __init__(self, values: _AnyInts) -> None:
        dtype = np.int32 if len(values) < 2**31 and values.max(initial=0) < 2**31 else np.int64
        self.values: npt.NDArray[np.integer[Any]] = values.astype(dtype, copy=False)
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


_BLOCK_LEVELS = 5
_BLOCK = 1 << (_BLOCK_LEVELS - 1)
"""Values per block of :class:`RangeMin` (16): ranges inside a block use the first levels
(four arrays of one value per position besides the values), the others the blocks'
sparse table (a sixteenth of a value per position and level)."""


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
