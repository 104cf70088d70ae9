"""Minimising a deterministic Moore machine: the project's one partition refinement.

The ground truth (:mod:`rsstp_sim.truth`) minimises the world's reachable poses with it and
the learner (:mod:`rsstp_sim.strategies.learner`) its complete hypothesis. Two states are in
one class when no action sequence tells them apart by what they show.

>>> moore_classes(np.array([[1], [2], [3], [0]]), [True, False, False, False]).tolist()
[3, 0, 1, 2]
>>> moore_classes(np.array([[1], [0]]), [False, False]).tolist()
[0, 0]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from rsstp_sim.arrays import BoolArray, IntArray, distinct

__all__ = ["moore_classes", "reached"]


def moore_classes(next_state: IntArray, output: ArrayLike) -> IntArray:
    """Moore's partition refinement: the coarsest partition of the states that keeps
    ``output`` and is stable under every action, as a class per state.

    ``next_state[s, k]`` is the successor of state ``s`` under the ``k``-th action (every
    state has one for every action); ``output[s]`` is what state ``s`` shows.

    Each round splits classes by the signature (class, class of each successor). The
    signature's numbers are packed into as few 64-bit words as their bit width allows (two
    for 39,000 classes and 6 actions), and one lexicographic sort of those words per round
    numbers the new classes: exact, with no hashing.
    """
    classes = np.unique(np.asarray(output), return_inverse=True)[1].astype(np.int64).ravel()
    count = int(classes.max(initial=-1)) + 1
    size = len(classes)
    while True:
        columns = [classes, *(classes[next_state[:, k]] for k in range(next_state.shape[1]))]
        words = _packed(columns, bits=max(1, count.bit_length()))
        order = np.lexsort(words[::-1])
        sorted_words = [word[order] for word in words]
        starts = np.zeros(size, np.bool_)
        if size:
            starts[0] = True
            for word in sorted_words:
                starts[1:] |= word[1:] != word[:-1]
        refined = np.empty(size, np.int64)
        refined[order] = np.cumsum(starts) - 1
        width = int(refined.max(initial=-1)) + 1
        if width == count:
            return classes
        classes, count = refined, width


def _packed(columns: list[IntArray], *, bits: int) -> list[IntArray]:
    """The columns' values (each below ``2**bits``) packed into 64-bit words, in order: the
    words sort as the rows of the columns do."""
    per_word = max(1, 63 // bits)
    words = []
    for first in range(0, len(columns), per_word):
        word = np.zeros_like(columns[0])
        for column in columns[first : first + per_word]:
            word = (word << bits) | column
        words.append(word)
    return words


def reached(tail: IntArray, head: IntArray, start: int, n: int) -> BoolArray:
    """The nodes ``0 .. n-1`` reached from ``start`` along the edges ``tail[i] -> head[i]``,
    breadth first, a whole frontier per numpy call."""
    order = np.argsort(tail, kind="stable")
    heads = head[order]
    bounds = np.searchsorted(tail[order], np.arange(n + 1, dtype=np.int64))
    seen = np.zeros(n, np.bool_)
    seen[start] = True
    frontier = np.array([start], np.int64)
    while len(frontier):
        lo, hi = bounds[frontier], bounds[frontier + 1]
        sizes = hi - lo
        offsets = np.repeat(lo - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
        following = distinct(heads[offsets])
        frontier = following[~seen[following]]
        seen[frontier] = True
    return seen
