"""Where the learner believes it is, and how it finds the landmark again when it does not know.

The learner's plan is a generator: it yields an action and receives the sensation that
followed. :meth:`Walker.move` wraps one such step and keeps the belief (the internal state the
agent is at, or None) up to date along confirmed transitions.
"""

from __future__ import annotations

from collections.abc import Generator

import numpy as np

from rsstp_sim.strategies._base import AgentView
from rsstp_sim.strategies._learner_hypothesis import FAR, Hypothesis, IntArray

__all__ = [
    "CONFINED_STEPS",
    "LONGEST_RUN",
    "PHASES",
    "UNPROVEN",
    "Confined",
    "Plan",
    "Refuted",
    "Walker",
]

LONGEST_RUN = 16
"""The longest run of one action in a random search."""

PHASES = {
    "search": "home",
    "home": "home",
    "navigate": "explore",
    "take": "explore",
    "test": "identify",
    "return": "identify",
    "analyse": "identify",
    "verify": "identify",
    "wander": "done",
    "confined": "done",
}
"""The phase recorded (``agent.enter``) for each step counter of :attr:`Walker.stats`: *home*
(searching for the landmark), *explore* (walking to the next transition, and taking it), *identify*
(telling where a transition led: tests, returns, counterexamples, verification), *done*
(walking the finished model, with ``stop=False``)."""

_STEPS = {phase: f"steps_{phase}" for phase in PHASES}
"""The step counter of each phase (made once: :meth:`Walker.move` counts every step)."""

CONFINED_STEPS = 16_384
"""The shortest search for the landmark after which the agent may conclude it is confined (a
world of a thousand classes, lost early, can take thousands of steps to find it again)."""

UNPROVEN = 16
"""How many times longer the search lasts before the agent takes itself as confined when its
confirmed transitions show no move that cannot be undone (:meth:`Walker.check_confined`)."""

NARROWED = 64
"""The most candidates for where it is that a lost agent brings together (:meth:`Walker.narrowing`)
before it follows their paths: more would cost more per step than the walks they save."""

Plan = Generator[int, bool, None]
"""A plan: yields the next action, receives the sensation that followed it."""


class Refuted(Exception):
    """The hypothesis predicted a wrong sensation on a confirmed path from the landmark.

    ``word`` is the action word walked from the landmark, ``trace`` the sensation after each
    of its actions (the last one the mispredicted), ``felt`` the float feedback after each
    (with float feedback: the feel may be the mispredicted).
    """

    def __init__(
        self, word: tuple[int, ...], trace: tuple[bool, ...], felt: tuple[float, ...]
    ) -> None:
        super().__init__(f"counterexample of length {len(word)}")
        self.word = word
        self.trace = trace
        self.felt = felt


class Confined(Exception):
    """The search for the landmark has lasted :data:`CONFINED_STEPS` steps or more, and 16
    times as long as the whole run before it: the agent takes it that no way leads back (a one-way
    world), and that the part it is confined to never senses."""

    def __init__(self, since: int) -> None:
        super().__init__(f"no sensation since step {since}")
        self.since = since


class Walker:
    """The agent walking its hypothesis.

    Since the landmark was last seen the agent took ``word``, sensed ``trace`` and felt
    ``felt`` (the float feedback; zeros when the agent has none);
    ``beliefs[i]`` is the state it believed it was at after ``word[i]`` (-1: unknown), and
    ``belief`` is where it believes it is now (None: lost). ``stats`` counts steps per
    ``phase`` and events.
    """

    def __init__(self, agent: AgentView) -> None:
        self.agent = agent
        self.h = Hypothesis(
            agent.model,
            agent.actions,
            landmark=agent.model.current,
            rng=agent.rng,
            feels=agent.float_feedback,
        )
        self.word: list[int] = []
        self.trace: list[bool] = []
        self.felt: list[float] = []
        self.beliefs: list[int] = []
        self.belief: int | None = None
        self.phase = "search"
        self.stats: dict[str, int] = {}
        self._run_action = 0
        self._run_left = 0
        self.last_seen = agent.step
        self.seen = False
        self.confined: int | None = None
        self._confinement = CONFINED_STEPS

    def count(self, key: str, n: int = 1) -> None:
        self.stats[key] = self.stats.get(key, 0) + n

    def feel(self) -> float:
        """The float feedback felt now (0.0 when the agent has none)."""
        return self.agent.memory.last_feedback if self.h.feels else 0.0

    def move(self, action: int, *, check: bool = False) -> Generator[int, bool, bool]:
        """Take ``action``; follow the belief. With ``check``, a wrong prediction of a
        confirmed transition raises :class:`Refuted` (else the agent is just lost)."""
        sensation = yield action
        phase, stats, agent = self.phase, self.stats, self.agent
        key = _STEPS[phase]
        stats[key] = stats.get(key, 0) + 1
        if agent.phase != PHASES[phase]:
            agent.enter(PHASES[phase])
        feel = agent.memory.last_feedback if self.h.feels else 0.0
        self.word.append(action)
        self.trace.append(sensation)
        self.felt.append(feel)
        h = self.h
        belief = self.belief
        if belief is not None:
            t = h.confirmed(belief, action)
            if t >= 0 and h.agrees(t, sensation, feel):
                self.belief = t
            else:
                self.belief = None
                if t >= 0 and check:
                    refuted = Refuted(tuple(self.word), tuple(self.trace), tuple(self.felt))
                    if sensation:
                        self.at_landmark()
                    raise refuted
        if sensation:
            self.at_landmark()
        else:
            self.beliefs.append(-1 if self.belief is None else self.belief)
        return sensation

    def at_landmark(self) -> None:
        """The sensation is true: the agent is at the landmark, whatever it believed."""
        h = self.h
        self.belief = h.landmark
        self.last_seen = self.agent.step
        self.seen = True
        if h.feels and np.isnan(h.feel[h.landmark]):
            h.set_feel(h.landmark, self.feel())
        self.word.clear()
        self.trace.clear()
        self.felt.clear()
        self.beliefs.clear()

    def pick(self, among: list[int]) -> int:
        """One of ``among`` (not empty), chosen by the run's generator: a choice among equals."""
        if len(among) == 1:
            return among[0]
        return among[int(self.agent.rng.integers(len(among)))]

    def random_action(self) -> int:
        """Runs of one action of random lengths (P(length >= n) = 1/n, at most
        :data:`LONGEST_RUN`): a search that goes round a ring faster than single steps."""
        rng = self.agent.rng
        if self._run_left <= 0:
            actions = self.agent.actions
            self._run_action = actions[int(rng.integers(len(actions)))]
            self._run_left = min(LONGEST_RUN, int(1.0 / (1.0 - float(rng.random()))))
        self._run_left -= 1
        return self._run_action

    def navigate(self, goal: int) -> Plan:
        """Walk a confirmed path to ``goal`` (finding the landmark first when lost)."""
        h = self.h
        self.phase = "navigate"
        if self.belief is None:
            yield from self.home()
        assert self.belief is not None
        word = h.path(self.belief, goal)
        if word is None:
            self.belief = None
            yield from self.home()
            word = h.path(h.landmark, goal) or []
        for action in word:
            yield from self.move(action, check=True)

    def home(self) -> Plan:
        """Lost: retrace, then follow candidates' paths to the landmark; else search.

        Undo the actions since the last known state (:meth:`retrace`), then take the states
        around it as candidates for where the agent is, most likely first, and follow the
        first one's path to the landmark; a candidate predicting a different sensation is
        ruled out. When none is left, every state is a candidate again, after a random run;
        when every state was ruled out, the agent is where its hypothesis does not reach yet,
        and it first wanders at random, twice as long each time. With float feedback it climbs
        the closeness instead; when a climb fails (a local maximum), it wanders, twice as long
        after each failed climb.
        """
        h = self.h
        phase, self.phase = self.phase, "home"
        near = yield from self.retrace()
        if near is None:
            self.phase = phase
            return
        climbing = self.agent.float_feedback
        sensation = self.trace[-1] if self.trace else True
        feel = self.feel()
        ids = np.asarray([s for s in near if h.agrees(s, sensation, feel)], dtype=np.int64)
        widened = not len(ids)
        if widened:
            ids = h.matching_ids(sensation, feel)
        failed = wander = 0
        while True:
            usable = -1  # (the first candidate with a path to the landmark, when one is wanted)
            if wander <= 0 and self._run_left <= 0 and len(ids):
                homeward = h.distance[ids] < FAR
                first = int(homeward.argmax())
                usable = first if homeward[first] else -1
            if wander > 0:  # every state of the hypothesis ruled out: outside it, wander
                wander -= 1
                action = self.random_action()
            elif usable >= 0:
                action = h.actions[int(h.toward[ids[usable]])]
                if not climbing and 1 < len(ids) <= NARROWED:
                    action = self.narrowing(ids, action)
            elif climbing:  # climb the feedback for a while, instead of a random run
                if (yield from self.climb(LONGEST_RUN * len(h.actions))):
                    self.phase = phase
                    return
                # A local maximum the climb's short runs do not leave (an obstacle's shadow, in a
                # part of the world the hypothesis does not hold yet): wander at random, twice as
                # long after each failed climb, then follow the candidates or climb again.
                self._run_left = 0
                wander = LONGEST_RUN << min(failed, 20)
                failed += 1
                widened = True
                ids = h.matching_ids(False, self.feel())
                continue
            else:
                action = self.random_action()
            sensation = yield from self.move(action)
            if sensation:
                self.phase = phase
                return
            self.check_confined()
            feel = self.feel()
            ids = h.follow(ids, action, sensation, feel)
            if not len(ids):
                if widened and self._run_left <= 0:
                    self.random_action()  # start a run
                    self._run_left += 1
                    if not climbing:
                        # Each time every state is ruled out, wander twice as long before
                        # following their paths again: the agent is in a part of the world
                        # its hypothesis does not hold yet, where their paths do not lead home.
                        wander = LONGEST_RUN << min(failed, 20)
                        failed += 1
                widened = True
                ids = h.matching_ids(sensation, feel)

    def narrowing(self, ids: IntArray, action: int) -> int:
        """The action that brings the candidates ``ids`` to the fewest states, every one of
        them by a confirmed transition (blocked moves bring several to one, as walking into an
        obstacle brings every pose on the way to the pose against it), if fewer than they are
        now; else ``action``. Walked on, the candidates become one and the agent is located."""
        h = self.h
        now = len(np.unique(ids))
        best, fewest = action, now
        for k in h.columns:
            moved = h.next[ids, k]
            if (moved < 0).any():
                continue
            count = len(np.unique(moved))
            if count < fewest:
                best, fewest = h.actions[k], count
        return best

    def check_confined(self) -> None:
        """After a step of a search for the landmark: raise :class:`Confined` when the search
        has lasted 16 times as long as the run before it, :data:`CONFINED_STEPS`, and a run of
        :data:`LONGEST_RUN` steps per state and action of the hypothesis, and the confirmed
        transitions show an action that no action undoes (:meth:`Hypothesis.irreversible`).
        When they show neither that nor an action undoing each action
        (:meth:`Hypothesis.reversible`), the search lasts :data:`UNPROVEN` times as long first
        (a generated two-link world between two obstacles, its landmark found by luck at step
        107, took more than 16,384 steps to find again); when they show every move undone, no
        part of the world is a trap and the search goes on. A heuristic: from sensations alone,
        a part of the world that never senses cannot be told from a search that has not yet
        found the sensed pose."""
        searched = self.agent.step - self.last_seen
        if searched < self._confinement or self.confined is not None or not self.seen:
            return
        h = self.h
        bound = max(
            CONFINED_STEPS, 16 * self.last_seen, LONGEST_RUN * len(h.labels) * len(h.actions)
        )
        if searched >= bound and h.irreversible():
            raise Confined(self.last_seen)
        if searched >= UNPROVEN * bound and not h.reversible():
            raise Confined(self.last_seen)
        self._confinement = max(bound, searched + CONFINED_STEPS)

    def climb(self, steps: int | None = None) -> Generator[int, bool, bool]:
        """With float feedback: climb the closeness to the sensed pose until it is sensed (True)
        or ``steps`` steps are taken (False; None: no limit).

        Coordinate ascent: keep taking an action while the feedback rises; when it does not,
        undo the action (when the confirmed transitions say which action undoes it) and try
        another; when no action makes it rise (a local maximum: an obstacle in the way), a
        random run of one action, then climb again. Only a rise above the best felt since the
        climb (re)started makes every action worth trying again: without undoing actions, a
        step down then a step back up would otherwise go round the same few poses for ever.
        Met again, a local
        maximum is left by a random walk (runs of random actions) of :data:`LONGEST_RUN` steps,
        then twice as many each time: a maximum whose slopes are wider than one run (the far
        side of an obstacle, the long way round) is left in the end, and the walks become the
        boolean learner's random search.
        """
        memory = self.agent.memory
        inverse = self.h.inverses()
        actions = list(self.agent.actions)
        end = None if steps is None else self.agent.step + steps
        tried: set[int] = set()
        action: int | None = None
        escapes = 0
        best = memory.last_feedback
        while end is None or self.agent.step < end:
            if action is None:
                untried = [b for b in actions if b not in tried]
                if not untried:  # a local maximum: leave it at random, then climb again
                    self._run_left = 0
                    run = [self.random_action()]
                    walk = 0 if escapes == 0 else LONGEST_RUN << min(escapes - 1, 20)
                    escapes += 1
                    while self._run_left > 0 or len(run) < walk:
                        run.append(self.random_action())
                    for step_action in run:
                        if (yield from self.move(step_action)):
                            return True
                        self.check_confined()
                    tried.clear()
                    best = memory.last_feedback
                    continue
                action = self.pick(untried)
            before = memory.last_feedback
            if (yield from self.move(action)):
                return True
            self.check_confined()
            after = memory.last_feedback
            undo = inverse.get(action)
            if after > best:
                best = after
                tried = set() if undo is None else {undo}
                continue
            if after > before:  # back up toward the best: keep on, what was tried stays tried
                continue
            tried.add(action)
            if after < before and undo is not None:
                if (yield from self.move(undo)):
                    return True
                self.check_confined()
            action = None
        return False

    def retrace(self) -> Generator[int, bool, list[int] | None]:
        """Undo the actions since the last known state; the states the agent is likely at.

        None when the landmark was seen on the way. The answer is the last known state
        (with a path to the landmark) first, then the states within two steps of it: a blocked
        move on the way out makes the undoing miss. Empty when an action has no known undo.
        """
        h = self.h
        known = [i for i, b in enumerate(self.beliefs) if b >= 0 and h.distance[b] < FAR]
        last = known[-1] if known else -1
        state = self.beliefs[last] if known else h.landmark
        back = self.word[last + 1 :]
        inverse = h.inverses()
        if any(a not in inverse for a in back):
            return []
        for action in reversed(back):
            if (yield from self.move(inverse[action])):
                return None
        return [state, *sorted(h.around(state, 2) - {state})]
