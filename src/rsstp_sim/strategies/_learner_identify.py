"""Identification: which state does a (state, action) pair lead to? Rule candidates out.

Following a candidate's confirmed path to the landmark from the world state being identified,
the candidates predicting a different sensation on the way are ruled out. No reset is needed:
reaching the landmark tells the agent where it is.
"""

from __future__ import annotations

from collections.abc import Generator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from rsstp_sim.strategies._base import AgentView
from rsstp_sim.strategies._learner_hypothesis import FAR, BoolArray
from rsstp_sim.strategies._learner_walk import Plan, Walker

__all__ = ["Deferral", "Identifier", "Trace"]

Trace = tuple[tuple[int, ...], tuple[bool, ...], tuple[float, ...]]
"""A test: its actions, the sensations before the first and after each action, and the
float feedback felt there (empty when the agent has none)."""

FEW = 24
"""A test follows this many candidates or fewer one at a time (:meth:`Identifier.session`):
fewer steps of Python than the arrays' fixed cost."""

LOCATED_STEPS = 2
"""With float feedback, a test ends when one candidate is left and it has agreed with what
was sensed and felt for this many steps: the agent is located there
(:meth:`Identifier.session`); :data:`SHARED_LOCATED_STEPS` where the feel is shared."""

SHARED_LOCATED_STEPS = 6
""":data:`LOCATED_STEPS` where many states feel alike (:meth:`Hypothesis.feel_shared`): two
steps that agree then say little (an 8 x 8 rover room was done with a wrong model)."""

SHARED_DOUBTS = 64
"""The ``doubts`` (the candidates left after the way back that are still tested one by one,
:meth:`Identifier.identify`) where many states feel alike, at least: a state taken as new
there is most often another pose felt alike, and its own transitions, taken as new in turn,
grow a copy of the room (in rover rooms of 36 to 256 classes, 1 doubt left 2 to 9 states a
class at 4 N^2 steps; 8 or 64 learned them)."""


@dataclass(frozen=True, slots=True)
class Deferral:
    """An identification put off: the candidates nothing could tell apart, the word from the
    landmark that led to the world state, its sensation, and the model version then."""

    candidates: frozenset[int]
    access: tuple[int, ...]
    label: bool
    version: int
    feel: float = 0.0


class Identifier(Walker):
    """Identifies the targets of (state, action) pairs; keeps the tests made as evidence.

    ``traces[(q, a)]``: the tests made from the world state ``q -a->`` led to. ``deferred``:
    the pairs whose candidates nothing could tell apart yet (:class:`Deferral`).
    ``made_by[s]``: the action that led to the world state ``s`` was created for.
    """

    def __init__(self, agent: AgentView, *, doubts: int) -> None:
        super().__init__(agent)
        self.doubts = doubts
        self.made_by: dict[int, int] = {}
        self.traces: dict[tuple[int, int], list[Trace]] = {}
        self.deferred: dict[tuple[int, int], Deferral] = {}
        self._singles = np.zeros((0, len(self.h.actions)), dtype=np.int8)
        self._singles_edits = -1
        self.retested: set[tuple[int, int]] = set()
        """The (state, action column) pairs whose tests changed since the verification last
        looked (:meth:`Learning.suspect <rsstp_sim.strategies._learner_plan.Learning.suspect>`)."""

    def confirm(self, q: int, a: int, t: int) -> None:
        self.deferred.pop((q, a), None)
        self.h.confirm(q, a, t)

    def new(
        self, q: int, a: int, label: bool, access: tuple[int, ...], *, here: bool, feel: float
    ) -> int:
        """A new state for ``q -a->``, felt ``feel``; ``here``: the agent is at it now."""
        self.deferred.pop((q, a), None)
        new = self.h.create(q, a, label, access, feel if self.h.feels else np.nan)
        self.made_by[new] = a
        self.count("new_states")
        if here:
            self.belief = new
            if self.beliefs:
                self.beliefs[-1] = new
        return new

    def identify(
        self,
        q: int,
        a: int,
        label: bool,
        access: tuple[int, ...],
        *,
        here: bool,
        feel: float,
        exclude: frozenset[int] = frozenset(),
        route: tuple[int, ...] | None = None,
    ) -> Plan:
        """Which state does ``q -a->`` lead to? Rule candidates out until one or none is left.

        Tests, in order: the paths to the landmark of the candidates confirmed transitions
        point at (:meth:`predict`); then the way back (the action undoing ``a``, then ``q``'s
        path to the landmark), which reaches the landmark if the state is new; then the paths
        of the candidates the way back could not rule out, if there are at most ``doubts`` of
        them (else the state is taken as new: a later merge undoes that if it was not).
        ``here``: the agent is at that world state now. ``exclude``: states already ruled
        out. ``route``: reach the world state again from the landmark by this word (else by a
        confirmed path to ``q``). ``feel``: the float feedback felt there (with float
        feedback, the candidates felt otherwise are ruled out, and a test may end with the
        agent located, :meth:`session`).
        """
        h = self.h
        shared = h.feel_shared()
        candidates = set(h.matching(label, feel)) - exclude
        undo = h.inverses().get(a)
        ranked = self.predict(q, a, candidates, undo)
        tried: set[int] = set()
        separate: list[int] | None = None
        returned = came_back = False
        while True:
            if not candidates:
                self.new(q, a, label, access, here=here, feel=feel)
                return
            distance = h.distance
            script: list[int] = []
            first: int | None = None
            follow = True
            if separate is not None:
                script, separate = separate, None
            else:
                first = next(
                    (c for c in ranked if c in candidates and c not in tried and distance[c] < FAR),
                    None,
                )
                if first is None and undo is not None and not returned:
                    way_back = h.path(q, h.landmark)
                    if way_back is not None:
                        script, follow, returned = [undo, *way_back], False, True
                if first is None and not script:
                    pool = np.fromiter(candidates, dtype=np.int64, count=len(candidates))
                    pool = pool[distance[pool] < FAR]
                    if tried:
                        pool = pool[~np.isin(pool, list(tried))]
                    if came_back:
                        # The way back reached the landmark: a candidate whose confirmed
                        # transition by ``undo`` leads elsewhere is not it.
                        column = h.column[undo] if undo is not None else 0
                        pool = pool[h.next[pool, column] < 0]
                        doubts = max(self.doubts, SHARED_DOUBTS) if shared else self.doubts
                        if not len(pool) or len(pool) > doubts or tried - set(ranked):
                            self.count("taken_as_new")
                            self.new(q, a, label, access, here=False, feel=feel)
                            return
                    if not len(pool):  # nothing can tell these candidates apart yet
                        self.count("deferred")
                        self.deferred[(q, a)] = Deferral(
                            frozenset(candidates), access, label, h.version, feel
                        )
                        return
                    pool.sort()  # (a choice among equals, by id)
                    far = distance[pool]
                    first = self.pick(pool[far == far.min()].tolist())
                if first is not None:
                    tried.add(first)
            if not here:
                arrived = yield from self.return_to(q, a, route)
                if arrived is None:
                    return
                if arrived:
                    self.confirm(q, a, h.landmark)
                    return
                felt = self.feel()
                if arrived != label or (h.feels and felt != feel):
                    # q stands for two world states: start afresh
                    self.count("restarts")
                    yield from self.identify(q, a, arrived, tuple(self.word), here=True, feel=felt)
                    return
            self.count("sessions")
            start = self.agent.step
            survivors, candidates, at_landmark, located = yield from self.session(
                (q, a), candidates, first, script, follow=follow
            )
            self.record(q, a, label, feel, start)
            here = False
            if located is not None:  # by what it sensed and felt
                self.confirm(q, a, located)
                return
            if not follow:  # the way back
                came_back = at_landmark
                ranked = sorted(survivors) + ranked
                continue
            if at_landmark and survivors:
                ruled = {c for c in survivors if not self.plausible(q, a, c, undo)}
                if ruled:
                    self.count("implausible", len(ruled))
                    candidates -= ruled
                    survivors -= ruled
                    if not survivors:
                        continue
                # The predicted first: if nothing confirmed tells two apart, the likelier.
                ordered = sorted(
                    survivors, key=lambda c: (ranked.index(c) if c in ranked else len(ranked), c)
                )
                word = None if len(ordered) == 1 else h.separating_word(ordered[0], ordered[1])
                if word is None:
                    blocked = q in candidates and q not in survivors and q not in tried
                    if blocked and h.distance[q] < FAR:
                        # The move may have been blocked: follow q itself through too.
                        ranked = [q, *ordered, *ranked]
                        continue
                    self.confirm(q, a, ordered[0])
                    return
                separate = word
                tried -= survivors  # each may need its own path again after the separation

    def plausible(self, q: int, a: int, c: int, undo: int | None) -> bool:
        """Whether ``q -a-> c`` fits the confirmed transitions, moves being one-to-one
        (:attr:`~Hypothesis.one_to_one`): not when ``a`` moves (``c`` shown apart from ``q``)
        and another state shown apart from both already leads to ``c`` by ``a`` (two states
        would), nor, while every action has an undoing one, when ``c``'s confirmed undo leads
        to a state shown apart from ``q``. A path to the landmark can reach it from a state it
        was not planned from, where blocked moves bring two walks together; these do not."""
        h = self.h
        if not h.one_to_one or c == q or not h.apart(q, c):
            return True
        k = h.column[a]
        for u, column in h.incoming.predecessors(c):
            if column == k and u not in (q, c) and h.apart(u, c) and h.apart(u, q):
                return False
        if undo is not None and h.reversible():
            back = int(h.next[c, h.column[undo]])
            if back >= 0 and back != q and h.apart(back, q):
                return False
        return True

    def predict(self, q: int, a: int, candidates: set[int], undo: int | None) -> list[int]:
        """Candidates for ``q -a->`` that confirmed transitions point at, most votes first.

        Two votes for ``c`` when ``c -undo-> q``; one for the far corner ``y`` of each square
        ``p -b-> q``, ``p -a-> r -b-> y`` (actions that commute, as two joints' turns do: not
        where the confirmed squares show ``a`` and ``b`` do not, :meth:`~Hypothesis.not_commuting`).
        """
        h = self.h
        votes: dict[int, int] = {}
        if undo is not None:
            k = h.column[undo]
            for c, column in h.incoming.predecessors(q):  # (the states c -undo-> q)
                if column == k and c in candidates:
                    votes[c] = votes.get(c, 0) + 2
        column = h.column[a]
        apart = h.not_commuting()[column]
        for p, kb in h.incoming.predecessors(q):
            if apart[kb]:
                continue
            r = int(h.next[p, column])
            if r >= 0:
                y = int(h.next[r, kb])
                if y in candidates:
                    votes[y] = votes.get(y, 0) + 1
        if len(votes) < 2:  # (a permutation of one draws nothing from the generator)
            return list(votes)
        tie = {c: i for i, c in enumerate(self.agent.rng.permutation(sorted(votes)).tolist())}
        return sorted(votes, key=lambda c: (-votes[c], tie[c]))

    def session(
        self,
        via: tuple[int, int],
        candidates: set[int],
        first: int | None,
        script: list[int],
        *,
        follow: bool = True,
    ) -> Generator[int, bool, tuple[set[int], set[int], bool, int | None]]:
        """One test from the world state ``via`` led to: follow paths to the landmark.

        Plays ``script`` first; then (if ``follow``) follows ``first``'s path to the landmark,
        and the nearest remaining candidate's when ``first`` is ruled out. A candidate is
        followed on the hypothesis that it is the world state, ``via`` leading to it. Returns
        the candidates that reached the landmark with the world (if it was reached), the
        candidates not ruled out, whether the landmark was reached, and the candidate the
        agent was located as (else None): with float feedback, when one candidate is left,
        followed, agreeing with what was sensed and felt for :data:`LOCATED_STEPS` steps
        (:data:`SHARED_LOCATED_STEPS` where the feel is shared), the
        test ends there and the agent believes it is where that candidate is now.
        """
        h = self.h
        located_after = SHARED_LOCATED_STEPS if h.feel_shared() else LOCATED_STEPS
        ids = np.asarray(sorted(candidates), dtype=np.int64)
        position = ids.copy()
        tracked = np.ones(len(ids), dtype=bool)
        chosen = first
        script = list(script)
        at_landmark = False
        taken = 0
        while len(ids) or script:
            if len(ids) <= FEW:
                return (
                    yield from self._session_few(
                        via, ids.tolist(), position.tolist(), tracked.tolist(), chosen, script,
                        follow=follow, taken=taken, located_after=located_after,
                    )
                )  # fmt: skip
            if script:
                action = script.pop(0)
            elif not follow:
                break
            else:
                distance = h.distance[position]
                index = -1
                if chosen is not None:
                    where = np.flatnonzero((ids == chosen) & tracked)
                    if len(where) and distance[where[0]] < FAR:
                        index = int(where[0])
                if index < 0:
                    usable = np.flatnonzero(tracked & (distance < FAR))
                    if not len(usable):
                        break
                    nearest = distance[usable] == distance[usable].min()
                    index = self.pick(usable[nearest].tolist())
                    chosen = int(ids[index])
                action = h.actions[int(h.toward[position[index]])]
                if position[index] == via[0] and action == via[1]:
                    # Its path goes through ``via``, which leads back to it on this
                    # hypothesis: followed, it would go round for ever.
                    tracked[index] = False
                    continue
            sensation = yield from self.move(action)
            taken += 1
            moved = h.step(ids, position, action, via)
            tracked &= moved >= 0
            position = np.where(tracked, moved, position)
            keep = ~tracked | h.agree(position, sensation, self.feel())
            ids, position, tracked = ids[keep], position[keep], tracked[keep]
            if sensation:
                at_landmark = True
                break
            if h.feels and taken >= located_after and len(ids) == 1 and tracked[0]:
                self.belief = int(position[0])
                self.beliefs[-1] = self.belief
                return {int(ids[0])}, {int(ids[0])}, False, int(ids[0])
        survivors = set(ids[tracked].tolist()) if at_landmark else set()
        return survivors, set(ids.tolist()), at_landmark, None

    def _session_few(
        self,
        via: tuple[int, int],
        ids: list[int],
        position: list[int],
        tracked: list[bool],
        chosen: int | None,
        script: list[int],
        *,
        follow: bool,
        taken: int,
        located_after: int,
    ) -> Generator[int, bool, tuple[set[int], set[int], bool, int | None]]:
        """:meth:`session` on from where it is, with :data:`FEW` candidates or fewer: one at a
        time, in lists (``ids[i]`` followed from ``position[i]``, ruled out when it disagrees
        while ``tracked[i]``), the same steps as the arrays take."""
        h = self.h
        at_landmark = False
        while ids or script:
            if script:
                action = script.pop(0)
            elif not follow:
                break
            else:
                distance = h.distance
                index = -1
                if chosen is not None and chosen in ids:
                    i = ids.index(chosen)
                    if tracked[i] and distance[position[i]] < FAR:
                        index = i
                if index < 0:
                    usable = [i for i, t in enumerate(tracked) if t and distance[position[i]] < FAR]
                    if not usable:
                        break
                    least = min(int(distance[position[i]]) for i in usable)
                    index = self.pick([i for i in usable if distance[position[i]] == least])
                    chosen = ids[index]
                action = h.actions[int(h.toward[position[index]])]
                if position[index] == via[0] and action == via[1]:
                    tracked[index] = False  # (it would go round for ever: see session)
                    continue
            sensation = yield from self.move(action)
            taken += 1
            feel = self.feel()
            column = h.next[:, h.column[action]]
            back = action == via[1]  # (from via's state, a candidate goes back to itself)
            kept: tuple[list[int], list[int], list[bool]] = ([], [], [])
            for c, p, follows in zip(ids, position, tracked, strict=True):
                if follows:
                    moved = c if back and p == via[0] else int(column[p])
                    if moved < 0:
                        follows = False
                    else:
                        p = moved
                if not follows or h.agrees(p, sensation, feel):
                    kept[0].append(c)
                    kept[1].append(p)
                    kept[2].append(follows)
            ids, position, tracked = kept
            if sensation:
                at_landmark = True
                break
            if h.feels and taken >= located_after and len(ids) == 1 and tracked[0]:
                self.belief = position[0]
                self.beliefs[-1] = self.belief
                return {ids[0]}, {ids[0]}, False, ids[0]
        survivors = {c for c, follows in zip(ids, tracked, strict=True) if follows}
        return (survivors if at_landmark else set()), set(ids), at_landmark, None

    def record(self, q: int, a: int, label: bool, feel: float, start: int) -> None:
        """Keep the test from ``q -a->`` made since step ``start``: actions, sensations (and
        what was felt, with float feedback)."""
        memory = self.agent.memory
        actions = tuple(int(v) for v in memory.actions[start + 1 :].tolist())
        sensations = tuple(bool(v) for v in memory.sensations[start + 1 :].tolist())
        felt: tuple[float, ...] = ()
        if self.h.feels:
            felt = (feel, *(float(v) for v in memory.feedback[start + 1 :].tolist()))
        self.traces.setdefault((q, a), []).append((actions, (label, *sensations), felt))
        self._retest(q, a)

    def drop_traces(self, q: int, a: int) -> list[Trace]:
        """Forget the tests made from ``q -a->``; those there were."""
        self._retest(q, a)
        return self.traces.pop((q, a), [])

    def _retest(self, q: int, a: int) -> None:
        k = self.h.column[a]
        self.retested.add((q, k))
        if q < len(self._singles):
            self._singles[q, k] = -1

    def singled_out(self, wanted: BoolArray) -> BoolArray:
        """For the (state, action column) pairs ``wanted`` (rows: state ids): whether the tests
        kept for the pair, replayed from every state of the hypothesis, leave its confirmed
        successor alone. (False elsewhere.)

        Each pair is replayed once while the hypothesis's confirmed successors (its
        :attr:`~Hypothesis.edits`) and the pair's tests stay as they are."""
        singles = self._singles_for(len(wanted))
        rows, columns = np.nonzero(wanted & (singles < 0))
        for s, k in zip(rows.tolist(), columns.tolist(), strict=True):
            self._replay(s, k)
        single: BoolArray = wanted & (singles == 1)
        return single

    def single(self, s: int, k: int, n: int) -> bool:
        """:meth:`singled_out` for the one pair ``(s, k)`` (``s < n``, the rows wanted)."""
        singles = self._singles_for(n)
        if singles[s, k] < 0:
            self._replay(s, k)
        return bool(singles[s, k] == 1)

    def _singles_for(self, n: int) -> NDArray[np.int8]:
        """The pairs of states ``0 .. n-1`` replayed (1: singled out, 0: not, -1: not yet), as
        long as the :attr:`~Hypothesis.edits` stay the same."""
        h = self.h
        if self._singles_edits != h.edits or len(self._singles) < n:
            self._singles = np.full((n, len(h.actions)), -1, dtype=np.int8)
            self._singles_edits = h.edits
        return self._singles[:n]

    def _replay(self, s: int, k: int) -> None:
        """Replay the tests kept for ``(s, k)``: whether they single out its successor."""
        h = self.h
        a = h.actions[k]
        target = int(h.next[s, k])
        agreeing: NDArray[np.int64] | None = None  # (each test replayed from those left)
        for word, outputs, felt in self.traces.get((s, a), ()):
            agreeing = h.consistent(word, outputs, (s, a), felt, among=agreeing)
            if not (agreeing == target).any():
                break
        single = agreeing is not None and len(agreeing) == 1 and int(agreeing[0]) == target
        self._singles[s, k] = single

    def return_to(
        self, q: int, a: int, route: tuple[int, ...] | None
    ) -> Generator[int, bool, bool | None]:
        """Go back to the world state ``q -a->`` led to; the sensation there, or None."""
        h = self.h
        self.phase = "return"
        if self.belief is None:
            yield from self.home()
        assert self.belief is not None
        if route is not None:
            yield from self.navigate(h.landmark)
            self.phase = "return"
            sensation = False
            for action in route:
                sensation = yield from self.move(action)
            self.phase = "test"
            return sensation
        word = h.path(self.belief, q)
        if word is None:
            yield from self.navigate(h.landmark)
            word = h.path(h.landmark, q)
            if word is None:
                return None
        self.phase = "return"
        for action in word:
            yield from self.move(action, check=True)
        self.phase = "test"
        return (yield from self.move(a))
