"""What the learner asks of its confirmed transitions again and again, kept up to date as they
change one at a time instead of worked out afresh over every state.

The hypothesis (:class:`~rsstp_sim.strategies._learner_hypothesis.Hypothesis`) writes each
confirmed successor through :meth:`Incoming.set`, which keeps, beside its ``next`` array:

- the transitions *into* each state (who leads here, and by which action column): what
  :meth:`Hypothesis.inverses` counts on, what the learner's votes for a candidate follow, and
  how a shorter way to the landmark spreads back;
- for each pair of action columns ``(a, b)``, among the confirmed moves ``s -a-> t`` with
  ``t != s``: how many have ``t -b-> s`` (``back``) and how many have a confirmed ``t -b->``
  at all (``known``), the counts that tell which action undoes which;
- for each pair of action columns ``(a, b)``, ``a < b``, among the states ``s`` with
  ``s -a-> r -b-> y`` and ``s -b-> q -a-> z`` all confirmed (a *square*): how many there are
  (``squares``) and how many close, ``y == z`` (``closed``), the counts that tell which actions
  commute;
- for each state, how many of its actions have no confirmed successor (``open``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["Incoming"]


class Incoming:
    """The confirmed transitions into each state, and the counts above, for ``width`` actions.

    ``into[t]``: the codes ``s * width + k`` of the confirmed ``s -k-> t`` (k an action column).
    ``back[a][b]`` and ``known[a][b]``: the counts of the module docstring, by column.
    ``squares[a][b]`` and ``closed[a][b]`` (``a < b``; 0 elsewhere): the squares of the module
    docstring, over every row of ``next_`` (a state gone has an empty row).
    ``open[s]``: the columns of ``s`` with no confirmed successor, for the states
    :meth:`open_row` was told are alive (0 for the others).
    """

    def __init__(self, width: int, capacity: int) -> None:
        self.width = width
        self.into: dict[int, set[int]] = {}
        self.back = [[0] * width for _ in range(width)]
        self.known = [[0] * width for _ in range(width)]
        self.squares = [[0] * width for _ in range(width)]
        self.closed = [[0] * width for _ in range(width)]
        self.open: NDArray[np.int64] = np.zeros(capacity, dtype=np.int64)
        self._alive: set[int] = set()

    def grow(self, capacity: int) -> None:
        if capacity > len(self.open):
            grown = np.zeros(capacity, dtype=np.int64)
            grown[: len(self.open)] = self.open
            self.open = grown

    def open_row(self, s: int, row: NDArray[np.int64]) -> None:
        """State ``s`` is alive, its confirmed successors ``row`` (-1: none)."""
        self._alive.add(s)
        self.open[s] = int(np.count_nonzero(row < 0))

    def close_row(self, s: int) -> None:
        """State ``s`` is gone (its row emptied first)."""
        self._alive.discard(s)
        self.open[s] = 0

    def predecessors(self, t: int) -> list[tuple[int, int]]:
        """The confirmed transitions into ``t``, as ``(source, action column)``."""
        width = self.width
        return [divmod(code, width) for code in self.into.get(t, ())]

    def set(self, next_: NDArray[np.int64], s: int, k: int, t: int) -> None:
        """``next_[s, k] = t`` (-1: unconfirmed), and the indexes kept with it."""
        old = int(next_[s, k])
        if old == t:
            return
        width = self.width
        into = self.into
        back, known = self.back, self.known
        code = s * width + k
        # The squares s -k-> is a side of: from s, by k and another action; from each state
        # p leading to s by c, by c and k (s -k-> their second side).
        sides = {(s, min(k, b), max(k, b)) for b in range(width) if b != k}
        for other in into.get(s, ()):
            p, c = divmod(other, width)
            if p != s and c != k:
                sides.add((p, min(c, k), max(c, k)))
        for p, a, b in sides:
            self._square(next_, p, a, b, -1)
        if old >= 0:
            if old != s:
                self._count(next_, s, k, old, -1)
            into[old].discard(code)
        # The transitions into s, with s -k-> as the move back.
        for other in into.get(s, ()):
            u, a = divmod(other, width)
            if u == s:
                continue
            if old >= 0:
                known[a][k] -= 1
                back[a][k] -= old == u
            if t >= 0:
                known[a][k] += 1
                back[a][k] += t == u
        next_[s, k] = t
        if t >= 0:
            into.setdefault(t, set()).add(code)
            if t != s:
                self._count(next_, s, k, t, 1)
        if s in self._alive:
            self.open[s] += (t < 0) - (old < 0)
        for p, a, b in sides:
            self._square(next_, p, a, b, 1)

    def _square(self, next_: NDArray[np.int64], p: int, a: int, b: int, sign: int) -> None:
        """Count the square from ``p`` by actions ``a < b`` in or out (``sign``) of
        ``squares``/``closed``, if its four sides are confirmed."""
        r, q = int(next_[p, a]), int(next_[p, b])
        if r < 0 or q < 0:
            return
        y, z = int(next_[r, b]), int(next_[q, a])
        if y >= 0 and z >= 0:
            self.squares[a][b] += sign
            self.closed[a][b] += sign * (y == z)

    def _count(self, next_: NDArray[np.int64], s: int, a: int, t: int, sign: int) -> None:
        """Count the move ``s -a-> t`` (``t != s``) in or out (``sign``) of ``back``/``known``."""
        back, known = self.back[a], self.known[a]
        for b, v in enumerate(next_[t].tolist()):
            if v >= 0:
                known[b] += sign
                if v == s:
                    back[b] += sign
