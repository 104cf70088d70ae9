"""What the ``splitter`` strategy must do, computed the plain way from its docstring.

The strategy (``rsstp_sim.strategies.splitter``) keeps interned contexts, bit masks and inverted
indexes so that a step costs little. This reference keeps none of that: it stores the memory as
three lists and, at every step, compares histories pair by pair, over the window since the last
split. It shares no code with the strategy; only its vocabulary.

The rules, as the strategy's docstring states them (``h`` is the horizon, ``now`` the step just
taken, ``since`` the step of the last split, 0 before the first):

- **History** of a visit ``t`` (``since <= t <= now``): the pairs ``(a_i, o_i)`` for
  ``t < i <= min(t + h, now)``. The **continuation** of the row ``(s_x, a_{x+1})`` from the
  visit ``x``: the history of ``x + 1``, at most ``h - 1`` pairs.
- Two histories **differ at k** when they have the same ``k`` actions, the same first ``k - 1``
  sensations and different ``k``-th sensations.
- **Contradiction** in a state: two of its visits whose histories differ at some ``k``.
- **Prune**, every step: ``u -a-> j`` is barred when a continuation of ``(u, a)`` differs from a
  history of a visit of ``j``. A row with a barred successor loses them all, unless that would
  empty it: then it goes to every state not barred, or to every state when all are.
- **Split**, after the prune, of a state with a contradiction: the lowest such state. Its
  visits whose history has the contradiction's ``k - 1`` pairs and ``k``-th action fall on two
  sides by their ``k``-th sensation; the state keeps the side of the earliest of them, a new
  state (DESIGN.md 2: rows and columns duplicated) takes the other. Then every transition into
  either half is deleted from a row ``(u, a)`` whose continuations differ from a history of
  that half's side (for the halves as sources, their own side's continuations; visits on no
  side count for neither). A row emptied by that goes to every state. Every history is then
  forgotten: ``since`` becomes ``now``.

The docstring leaves four things unsaid or loose, and this reference fixes them as the strategy
does: the prune comes before the split of the same step; of several states with a contradiction
the lowest is split; "the side its first visit was on" is the side of the earliest visit on
either side (the state's first visit since the last split may be on neither); and of several
contradictions of one state at one step, :meth:`ReferenceSplitter.choose` says which is taken.
"""

from __future__ import annotations

from collections.abc import Iterable

Row = tuple[int, int]
"""A row of the model: (state, action)."""


class PlainModel:
    """A transition system as rows ``(state, action) -> set of successors``, and a current state.

    Starts as one state with a self-loop per action; :meth:`split` hands out the next unused id.
    """

    def __init__(self, actions: Iterable[int]) -> None:
        self.actions = tuple(sorted(actions))
        self.states: list[int] = [0]
        self.rows: dict[Row, set[int]] = {(0, a): {0} for a in self.actions}
        self.current = 0

    def successors(self, u: int, a: int) -> list[int]:
        return sorted(self.rows[(u, a)])

    def split(self, s: int) -> int:
        """Duplicate the row and the column of ``s`` (a self-loop gives all four arrows)."""
        new = max(self.states) + 1
        for targets in self.rows.values():
            if s in targets:
                targets.add(new)
        for a in self.actions:
            self.rows[(new, a)] = set(self.rows[(s, a)])
        self.states.append(new)
        return new

    def transitions(self) -> list[tuple[int, int, int]]:
        """(source, action, target), sorted."""
        return sorted((u, a, t) for (u, a), targets in self.rows.items() for t in targets)


class ReferenceSplitter:
    """The splitter's model, step by step, from the actions and sensations the agent sees.

    :meth:`step` takes one step's action and sensation and the state the run moved to (the
    run's own draw when the model gives several successors: that choice is the runner's, not
    the strategy's), checks that its model allows that move, and refines its model.
    """

    def __init__(self, actions: Iterable[int], *, horizon: int, sensation: bool) -> None:
        self.model = PlainModel(actions)
        self.horizon = horizon
        self.actions: list[int] = [-1]
        self.states: list[int] = [0]
        self.sensations: list[bool] = [sensation]
        self.since = 0
        self.barred: dict[Row, set[int]] = {}
        self.splits: list[tuple[int, int]] = []
        """(step, state) of every split."""

    # -- the coupling ---------------------------------------------------------------------------

    def step(self, action: int, sensation: bool, moved_to: int) -> None:
        model = self.model
        successors = model.successors(model.current, action)
        allowed = successors or [model.current]
        assert moved_to in allowed, (
            f"step {len(self.actions)}: moved from {model.current} by {action} to {moved_to}; "
            f"the reference allows {allowed}"
        )
        model.current = moved_to
        self.actions.append(action)
        self.states.append(moved_to)
        self.sensations.append(sensation)
        now = len(self.actions) - 1
        self._bar_what_ends_at(now)
        self._prune()
        found = self._contradictions_ending_at(now)
        if found:
            state = min(state for state, _ in found)
            self._split(now, state, [v for s, v in found if s == state])

    # -- histories ------------------------------------------------------------------------------

    def differ_at(self, x: int, y: int, k: int) -> bool:
        """The histories of ``x`` and ``y`` differ at ``k`` (both have ``k`` pairs)."""
        a, o = self.actions, self.sensations
        return (
            o[x + k] != o[y + k]
            and a[x + 1 : x + k + 1] == a[y + 1 : y + k + 1]
            and o[x + 1 : x + k] == o[y + 1 : y + k]
        )

    def differ(self, x: int, y: int, most: int, now: int) -> bool:
        """The histories of ``x`` and ``y``, at most ``most`` pairs each, differ at some k."""
        return any(self.differ_at(x, y, k) for k in range(1, min(most, now - x, now - y) + 1))

    def _bar_what_ends_at(self, now: int) -> None:
        """Add to the barred sets the differences between a continuation and a history that
        the pair of step ``now`` completes (those completed earlier are in already)."""
        s, a = self.states, self.actions
        for k in range(1, self.horizon):
            x = now - 1 - k  # the continuation (history of x + 1) has its k-th pair at now
            if x >= self.since:
                for w in range(self.since, now - k + 1):
                    if self.differ_at(x + 1, w, k):
                        self.barred.setdefault((s[x], a[x + 1]), set()).add(s[w])
            w = now - k  # the history of w has its k-th pair at now
            if w >= self.since:
                for x in range(self.since, now - k):
                    if self.differ_at(x + 1, w, k):
                        self.barred.setdefault((s[x], a[x + 1]), set()).add(s[w])

    def _contradictions_ending_at(self, now: int) -> list[tuple[int, int]]:
        """(state, v): the history of the visit ``v`` differs, at its pair of step ``now``, from
        that of an earlier visit of the same state (earlier pairs showed none: a contradiction
        is split on the step it appears)."""
        s = self.states
        found = []
        for k in range(1, self.horizon + 1):
            v = now - k
            if v < self.since:
                break
            if any(s[w] == s[v] and self.differ_at(w, v, k) for w in range(self.since, v)):
                found.append((s[v], v))
        return found

    # -- prune and split ------------------------------------------------------------------------

    def _prune(self) -> None:
        model = self.model
        for row, targets in model.rows.items():
            bar = self.barred.get(row, set())
            bad = targets & bar
            if not bad:
                continue
            if bad != targets:
                targets -= bad
            else:
                free = {j for j in model.states if j not in bar}
                targets.clear()
                targets.update(free or model.states)

    def _split(self, now: int, state: int, candidates: list[int]) -> None:
        v = self.choose(now, candidates)
        k = now - v
        a, o = self.actions, self.sensations
        sides: dict[bool, list[int]] = {False: [], True: []}
        prefix = self.pairs(v, k - 1)
        for t in range(self.since, now - k + 1):
            if self.states[t] == state and self.pairs(t, k - 1) == prefix and a[t + k] == a[now]:
                sides[o[t + k]].append(t)
        keep, other = sorted(sides.values())
        new = self.model.split(state)
        self.splits.append((now, state))
        groups = {state: keep, new: other}
        sources = dict(groups)
        for x in range(self.since, now + 1):
            if self.states[x] != state:
                sources.setdefault(self.states[x], []).append(x)
        touched: set[Row] = set()
        h = self.horizon
        for u, xs in sources.items():
            for x in xs:
                if x == now:
                    continue
                row = (u, a[x + 1])
                for target, ws in groups.items():
                    if target in self.model.rows[row] and any(
                        self.differ(x + 1, w, h - 1, now) for w in ws
                    ):
                        self.model.rows[row].discard(target)
                        touched.add(row)
        for row in touched:
            if not self.model.rows[row]:
                self.model.rows[row].update(self.model.states)
        self.since = now
        self.barred = {}

    def choose(self, now: int, candidates: list[int]) -> int:
        """Which of a state's contradictions found at ``now`` (by the later visit ``v``) to
        split along: the one whose common prefix (the pairs of ``v`` before ``now``) was seen
        first, in any history since the last split; of two seen first at the same step, the
        longer. The docstring does not say; this is the strategy's order (its contexts are
        numbered as they are first seen, older visits first)."""

        def first_seen(v: int) -> tuple[int, int]:
            m = now - 1 - v
            if m == 0:
                return (-1, 0)
            prefix = self.pairs(v, m)
            seen = min(t + m for t in range(self.since, v + 1) if self.pairs(t, m) == prefix)
            return (seen, -m)

        return min(candidates, key=first_seen)

    def pairs(self, t: int, m: int) -> list[tuple[int, bool]]:
        """The first ``m`` pairs of the history of ``t``."""
        end = t + m + 1
        return list(zip(self.actions[t + 1 : end], self.sensations[t + 1 : end], strict=True))
