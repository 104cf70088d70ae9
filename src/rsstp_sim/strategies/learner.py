"""The ``learner`` strategy: builds the minimal model of the world from one long trajectory.

See :class:`LearnerStrategy`.
"""

from __future__ import annotations

from collections.abc import Generator, Mapping
from typing import Any, ClassVar

import numpy as np

from rsstp_sim.strategies._base import AgentView, StrategyBase
from rsstp_sim.strategies._learner_hypothesis import FAR, Hypothesis
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["LearnerStrategy"]

_LONGEST_RUN = 16
"""The longest run of one action in a random search."""

Plan = Generator[int, bool, None]
"""The learner's plan: yields the next action, receives the sensation that followed it."""


class _Refuted(Exception):
    """The hypothesis predicted a wrong sensation on a confirmed path from the landmark."""

    def __init__(self, word: tuple[int, ...], trace: tuple[bool, ...]) -> None:
        super().__init__(f"counterexample of length {len(word)}")
        self.word = word
        self.trace = trace


class LearnerStrategy(StrategyBase):
    """Learns the minimal Moore model of the world, reset-free, from actions and sensations.

    The internal states are labelled with the sensation they predict (:meth:`labels`); the
    model has one transition per (state, action). The sensation is true in one world state
    only (the feedback pose), which serves as a landmark: seeing it, the agent knows where it
    is, as a reset would tell it.

    The learner keeps the model complete: a transition is either *confirmed* or a conjecture
    copied by a split. Located at an internal state, it walks confirmed transitions to the
    nearest unconfirmed (state, action) pair, takes it, and identifies the world state reached
    by ruling out candidates: following confirmed paths to the landmark, a candidate predicting
    a different sensation is ruled out. None left: a new state (``split``); one left that
    reached the landmark with the world: that state. A wrong prediction on a confirmed path is
    a counterexample, analysed with the landmark as the reset (Rivest and Schapire's binary
    search) to find the wrong transition. When every transition is confirmed the hypothesis is
    minimised (``merge``) and :attr:`done` is set; the agent then walks its model at random,
    and a refutation resumes learning.

    Assumptions: the world is deterministic and strongly connected (every state can reach
    every other), as the arm's reachable poses are; at most one class of states is sensed.
    """

    name: ClassVar[str] = "learner"

    def __init__(self, *, doubts: int = 1) -> None:
        self._doubts = doubts
        self.done = False
        self._h: Hypothesis | None = None
        self._next = 0

    def params(self) -> Mapping[str, Any]:
        return {}

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        """One state with a self-loop per action: the conjecture that nothing ever changes."""
        return TransitionSystem.universal(actions)

    # ------------------------------------------------------------ the protocol

    def reset(self, agent: AgentView) -> None:
        self._agent = agent
        self._h = None
        self.done = False
        self._first_landmark: int | None = None
        self._o0 = bool(agent.memory.sensations[0])
        self._word: list[int] = []
        self._trace: list[bool] = []
        self._beliefs: list[int] = []
        self._belief: int | None = None
        self._made_by: dict[int, int] = {}
        self._traces: dict[tuple[int, int], list[tuple[tuple[int, ...], tuple[bool, ...]]]] = {}
        self._checked: set[tuple[int, int]] = set()
        self._checked_version = -1
        self._deferred: dict[tuple[int, int], tuple[frozenset[int], tuple[int, ...], bool]] = {}
        self._run_action = 0
        self._run_left = 0
        self._phase = "search"
        self._stats: dict[str, int] = {}
        self._plan: Plan = self._learn()
        self._next = next(self._plan)

    def choose_action(self, agent: AgentView) -> int:
        return self._next

    def refine(self, agent: AgentView) -> None:
        sensation = bool(agent.memory.sensations[-1])
        self._next = self._plan.send(sensation)
        if self._belief is not None and agent.model.current != self._belief:
            agent.model.current = self._belief

    # --------------------------------------------------------------- results

    def labels(self) -> dict[int, bool]:
        """The sensation each internal state predicts."""
        if self._h is None:
            return {s: self._o0 for s in self._agent.model.states}
        return dict(self._h.labels)

    @property
    def start_state(self) -> int | None:
        """The internal state the run started in, or None if the trajectory leaves it open.

        Found by replaying the steps before the landmark was first seen through the model.
        """
        h = self._h
        if h is None or self._first_landmark is None:
            return self._agent.model.current if h is None else None
        memory = self._agent.memory
        first = self._first_landmark
        actions = memory.actions[1 : first + 1].tolist()
        sensations = memory.sensations[: first + 1].tolist()
        candidates = np.asarray(h.with_label(sensations[0]), dtype=np.int64)
        position = candidates.copy()
        for action, sensation in zip(actions, sensations[1:], strict=True):
            position = h.next[position, h.column[action]]
            keep = position >= 0
            keep[keep] = h.label[position[keep]] == sensation
            candidates, position = candidates[keep], position[keep]
        return int(candidates[0]) if len(candidates) == 1 else None

    def stats(self) -> dict[str, int]:
        """Counters: steps per phase, counterexamples, sessions, new states, merges."""
        return dict(self._stats)

    def _count(self, key: str, n: int = 1) -> None:
        self._stats[key] = self._stats.get(key, 0) + n

    # ------------------------------------------------------------------ moves

    def _move(self, action: int, *, check: bool = False) -> Generator[int, bool, bool]:
        """Take ``action``; follow the belief; with ``check``, a wrong prediction refutes."""
        sensation = yield action
        self._count(f"steps_{self._phase}")
        self._word.append(action)
        self._trace.append(sensation)
        h = self._h
        assert h is not None
        belief = self._belief
        if belief is not None:
            t = h.confirmed(belief, action)
            if t >= 0 and h.labels[t] == sensation:
                self._belief = t
            else:
                self._belief = None
                if t >= 0 and check:
                    refuted = _Refuted(tuple(self._word), tuple(self._trace))
                    if sensation:
                        self._at_landmark()
                    raise refuted
        if sensation:
            self._at_landmark()
        else:
            self._beliefs.append(-1 if self._belief is None else self._belief)
        return sensation

    def _at_landmark(self) -> None:
        assert self._h is not None
        self._belief = self._h.landmark
        self._word.clear()
        self._trace.clear()
        self._beliefs.clear()

    def _random_action(self) -> int:
        """Runs of one action with heavy-tailed lengths (P(length >= n) = 1/n): a search that
        covers a ring of n states in about n steps, and does not get stuck against a wall."""
        rng = self._agent.rng
        if self._run_left <= 0:
            actions = self._agent.actions
            self._run_action = actions[int(rng.integers(len(actions)))]
            self._run_left = min(_LONGEST_RUN, int(1.0 / (1.0 - float(rng.random()))))
        self._run_left -= 1
        return self._run_action

    # ------------------------------------------------------------------- plan

    def _learn(self) -> Plan:
        agent = self._agent
        if not self._o0:
            while not (yield self._random_action()):
                self._count("steps_search")
            self._count("steps_search")
            self._first_landmark = agent.step
        else:
            self._first_landmark = 0
        self._h = Hypothesis(agent.model, agent.actions, landmark=agent.model.current)
        agent.note(f"landmark found: state {self._h.landmark} is where the sensation is true")
        self._at_landmark()
        pending: _Refuted | None = None
        while True:
            try:
                if pending is not None:
                    refuted, pending = pending, None
                    self._phase = "analyse"
                    yield from self._analyse(refuted)
                elif self._belief is None:
                    self._phase = "home"
                    yield from self._home()
                else:
                    yield from self._advance()
            except _Refuted as refuted:
                self._count("counterexamples")
                if self.done:
                    agent.note("the model was refuted: learning resumes")
                self.done = False
                pending = refuted

    def _advance(self) -> Plan:
        """One exploration, or the end game: forced deferrals, clean-up, minimisation, done."""
        h = self._h
        assert h is not None and self._belief is not None
        goal = self._goal()
        if goal is not None:
            word, pair = goal
            self._phase = "navigate"
            for action in word:
                yield from self._move(action, check=True)
            if pair is not None:
                yield from self._explore(*pair)
            return
        if self._deferred:
            (q, a), (_, access, label) = min(self._deferred.items())
            self._count("forced")
            self._new(q, a, label, access, here=False)
            return
        reachable = h.reachable()
        garbage = [s for s in h.states() if s not in reachable]
        if garbage:
            for s in garbage:
                h.discard(s)
                self._forget(s, None)
            self._count("discarded", len(garbage))
            return
        if not h.is_complete():  # pragma: no cover - every unconfirmed pair is a goal
            raise AssertionError("incomplete hypothesis with nothing to explore")
        merges = h.minimise()
        if merges:
            for keep, gone in merges:
                self._forget(gone, keep)
            self._count("merges", len(merges))
            self._agent.note(f"minimised: {len(merges)} merges, {len(h.labels)} states")
            if self._belief not in h.labels:
                self._belief = None
            return
        suspect = self._suspect()
        if suspect is not None:
            yield from self._reverify(*suspect)
            return
        if not self.done:
            self.done = True
            self._agent.note(f"done: {len(h.labels)} states, every transition confirmed")
        self._phase = "wander"
        while True:
            yield from self._move(self._random_action(), check=True)

    def _goal(self) -> tuple[list[int], tuple[int, int] | None] | None:
        """The path to the next pair to explore (or to the landmark first), or None."""
        h = self._h
        belief = self._belief
        assert h is not None and belief is not None
        distance = h.distance
        rows, columns = np.nonzero(h.alive[:, None] & (h.next < 0))
        open_pairs: dict[int, list[int]] = {}
        for s, k in zip(rows.tolist(), columns.tolist(), strict=True):
            a = h.actions[k]
            deferred = self._deferred.get((s, a))
            if deferred is not None and not any(
                u not in h.labels or distance[u] < FAR for u in deferred[0]
            ):
                continue
            open_pairs.setdefault(s, []).append(a)
        if not open_pairs:
            return None
        inverse = self._inverses()

        def first(s: int) -> int:
            """The action undoing the one that created ``s`` first: it leads somewhere known.

            Not known yet: an action that undoes no other action and is not the same one.
            """
            actions = open_pairs[s]
            made_by = self._made_by.get(s)
            if made_by is None:
                return actions[0]
            undo = inverse.get(made_by)
            if undo is not None:
                return undo if undo in actions else actions[0]
            taken = set(inverse.values())
            likely = [b for b in actions if b not in taken and b != made_by]
            return likely[0] if likely else actions[0]

        outside = [s for s in open_pairs if distance[s] == FAR]
        if outside:
            oldest = min(outside)
            word = h.path(belief, oldest)
            if word is not None:
                return word, (oldest, first(oldest))
        found = h.nearest(belief, set(open_pairs))
        if found is not None:
            word, s = found
            return word, (s, first(s))
        if belief != h.landmark and distance[belief] < FAR:
            word = h.path(belief, h.landmark)
            if word is not None:
                return word, None
        self._belief = None  # nothing reachable from here: find the landmark again
        return [], None

    def _explore(self, q: int, a: int) -> Plan:
        """Take ``a`` from ``q`` (located there) and identify the state it leads to."""
        h = self._h
        assert h is not None
        self._phase = "test"
        sensation = yield from self._move(a)
        if sensation:
            self._confirm(q, a, h.landmark)
            return
        yield from self._identify(q, a, sensation, tuple(self._word), here=True)

    def _confirm(self, q: int, a: int, t: int) -> None:
        assert self._h is not None
        self._deferred.pop((q, a), None)
        self._h.confirm(q, a, t)

    def _new(self, q: int, a: int, label: bool, access: tuple[int, ...], *, here: bool) -> int:
        assert self._h is not None
        self._deferred.pop((q, a), None)
        new = self._h.create(q, a, label, access)
        self._made_by[new] = a
        self._count("new_states")
        if here:
            self._belief = new
            if self._beliefs:
                self._beliefs[-1] = new
        return new

    # --------------------------------------------------------- identification

    def _identify(
        self,
        q: int,
        a: int,
        label: bool,
        access: tuple[int, ...],
        *,
        here: bool,
        exclude: frozenset[int] = frozenset(),
        route: tuple[int, ...] | None = None,
    ) -> Plan:
        """Which state does ``q -a->`` lead to? Rule candidates out until one or none is left.

        Tests, in order: the paths to the landmark of the candidates the model predicts
        (a state ``c`` with ``c -undo-> q``, or the corner of a square of confirmed
        transitions); then the way back (the action undoing ``a``, then ``q``'s path to the
        landmark), which reaches the landmark if the state is new; then the other candidates'
        paths. ``here``: the agent is at that world state now. ``exclude``: states already
        ruled out. ``route``: reach the world state again from the landmark by this word (else
        by a confirmed path to ``q``).
        """
        h = self._h
        assert h is not None
        candidates = set(h.with_label(label)) - exclude
        undo = self._inverses().get(a)
        ranked = self._predict(q, a, candidates, undo)
        tried: set[int] = set()
        separate: list[int] | None = None
        returned = came_back = False
        while True:
            if not candidates:
                self._new(q, a, label, access, here=here)
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
                    untried = [c for c in candidates if c not in tried and distance[c] < FAR]
                    if came_back:
                        # The way back reached the landmark: a candidate with a confirmed
                        # transition by ``undo`` leads elsewhere, so is not it.
                        column = h.column[undo] if undo is not None else 0
                        untried = [c for c in untried if h.next[c, column] < 0]
                        if len(untried) > self._doubts or tried - set(ranked):
                            self._count("tentative")
                            self._new(q, a, label, access, here=False)
                            return
                    if not untried:  # nothing can tell these candidates apart yet
                        self._count("deferred")
                        self._deferred[(q, a)] = (frozenset(candidates), access, label)
                        return
                    first = min(untried, key=lambda c: (distance[c], c))
                if first is not None:
                    tried.add(first)
            if not here:
                arrived = yield from self._return_to(q, a, route)
                if arrived is None:
                    return
                if arrived:
                    self._confirm(q, a, h.landmark)
                    return
                if arrived != label:  # q stands for two world states: start afresh
                    self._count("restarts")
                    yield from self._identify(q, a, arrived, tuple(self._word), here=True)
                    return
            self._count("sessions")
            start = self._agent.step
            survivors, candidates, at_landmark = yield from self._session(
                candidates, first, script, follow=follow
            )
            self._record(q, a, label, start)
            here = False
            if not follow:  # the way back
                came_back = at_landmark
                ranked = sorted(survivors) + ranked
                continue
            if at_landmark and survivors:
                ordered = sorted(survivors)
                if len(ordered) == 1:
                    self._confirm(q, a, ordered[0])
                    return
                word = h.separating_word(ordered[0], ordered[1])
                if word is None:
                    self._confirm(q, a, ordered[0])
                    return
                separate = word

    def _record(self, q: int, a: int, label: bool, start: int) -> None:
        """Keep the test from ``q -a->`` made since step ``start``: actions and sensations."""
        memory = self._agent.memory
        actions = tuple(int(v) for v in memory.actions[start + 1 :].tolist())
        sensations = tuple(bool(v) for v in memory.sensations[start + 1 :].tolist())
        self._traces.setdefault((q, a), []).append((actions, (label, *sensations)))

    def _forget(self, gone: int, keep: int | None) -> None:
        """State ``gone`` merged into ``keep`` (or discarded): move or drop what names it."""
        assert self._h is not None
        self._made_by.pop(gone, None)
        for a in self._h.actions:
            traces = self._traces.pop((gone, a), None)
            if traces and keep is not None:
                self._traces.setdefault((keep, a), []).extend(traces)
        self._checked.clear()

    def _suspect(self) -> tuple[int, int] | None:
        """The nearest confirmed transition whose tests do not single out its target.

        Checked without moving: each test kept for ``q -a->`` is replayed from every state of
        the complete hypothesis; the transition is verified when its target is the only state
        agreeing with all of them. A transition to the landmark needs no test.
        """
        h = self._h
        assert h is not None and self._belief is not None
        if self._checked_version != h.version:
            self._checked.clear()
            self._checked_version = h.version
        doubtful: set[int] = set()
        pairs: dict[int, list[int]] = {}
        for s in h.states():
            for k, a in enumerate(h.actions):
                t = int(h.next[s, k])
                if t == h.landmark or (s, a) in self._checked:
                    continue
                agreeing: set[int] | None = None
                for word, outputs in self._traces.get((s, a), ()):
                    found = set(h.consistent(word, outputs))
                    agreeing = found if agreeing is None else agreeing & found
                if agreeing != {t}:
                    doubtful.add(s)
                    pairs.setdefault(s, []).append(a)
        if not doubtful:
            return None
        found_path = h.nearest(self._belief, doubtful)
        if found_path is None:
            return None
        return found_path[1], pairs[found_path[1]][0]

    def _reverify(self, q: int, a: int) -> Plan:
        """Take ``q -a->`` again and identify where it leads with the complete hypothesis."""
        h = self._h
        assert h is not None and self._belief is not None
        self._count("reverified")
        yield from self._navigate(q)
        self._phase = "verify"
        before = h.confirmed(q, a)
        sensation = yield from self._move(a)
        self._belief = None
        self._traces.pop((q, a), None)
        if sensation:
            self._confirm(q, a, h.landmark)
        else:
            yield from self._identify(q, a, sensation, tuple(self._word), here=True)
        if h.confirmed(q, a) != before:
            self._count("corrected")
            self._agent.note(f"verification: state {q} by action {a} leads elsewhere")
        self._checked.add((q, a))
        self._checked_version = h.version

    def _predict(self, q: int, a: int, candidates: set[int], undo: int | None) -> list[int]:
        """Candidates for ``q -a->`` that confirmed transitions point at, most votes first.

        A vote for ``c`` when ``c -undo-> q``; one for the far corner ``y`` of each square
        ``p -b-> q``, ``p -a-> r -b-> y`` (actions that commute, as two joints' turns do).
        """
        h = self._h
        assert h is not None
        votes: dict[int, int] = {}
        if undo is not None:
            k = h.column[undo]
            for c in candidates:
                if h.next[c, k] == q:
                    votes[c] = votes.get(c, 0) + 2
        column = h.column[a]
        sources, columns = np.nonzero(h.next == q)
        for p, kb in zip(sources.tolist(), columns.tolist(), strict=True):
            r = int(h.next[p, column])
            if r >= 0:
                y = int(h.next[r, kb])
                if y in candidates:
                    votes[y] = votes.get(y, 0) + 1
        return sorted(votes, key=lambda c: (-votes[c], c))

    def _session(
        self, candidates: set[int], first: int | None, script: list[int], *, follow: bool = True
    ) -> Generator[int, bool, tuple[set[int], set[int], bool]]:
        """One test from the world state being identified: follow paths to the landmark.

        Plays ``script`` first; then (if ``follow``) follows ``first``'s path to the landmark,
        and the nearest remaining candidate's when ``first`` is ruled out. Returns the
        candidates that reached the landmark with the world (if it was reached), the
        candidates not ruled out, and whether the landmark was reached.
        """
        h = self._h
        assert h is not None
        ids = np.asarray(sorted(candidates), dtype=np.int64)
        position = ids.copy()
        tracked = np.ones(len(ids), dtype=bool)
        chosen = first
        script = list(script)
        at_landmark = False
        while len(ids):
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
                    index = int(usable[np.argmin(distance[usable])])
                    chosen = int(ids[index])
                action = h.actions[int(h.toward[position[index]])]
            sensation = yield from self._move(action)
            moved = h.next[position, h.column[action]]
            tracked &= moved >= 0
            position = np.where(tracked, moved, position)
            keep = ~tracked | (h.label[position] == sensation)
            ids, position, tracked = ids[keep], position[keep], tracked[keep]
            if sensation:
                at_landmark = True
                break
        survivors = {int(s) for s in ids[tracked]} if at_landmark else set()
        return survivors, {int(s) for s in ids}, at_landmark

    def _return_to(
        self, q: int, a: int, route: tuple[int, ...] | None
    ) -> Generator[int, bool, bool | None]:
        """Go back to the world state ``q -a->`` led to; the sensation there, or None."""
        h = self._h
        assert h is not None
        self._phase = "return"
        if self._belief is None:
            yield from self._home()
        assert self._belief is not None
        if route is not None:
            yield from self._navigate(h.landmark)
            self._phase = "return"
            sensation = False
            for action in route:
                sensation = yield from self._move(action)
            self._phase = "test"
            return sensation
        word = h.path(self._belief, q)
        if word is None:
            yield from self._navigate(h.landmark)
            word = h.path(h.landmark, q)
            if word is None:
                return None
        self._phase = "return"
        for action in word:
            yield from self._move(action, check=True)
        self._phase = "test"
        return (yield from self._move(a))

    def _navigate(self, goal: int) -> Plan:
        """Walk a confirmed path to ``goal`` (finding the landmark first when lost)."""
        h = self._h
        assert h is not None
        self._phase = "navigate"
        if self._belief is None:
            yield from self._home()
        assert self._belief is not None
        word = h.path(self._belief, goal)
        if word is None:
            self._belief = None
            yield from self._home()
            word = h.path(h.landmark, goal) or []
        for action in word:
            yield from self._move(action, check=True)

    def _inverses(self) -> dict[int, int]:
        """Actions that undo others, as far as the confirmed transitions show.

        ``b`` undoes ``a`` when most confirmed ``s -a-> t`` (``t != s``) with a confirmed
        ``t -b->`` have ``t -b-> s``. Learned from the agent's own experience; used only to
        find the way back when lost.
        """
        h = self._h
        assert h is not None
        states = np.flatnonzero(h.alive)
        inverse: dict[int, int] = {}
        for ka, a in enumerate(h.actions):
            t = h.next[states, ka]
            moved = (t >= 0) & (t != states)
            sources, targets = states[moved], t[moved]
            best, best_count = -1, 0
            for kb in range(len(h.actions)):
                back = h.next[targets, kb]
                count = int(np.count_nonzero(back == sources))
                if count > best_count and 2 * count >= np.count_nonzero(back >= 0):
                    best, best_count = kb, count
            if best >= 0:
                inverse[a] = h.actions[best]
        return inverse

    def _retrace(self) -> Generator[int, bool, list[int] | None]:
        """Undo the actions since the last known state; the states the agent is likely at.

        None when the landmark was reached on the way or an action cannot be undone. A blocked
        move on the way out makes the undoing miss by a step: the answer is the states within
        two steps of the last known state.
        """
        h = self._h
        assert h is not None
        known = [i for i, b in enumerate(self._beliefs) if b >= 0 and h.distance[b] < FAR]
        last = known[-1] if known else -1
        state = self._beliefs[last] if known else h.landmark
        back = self._word[last + 1 :]
        inverse = self._inverses()
        if any(a not in inverse for a in back):
            return []
        for action in reversed(back):
            if (yield from self._move(inverse[action])):
                return None
        return [state, *sorted(h.around(state, 2) - {state})]

    def _home(self) -> Plan:
        """Lost: look for the landmark nearby, then retrace, then follow candidates' paths.

        A failed test usually leaves the agent beside the landmark (it followed a path to the
        landmark from a state beside the one it is at): first probe the states next to the
        landmark, each probe undone when it fails. Then undo the actions since the last known
        state and probe the states around it. Last, follow candidates' paths to the landmark
        ruling them out, and search at random when none is left.
        """
        h = self._h
        assert h is not None
        phase, self._phase = self._phase, "home"
        near = yield from self._retrace()
        if near is None:
            self._phase = phase
            return
        sensation = self._trace[-1] if self._trace else True
        # Positions of the candidates, most likely first; the first usable one is followed.
        ids = np.asarray([s for s in near if h.labels[s] == sensation], dtype=np.int64)
        widened = not len(ids)
        if widened:
            ids = np.asarray(h.with_label(sensation), dtype=np.int64)
        while True:
            usable = np.flatnonzero(h.distance[ids] < FAR)
            if len(usable) and self._run_left <= 0:
                action = h.actions[int(h.toward[ids[usable[0]]])]
            else:
                action = self._random_action()
            sensation = yield from self._move(action)
            if sensation:
                self._phase = phase
                return
            moved = h.next[ids, h.column[action]]
            keep = moved >= 0
            keep[keep] = h.label[moved[keep]] == sensation
            ids = moved[keep]
            if not len(ids):
                if widened and self._run_left <= 0:
                    self._random_action()
                    self._run_left += 1
                widened = True
                ids = np.asarray(h.with_label(sensation), dtype=np.int64)

    # ----------------------------------------------------- counterexamples

    def _analyse(self, refuted: _Refuted) -> Plan:
        """Find the wrong transition behind a counterexample, then identify its target anew.

        ``refuted.word`` led from the landmark along confirmed transitions to a wrong
        prediction. With ``q_i`` the state after ``i`` actions and ``access[q]`` the word that
        defines ``q``, the landmark, ``access[q_i]`` then the rest of the word ends with the
        observed sensation for ``i = 0`` and with the predicted one for the last ``i``: a
        binary search finds ``i`` where it changes, and ``q_i -word[i]->`` is wrong.
        """
        h = self._h
        assert h is not None
        word, trace = refuted.word, refuted.trace
        states = [h.landmark]
        for action in word:
            t = h.confirmed(states[-1], action)
            if t < 0:
                return
            states.append(t)
        observed = trace[-1]
        if h.labels[states[-1]] == observed:
            return
        low, high = 0, len(word)
        low_trace = list(trace)
        while high - low > 1:
            middle = (low + high) // 2
            prefix = h.access[states[middle]]
            outputs = yield from self._query(prefix + word[middle:])
            if outputs[-1] == observed:
                low, low_trace = middle, outputs[len(prefix) :]
            else:
                high = middle
        q, a, wrong = states[low], word[low], states[low + 1]
        label = low_trace[0]
        excluded = {wrong}
        ids = np.asarray([s for s in h.with_label(label) if s != wrong], dtype=np.int64)
        position = ids.copy()
        for action, sensation in zip(word[low + 1 :], low_trace[1:], strict=True):
            moved = h.next[position, h.column[action]]
            known = moved >= 0
            mismatch = known.copy()
            mismatch[known] = h.label[moved[known]] != sensation
            excluded.update(int(s) for s in ids[mismatch])
            keep = known & ~mismatch
            ids, position = ids[keep], moved[keep]
        self._agent.note(
            f"counterexample of length {len(word)}: state {q} by action {a} "
            f"does not lead to state {wrong}"
        )
        h.unconfirm(q, a)
        self._traces.pop((q, a), None)
        access = h.access[q] + (a,)
        self._phase = "test"
        yield from self._identify(
            q, a, label, access, here=False, exclude=frozenset(excluded), route=access
        )

    def _query(self, word: tuple[int, ...]) -> Generator[int, bool, list[bool]]:
        """From the landmark, play ``word``; the sensations after each action."""
        h = self._h
        assert h is not None
        yield from self._navigate(h.landmark)
        self._phase = "analyse"
        outputs: list[bool] = []
        for action in word:
            outputs.append((yield from self._move(action)))
        return outputs
