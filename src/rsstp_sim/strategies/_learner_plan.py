"""The learner's plan: explore, analyse counterexamples, verify, minimise, then walk the model."""

from __future__ import annotations

from collections.abc import Generator

import numpy as np
from numpy.typing import NDArray

from rsstp_sim.strategies._base import AgentView
from rsstp_sim.strategies._learner_hypothesis import FAR
from rsstp_sim.strategies._learner_identify import Identifier
from rsstp_sim.strategies._learner_walk import PHASES, Confined, Plan, Refuted
from rsstp_sim.words import counted

__all__ = ["Learning"]


class Learning(Identifier):
    """One run of the learner; :meth:`plan` is the generator the strategy drives.

    ``found``: the landmark has been seen (``first_landmark``: the step it was first seen).
    ``done``: every transition is confirmed, tested and the hypothesis is minimal.
    """

    def __init__(self, agent: AgentView, *, doubts: int, stop: bool = True) -> None:
        super().__init__(agent, doubts=doubts)
        self.stop = stop
        self.start_sensation = bool(agent.memory.sensations[0])
        self.found = False
        self.first_landmark = 0
        self.done = False
        self._checked = np.zeros((0, len(self.h.actions)), dtype=bool)
        self._checked_version = -1
        self._doubtful: tuple[tuple[int, int, int], NDArray[np.bool_], NDArray[np.bool_]] | None
        self._doubtful = None
        """What :meth:`suspect` found: for the (model version, edits, rows) then, the doubtful
        pairs and the states they are of (a mask), kept up to date as pairs are retested."""
        self._settled = -1
        """The hypothesis's :attr:`~Hypothesis.edits` when it was last found complete, with
        every state reachable and none to merge."""

    def plan(self) -> Plan:
        agent = self.agent
        if not self.start_sensation and agent.float_feedback:
            yield from self.climb()  # (it ends when the sensation is true)
            self.first_landmark = agent.step
        while not self.start_sensation and not self.first_landmark:  # search for the landmark
            sensation = yield self.random_action()
            self.count("steps_search")
            agent.enter(PHASES["search"])
            if sensation:
                self.first_landmark = agent.step
                break
        self.found = True
        agent.note(f"landmark found: state {self.h.landmark} is where the sensation is true")
        self.at_landmark()
        pending: Refuted | None = None
        while True:
            try:
                if pending is not None:
                    refuted, pending = pending, None
                    self.phase = "analyse"
                    yield from self.analyse(refuted)
                elif self.belief is None:
                    yield from self.home()
                else:
                    yield from self.advance()
            except Refuted as refuted:
                self.count("counterexamples")
                if self.done:
                    agent.note("the model was refuted: learning resumes")
                self.done = False
                pending = refuted
            except Confined as confined:
                self.confine(confined.since)
                if self.stop:
                    while True:  # (the run ends here)
                        yield from self.move(self.random_action())

    def advance(self) -> Plan:
        """One exploration, or the end game: forced deferrals, clean-up, minimisation,
        verification; then done, and a random walk that checks every prediction."""
        h = self.h
        if h.twins:
            merges = h.unify()
            for keep, gone in merges:
                self.forget(gone, keep)
                if self.belief == gone:
                    self.belief = keep
            if merges:
                self.count("twins", len(merges))
            if self.belief is not None and not h.alive[self.belief]:
                self.belief = None
            return
        goal = self.goal()
        if goal is not None:
            word, pair = goal
            self.phase = "navigate"
            for action in word:
                yield from self.move(action, check=True)
            if pair is not None:
                yield from self.explore(*pair)
            return
        if self.deferred:
            (q, a), deferral = min(self.deferred.items())
            self.count("forced")
            self.new(q, a, deferral.label, deferral.access, here=False, feel=deferral.feel)
            return
        if self._settled != h.edits:  # (a verification that changed nothing leaves it so)
            reachable = h.reachable()
            garbage = [s for s in h.states() if s not in reachable]
            if garbage:
                for s in garbage:
                    h.discard(s)
                    self.forget(s, None)
                self.count("discarded", len(garbage))
                return
            if not h.is_complete():  # pragma: no cover - every unconfirmed pair is a goal
                raise AssertionError("incomplete hypothesis with nothing to explore")
            merges = h.minimise()
            if merges:
                for keep, gone in merges:
                    self.forget(gone, keep)
                self.count("merges", len(merges))
                self.agent.note(f"minimised: {len(merges)} merges, {len(h.labels)} states")
                if self.belief not in h.labels:
                    self.belief = None
                return
            self._settled = h.edits
        suspect = self.suspect()
        if suspect is not None:
            yield from self.reverify(*suspect)
            return
        if not self.done:
            self.done = True
            done = f"done: {counted(len(h.labels), 'state')}, every transition confirmed and tested"
            if self.stop:
                self.agent.stop(done)
            else:
                self.agent.note(done)
        self.phase = "wander"
        while True:  # every prediction checked
            yield from self.move(self.random_action(), check=True)

    def goal(self) -> tuple[list[int], tuple[int, int] | None] | None:
        """A path to the next pair to explore, with the pair (None: go to the landmark first).

        The states with no confirmed path to the landmark come first, oldest first: until
        they have one, they cannot be told apart from the states identified next. The action
        tried first from a state is the one undoing the action that created it.
        """
        h = self.h
        belief = self.belief
        assert belief is not None
        distance = h.distance
        put_off: dict[int, set[int]] = {}  # the open columns of a state put off, by state
        for (s, a), deferred in self.deferred.items():
            # Put off until the model changed and a candidate can be tested.
            if deferred.version == h.version or not any(
                u not in h.labels or distance[u] < FAR for u in deferred.candidates
            ):
                if h.alive[s] and h.next[s, h.column[a]] < 0:
                    put_off.setdefault(s, set()).add(h.column[a])
        open_count = h.incoming.open
        wanted: NDArray[np.bool_] = open_count > 0
        for s, columns in put_off.items():
            if len(columns) == open_count[s]:
                wanted[s] = False
        if not wanted.any():
            return None
        actions_of = h.actions

        def open_actions(s: int) -> list[int]:
            shut = put_off.get(s, ())
            row = h.next[s].tolist()
            return [actions_of[k] for k, t in enumerate(row) if t < 0 and k not in shut]

        inverse = h.inverses()

        def first(s: int) -> int:
            actions = open_actions(s)
            made_by = self.made_by.get(s)
            if made_by is None:
                return self.pick(actions)
            undo = inverse.get(made_by)
            if undo is not None:
                return undo if undo in actions else self.pick(actions)
            # Not known yet: an action that undoes no other one, and not the same one.
            taken = set(inverse.values())
            likely = [b for b in actions if b not in taken and b != made_by]
            return self.pick(likely or actions)

        outside = np.flatnonzero(wanted & (distance[: len(wanted)] == FAR))
        if len(outside):
            oldest = int(outside[0])
            word = h.path(belief, oldest)
            if word is not None:
                return word, (oldest, first(oldest))
        found = h.nearest_where(belief, wanted)
        if found is not None:
            word, s = found
            return word, (s, first(s))
        if belief != h.landmark and distance[belief] < FAR:
            word = h.path(belief, h.landmark)
            if word is not None:
                return word, None
        if belief == h.landmark:
            return None  # (what is left to explore is out of the landmark's reach: garbage)
        self.belief = None  # nothing reachable from here: find the landmark again
        return [], None

    def explore(self, q: int, a: int) -> Plan:
        """Take ``a`` from ``q`` (located there) and identify the state it leads to."""
        self.phase = "take"
        sensation = yield from self.move(a)
        self.phase = "test"
        if sensation:
            self.confirm(q, a, self.h.landmark)
            return
        yield from self.identify(q, a, sensation, tuple(self.word), here=True, feel=self.feel())

    def confine(self, since: int) -> None:
        """A one-way world: no sensation since step ``since``, and the search for the landmark
        has lasted longer than the run before it. The part the agent is confined to never
        senses, so one state predicting false, every action a self-loop, is its exact model:
        the agent is there now. Say so, and end the run (unless ``stop`` is false)."""
        state = self.h.add_silent()
        self.confined = state
        self.belief = state
        self.word.clear()
        self.trace.clear()
        self.beliefs.clear()
        self.phase = "confined"
        searched = self.agent.step - since
        text = (
            f"confined from step {since}: no sensation in the {searched:,} steps since, no way "
            f"back found; the part it is confined to is 1 state (state {state}, never sensing)"
        )
        self.agent.note(text)
        if self.stop:
            self.agent.stop(text)

    def forget(self, gone: int, keep: int | None) -> None:
        """State ``gone`` merged into ``keep`` (or discarded): move or drop what names it."""
        self.made_by.pop(gone, None)
        for a in self.h.actions:
            self.deferred.pop((gone, a), None)
            traces = self.drop_traces(gone, a)
            if traces and keep is not None:  # (the merge changed the edits: all are replayed)
                self.traces.setdefault((keep, a), []).extend(traces)
        self._checked[:] = False
        self._doubtful = None

    # ------------------------------------------------------------- verification

    def suspect(self) -> tuple[int, int] | None:
        """The nearest confirmed transition whose tests do not single out its target.

        Checked without moving: each test kept for ``q -a->`` is replayed from every state of
        the complete hypothesis; the transition is verified when its target is the only state
        agreeing with all of them (:meth:`~Identifier.singled_out`). A transition to the
        landmark needs no test. A verified transition, or one taken again, stays checked
        while the model stays as it is.
        """
        h = self.h
        assert self.belief is not None
        n = len(h.label)
        if self._checked_version != h.version:
            self._checked[:] = False
            self._checked_version = h.version
        checked = self._checked_for(n)
        key = (h.version, h.edits, n)
        if self._doubtful is None or self._doubtful[0] != key:
            todo = h.alive[:n, None] & (h.next[:n] != h.landmark) & ~checked
            singled_out = self.singled_out(todo)
            checked |= todo & singled_out
            doubtful = todo & ~singled_out
            states = doubtful.any(axis=1)
            self._doubtful = (key, doubtful, states)
        else:  # (only the pairs retested since can have changed)
            _, doubtful, states = self._doubtful
            for q, k in self.retested:
                if q >= n:
                    continue
                todo = bool(h.alive[q]) and h.next[q, k] != h.landmark and not checked[q, k]
                singled = todo and self.single(q, k, n)
                checked[q, k] |= singled
                doubtful[q, k] = todo and not singled
                states[q] = doubtful[q].any()
        self.retested.clear()
        if not states.any():
            return None
        nearest = h.nearest_where(self.belief, states)
        if nearest is None:
            return None
        s = nearest[1]
        return s, h.actions[int(np.flatnonzero(doubtful[s])[0])]

    def reverify(self, q: int, a: int) -> Plan:
        """Take ``q -a->`` again and identify where it leads with the complete hypothesis."""
        h = self.h
        self.count("reverified")
        yield from self.navigate(q)
        self.phase = "verify"
        before = h.confirmed(q, a)
        sensation = yield from self.move(a)
        self.belief = None
        self.drop_traces(q, a)
        if sensation:
            self.confirm(q, a, h.landmark)
        else:
            yield from self.identify(q, a, sensation, tuple(self.word), here=True, feel=self.feel())
        if h.confirmed(q, a) != before:
            self.count("corrected")
            self.agent.note(f"verification: state {q} by action {a} leads elsewhere")
        self._checked_for(len(h.label))[q, h.column[a]] = True
        self._checked_version = h.version
        self.retested.add((q, h.column[a]))

    def _checked_for(self, n: int) -> NDArray[np.bool_]:
        """The checked transitions of states ``0 .. n-1``, by action column."""
        if len(self._checked) < n:
            grown = np.zeros((n, len(self.h.actions)), dtype=bool)
            grown[: len(self._checked)] = self._checked
            self._checked = grown
        return self._checked[:n]

    # ---------------------------------------------------------- counterexamples

    def analyse(self, refuted: Refuted) -> Plan:
        """Find the wrong transition behind a counterexample, then identify its target anew.

        ``refuted.word`` led from the landmark along confirmed transitions to a wrong
        prediction. With ``q_i`` the state after ``i`` actions and ``access[q]`` the word that
        defines ``q``, playing from the landmark ``access[q_i]`` then the rest of the word
        ends with the observed sensation for ``i = 0`` and with the predicted one for the
        last ``i``: a binary search (Rivest and Schapire's, the landmark as the reset) finds
        ``i`` where it changes, and ``q_i -word[i]->`` is wrong.
        """
        h = self.h
        word, trace, felt = refuted.word, refuted.trace, refuted.felt
        states = [h.landmark]
        for action in word:
            t = h.confirmed(states[-1], action)
            if t < 0:
                return
            states.append(t)
        observed = (trace[-1], felt[-1] if h.feels else 0.0)
        if h.agrees(states[-1], *observed):
            return
        low, high = 0, len(word)
        low_trace, low_felt = list(trace), list(felt)
        while high - low > 1:
            middle = (low + high) // 2
            prefix = h.access[states[middle]]
            outputs, feels = yield from self.query(prefix + word[middle:])
            if (outputs[-1], feels[-1]) == observed:
                low = middle
                low_trace, low_felt = outputs[len(prefix) :], feels[len(prefix) :]
            else:
                high = middle
        q, a, wrong = states[low], word[low], states[low + 1]
        label, feel = low_trace[0], low_felt[0]
        # The states the sensations after q -a-> rule out, besides the wrong one.
        excluded = {wrong}
        ids = np.asarray([s for s in h.matching(label, feel) if s != wrong], dtype=np.int64)
        position = ids.copy()
        after = zip(word[low + 1 :], low_trace[1:], low_felt[1:], strict=True)
        for action, sensation, felt_then in after:
            moved = h.next[position, h.column[action]]
            known = moved >= 0
            mismatch = known.copy()
            mismatch[known] = ~h.agree(moved[known], sensation, felt_then)
            excluded.update(int(s) for s in ids[mismatch])
            keep = known & ~mismatch
            ids, position = ids[keep], moved[keep]
        self.agent.note(
            f"counterexample of length {len(word)}: state {q} by action {a} "
            f"does not lead to state {wrong}"
        )
        h.unconfirm(q, a)
        self.drop_traces(q, a)
        access = h.access[q] + (a,)
        self.phase = "test"
        yield from self.identify(
            q,
            a,
            label,
            access,
            here=False,
            feel=feel,
            exclude=frozenset(excluded),
            route=access,
        )

    def query(self, word: tuple[int, ...]) -> Generator[int, bool, tuple[list[bool], list[float]]]:
        """From the landmark, play ``word``; the sensations after each action, and what was
        felt (zeros without float feedback)."""
        yield from self.navigate(self.h.landmark)
        self.phase = "analyse"
        outputs: list[bool] = []
        feels: list[float] = []
        for action in word:
            outputs.append((yield from self.move(action)))
            feels.append(self.feel())
        return outputs, feels

    # ------------------------------------------------------------------ results

    def start_state(self) -> int | None:
        """The state the run started in: the only one from which the steps before the
        landmark was first seen replay through the model (what was sensed, and felt with float
        feedback: a walk into a wall can bring two starts to one state); None if several or
        none do."""
        h = self.h
        if not self.found:
            return self.agent.model.current
        memory = self.agent.memory
        first = self.first_landmark
        actions = memory.actions[1 : first + 1].tolist()
        sensations = memory.sensations[: first + 1].tolist()
        felt = memory.feedback[: first + 1].tolist() if h.feels else [0.0] * (first + 1)
        candidates = h.matching_ids(sensations[0], felt[0])
        position = candidates.copy()
        for action, sensation, feel in zip(actions, sensations[1:], felt[1:], strict=True):
            position = h.next[position, h.column[action]]
            keep = position >= 0
            keep[keep] = h.agree(position[keep], sensation, feel)
            candidates, position = candidates[keep], position[keep]
        return int(candidates[0]) if len(candidates) == 1 else None
