"""The learner's hypothesis: a Moore machine kept in the agent's transition system.

The model (:class:`~rsstp_sim.transition_system.TransitionSystem`) is always complete and
deterministic: every (state, action) has exactly one successor. A successor is either
*confirmed* (the learner took that action from that state and identified where it led) or a
*conjecture* (inherited from the state that was split to create this one, as the thesis's
split copies a row and a column). The confirmed successors are mirrored in dense arrays indexed
by state id, so that following many candidate states at once is one numpy indexing per step.

Every change goes through the model's ``split``, ``merge``, ``add`` and ``delete``, so a
recording shows the learning operation by operation.
"""

from __future__ import annotations

from collections import deque

import numpy as np
from numpy.typing import NDArray

from rsstp_sim.moore import moore_classes
from rsstp_sim.strategies._learner_incoming import Incoming
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["FAR", "Hypothesis"]

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
FloatArray = NDArray[np.float64]

FAR = np.iinfo(np.int64).max // 4
"""The distance to the landmark of a state with no confirmed path to it."""

EVIDENCE = 4
"""The confirmed moves by an action, from states known whole, that :meth:`Hypothesis.irreversible`
needs before it finds that no action undoes it."""

SHARED_FEEL = 2.0
"""With float feedback, the feel is taken as shared (:meth:`Hypothesis.feel_shared`) when the
states felt are at least this many times the felt values."""

FELT_STATES = 16
"""...and at least this many states are felt (a few first states may feel alike by chance)."""


class _TooFar:
    """:meth:`Hypothesis._search_near` met too many states: search a level at a time."""


_TOO_FAR = _TooFar()


class Hypothesis:
    """Labels, confirmed successors and the landmark, over the model's state ids.

    ``labels[s]`` is the sensation state ``s`` predicts; ``landmark`` is the one state
    predicting ``True``. ``access[s]`` is the action word that led from the landmark to the
    world state ``s`` was created for: a fact of the trajectory, which defines ``s``.
    ``next[s, k]`` is the confirmed successor of ``s`` by ``actions[k]``, or -1.

    ``feels`` (float feedback, ``mode = "float"``): ``feel[s]`` is the closeness the agent
    felt at the world state ``s`` was created for (NaN: unknown), ``also_felt[s]`` the
    feels of the states merged into ``s``.
    Two world states felt differently are different poses, so a candidate whose feel differs
    from the one felt is ruled out as one whose label differs is (:meth:`agree`): the states
    are then poses, and the minimisation at the end merges those the sensation cannot tell
    apart. Without ``feels`` the feel is never compared.

    ``rng`` (the run's generator) draws, once, the order in which the actions are tried
    when several shortest paths or several nearest states tie: a path keeps one preference
    all run long (a coherent sweep of the world; drawn anew at every search, the walks
    wander and take twice the steps), and the seed chooses it. None: the actions' order.
    """

    def __init__(
        self,
        model: TransitionSystem,
        actions: tuple[int, ...],
        landmark: int,
        rng: np.random.Generator | None = None,
        *,
        feels: bool = False,
    ) -> None:
        self.model = model
        self.feels = feels
        order = np.arange(len(actions)) if rng is None else rng.permutation(len(actions))
        self._columns: list[int] = [int(k) for k in order]
        self._ordered = [actions[k] for k in self._columns]
        self.actions = actions
        self.column = {a: k for k, a in enumerate(actions)}
        capacity = max(64, 2 * model.next_id)
        self.next: IntArray = np.full((capacity, len(actions)), -1, dtype=np.int64)
        self.label: BoolArray = np.zeros(capacity, dtype=bool)
        self.alive: BoolArray = np.zeros(capacity, dtype=bool)
        self.feel: FloatArray = np.full(capacity, np.nan)
        self.also_felt: dict[int, set[float]] = {}
        self._merged: BoolArray = np.zeros(capacity, dtype=bool)
        self._by_feel: dict[float, set[int]] = {}
        """With ``feels``: the states that agree with a feel, by feel (their own, and those of
        the states merged into them), the states whose feel is unknown aside (``_unfelt``)."""
        self._unfelt: set[int] = set()
        self._feel_keys: dict[int, tuple[float, ...]] = {}
        self.labels: dict[int, bool] = {}
        self.access: dict[int, tuple[int, ...]] = {}
        self.incoming = Incoming(len(actions), capacity)
        """Who leads to each state, the counts behind :meth:`inverses`, the open actions."""
        for s in model.states:
            self.alive[s] = True
            self.incoming.open_row(s, self.next[s])
            self._refelt(s)
            self.labels[s] = s == landmark
            self.label[s] = s == landmark
            self.access[s] = ()
        self.landmark = landmark
        self.unconfirmed = len(model.states) * len(actions)
        self._distance: IntArray | None = None
        self._toward: IntArray | None = None
        self._edits = 0
        self._inverse: tuple[int, dict[int, int]] = (-1, {})
        self._commuting: tuple[int, BoolArray] = (-1, np.zeros((0, 0), dtype=bool))
        self._matched: tuple[tuple[int, bool], IntArray] = ((-1, False), np.zeros(0, np.int64))
        self.near_states = 1024
        """How many states a search meets one at a time before it goes a level at a time."""
        self._far = False
        """The last search met more than :attr:`near_states` states: the next goes a level at a
        time from the start (searches late in a run go far, one after another)."""
        self.twins: list[tuple[int, int]] = []
        """Pairs of states found to be one world state, moves being one-to-one: both
        lead by one action to a third state (:meth:`confirm`); :meth:`unify` merges them."""
        self.one_to_one = not feels
        """Whether a move that changes the state is taken to come from one state only (no two
        states lead by the same action to a third): twins are looked for and merged, and
        candidates checked against it. Not with ``feels`` (the states are then poses, told
        apart by what is felt)."""

    # ----------------------------------------------------------------- queries

    @property
    def version(self) -> int:
        """Changes whenever the model does."""
        return self.model.version

    @property
    def edits(self) -> int:
        """Changes whenever the confirmed successors, the states or their labels and feels do
        (confirming a successor already confirmed is no change): what is worked out from
        them alone holds while it stays the same."""
        return self._edits

    @property
    def columns(self) -> list[int]:
        """The action columns in the run's order (drawn once by ``rng``): the order in which
        searches and ties try the actions."""
        return self._columns

    def states(self) -> list[int]:
        return [int(s) for s in np.flatnonzero(self.alive)]

    def confirmed(self, s: int, action: int) -> int:
        """The confirmed successor of ``s`` by ``action``, or -1."""
        return int(self.next[s, self.column[action]])

    def target(self, s: int, action: int) -> int:
        """The model's successor (confirmed or conjectured) of ``s`` by ``action``."""
        return self.model.successors(s, action)[0]

    def with_label(self, sensation: bool) -> list[int]:
        """The states predicting ``sensation``, by id."""
        return [int(s) for s in np.flatnonzero(self.alive & (self.label == sensation))]

    def agree(self, states: IntArray, sensation: bool, feel: float) -> BoolArray:
        """Which of ``states`` agree with what was sensed (and felt, with ``feels``)."""
        same: BoolArray = self.label[states] == sensation
        if self.feels:
            felt = self.feel[states]
            alike = np.isnan(felt) | (felt == feel)
            if self.also_felt:  # (a merged state is also felt as the states merged into it)
                other = np.flatnonzero(self._merged[states] & ~alike)
                for i in other.tolist():
                    alike[i] = feel in self.also_felt[int(states[i])]
            same &= alike
        return same

    def agrees(self, s: int, sensation: bool, feel: float) -> bool:
        """Whether state ``s`` agrees with what was sensed (and felt, with ``feels``)."""
        if self.labels[s] != sensation:
            return False
        if not self.feels:
            return True
        felt = float(self.feel[s])
        if felt != felt or felt == feel:  # (NaN: unknown)
            return True
        return feel in self.also_felt.get(s, ())

    def feel_shared(self) -> bool:
        """With ``feels``: whether the feel fails to single out poses, :data:`SHARED_FEEL`
        states or more sharing each felt value on average, once :data:`FELT_STATES` states are
        felt (a rover's closeness to a region is felt alike in a ring of cells and every
        heading; an arm's is near one value a pose)."""
        if not self.feels or not self._by_feel:
            return False
        felt = len(self.labels) - len(self._unfelt)
        return felt >= FELT_STATES and felt >= SHARED_FEEL * len(self._by_feel)

    def matching(self, sensation: bool, feel: float) -> list[int]:
        """The states agreeing with what was sensed (and felt), by id."""
        found: list[int] = self.matching_ids(sensation, feel).tolist()
        return found

    def matching_ids(self, sensation: bool, feel: float) -> IntArray:
        """:meth:`matching` as an array (read-only). Without feels it is kept while the
        :attr:`edits` stay the same: a search for the landmark asks for it at every step."""
        key = (self._edits, sensation)
        if not self.feels and self._matched[0] == key:
            return self._matched[1]
        if self.feels and feel == feel:  # (the states felt so, and those never felt)
            felt = self._by_feel.get(feel, set()) | self._unfelt
            ids = np.fromiter(sorted(felt), dtype=np.int64, count=len(felt))
            agreeing: IntArray = ids[self.label[ids] == sensation]
            agreeing.flags.writeable = False
            return agreeing
        states = np.flatnonzero(self.alive)
        found = states[self.agree(states, sensation, feel)]
        found.flags.writeable = False
        if not self.feels:
            self._matched = (key, found)
        return found

    def follow(self, states: IntArray, action: int, sensation: bool, feel: float) -> IntArray:
        """The confirmed successors by ``action`` of ``states`` that agree with what was then
        sensed and felt (:meth:`agree`), in the order of ``states`` (repeats kept)."""
        moved: IntArray = self.next[:, self.column[action]][states]
        if not self.feels:  # (label[-1], read for an unconfirmed successor, is masked out)
            keep = self.label[moved]
            if sensation:
                keep &= moved >= 0
            else:
                keep |= moved < 0
                np.logical_not(keep, out=keep)
            return moved[keep]
        keep = moved >= 0
        keep[keep] = self.agree(moved[keep], sensation, feel)
        return moved[keep]

    def step(
        self, start: IntArray, position: IntArray, action: int, via: tuple[int, int]
    ) -> IntArray:
        """Where each candidate ``start[i]``, now at ``position[i]``, goes by ``action``.

        Candidate ``c`` stands for the hypothesis "``via`` leads to ``c``": from the first
        state of ``via`` by its action it goes back to ``c`` itself, whatever the model says.
        -1 where the successor is not confirmed.
        """
        moved: IntArray = self.next[position, self.column[action]]
        if action == via[1]:
            moved = np.where(position == via[0], start, moved).astype(np.int64)
        return moved

    def consistent(
        self,
        word: tuple[int, ...],
        outputs: tuple[bool, ...],
        via: tuple[int, int],
        feels: tuple[float, ...] = (),
        among: IntArray | None = None,
    ) -> IntArray:
        """The states ``c`` from which ``word`` yields ``outputs`` (the first: ``c``'s own
        label) and ``feels`` (with :attr:`feels`), if ``via`` leads to ``c`` (see
        :meth:`step`); of ``among`` only, if given (live states, in increasing order)."""
        felt = feels if self.feels and feels else (0.0,) * len(outputs)
        if among is None:
            start = self.matching_ids(outputs[0], felt[0])
        else:
            start = among[self.agree(among, outputs[0], felt[0])]
        position = start.copy()
        for action, sensation, feel in zip(word, outputs[1:], felt[1:], strict=True):
            moved = self.step(start, position, action, via)
            keep = moved >= 0
            keep[keep] = self.agree(moved[keep], sensation, feel)
            start, position = start[keep], moved[keep]
        return start

    def set_feel(self, s: int, feel: float) -> None:
        """What is felt at the world state ``s`` stands for (first felt now)."""
        self.feel[s] = feel
        self._refelt(s)

    def _refelt(self, s: int) -> None:
        """State ``s``'s feels changed (or it came or went): index it anew."""
        if not self.feels:
            return
        for key in self._feel_keys.pop(s, ()):
            states = self._by_feel[key]
            states.discard(s)
            if not states:
                del self._by_feel[key]
        self._unfelt.discard(s)
        if not self.alive[s]:
            return
        felt = float(self.feel[s])
        if felt != felt:
            self._unfelt.add(s)
            return
        keys = {felt, *self.also_felt.get(s, ())} if self._merged[s] else {felt}
        self._feel_keys[s] = tuple(keys)
        for key in keys:
            self._by_feel.setdefault(key, set()).add(s)

    def is_complete(self) -> bool:
        return self.unconfirmed == 0

    def _guide(self) -> tuple[IntArray, IntArray]:
        """Distances to the landmark over confirmed transitions, and the first step's column.

        Kept up to date as transitions are confirmed (:meth:`_added`); computed afresh (a
        breadth-first search from the landmark, one numpy pass per distance) after a change
        that can lengthen a path: a transition withdrawn or replaced, a merge.
        """
        if self._distance is None or self._toward is None:
            n = len(self.label)
            distance = np.full(n, FAR, dtype=np.int64)
            distance[self.landmark] = 0
            reached = np.zeros(n, dtype=bool)
            reached[self.landmark] = True
            confirmed = self.next >= 0
            targets = np.where(confirmed, self.next, self.landmark)
            level = 0
            while True:
                level += 1
                found = ~reached & self.alive & (confirmed & reached[targets]).any(axis=1)
                if not found.any():
                    break
                distance[found] = level
                reached |= found
            self._distance = distance
            self._toward = np.full(n, -1, dtype=np.int64)
            self._aim(np.flatnonzero(distance < FAR))
        return self._distance, self._toward

    def _aim(self, states: IntArray | list[int]) -> None:
        """``toward`` of ``states`` from the distances: the first action, in the run's order,
        to a successor one step nearer the landmark (-1 at the landmark and out of reach)."""
        distance, toward = self._distance, self._toward
        assert distance is not None and toward is not None
        if not len(states):
            return
        if len(states) <= 16:  # (a few states, one at a time: a confirmation's)
            for x in states:
                nearer = int(distance[x]) - 1
                row = self.next[x].tolist()
                toward[x] = next(
                    (k for k in self._columns if row[k] >= 0 and distance[row[k]] == nearer), -1
                )
            return
        successors = self.next[states][:, self._columns]
        ahead = np.where(successors >= 0, distance[np.maximum(successors, 0)], FAR)
        nearer = ahead == (distance[states] - 1)[:, None]
        first = nearer.argmax(axis=1)
        columns = np.asarray(self._columns, dtype=np.int64)[first]
        toward[states] = np.where(nearer.any(axis=1), columns, -1)

    def _added(self, s: int, t: int) -> None:
        """The confirmed transition ``s -> t`` is new: shorten the distances it shortens."""
        distance = self._distance
        if distance is None:
            return
        if distance[t] + 1 >= distance[s]:
            self._aim([s])
            return
        distance[s] = distance[t] + 1
        # Spread the shorter way back along the confirmed transitions into the states it
        # shortened, a level at a time; then aim again every state whose distance or whose
        # successor's distance changed.
        incoming = self.incoming
        changed = {s}
        frontier = [s]
        while frontier:
            level: list[int] = []
            for u in frontier:
                shorter = int(distance[u]) + 1
                for p, _ in incoming.predecessors(u):
                    if shorter < distance[p]:
                        distance[p] = shorter
                        level.append(p)
            frontier = level
            changed.update(level)
        aimed = set(changed)
        for u in changed:
            aimed.update(p for p, _ in incoming.predecessors(u))
        self._aim(sorted(aimed))

    @property
    def distance(self) -> IntArray:
        """``distance[s]``: confirmed steps from ``s`` to the landmark (:data:`FAR`: none)."""
        return self._guide()[0]

    @property
    def toward(self) -> IntArray:
        """``toward[s]``: the column of the first action of a shortest path to the landmark."""
        return self._guide()[1]

    def path(self, source: int, goal: int) -> list[int] | None:
        """A shortest confirmed action word from ``source`` to ``goal``: of the shortest, the
        first in the run's order of the actions (as a breadth-first search finds it)."""
        if goal == self.landmark:
            return self._home_word(source)
        wanted = np.zeros(len(self.label), dtype=bool)
        wanted[goal] = True
        found = self._search(source, wanted)
        return None if found is None else found[0]

    def nearest(self, source: int, wanted: set[int]) -> tuple[list[int], int] | None:
        """A shortest confirmed word from ``source`` to one of ``wanted``, and that state."""
        mask = np.zeros(len(self.label), dtype=bool)
        mask[list(wanted)] = True
        return self._search(source, mask)

    def nearest_where(self, source: int, wanted: BoolArray) -> tuple[list[int], int] | None:
        """:meth:`nearest`, the states wanted given as a mask over the state ids."""
        mask = np.zeros(len(self.label), dtype=bool)
        mask[: len(wanted)] = wanted[: len(mask)]
        return self._search(source, mask)

    def _home_word(self, source: int) -> list[int] | None:
        """The path to the landmark that :attr:`toward` points along: at each state the first
        action, in the run's order, to a state one step nearer. It is the word a breadth-first
        search from ``source`` finds (of the shortest words, the first in that order), in
        steps as many as its length."""
        distance, toward = self._guide()
        if distance[source] >= FAR:
            return None
        word: list[int] = []
        s = source
        while s != self.landmark:
            k = int(toward[s])
            word.append(self.actions[k])
            s = int(self.next[s, k])
        return word

    def _search(self, source: int, wanted: BoolArray) -> tuple[list[int], int] | None:
        """Breadth first over the confirmed transitions, the actions in the run's order: the
        word to the first state reached that is ``wanted``, and that state.

        A first-in first-out search, state by state, while it has met at most
        :attr:`near_states` states (the goal is most often a few steps away); past that, one
        numpy pass per distance from ``source``: each level's successors in the order the
        first-in first-out search meets them (state by state in the level's order, action by
        action), each state kept where it is first met; so the state found, and its word, are
        the same either way. After a search that met more than that, the next goes a level at
        a time from the start, until one meets fewer again."""
        if wanted[source]:
            return [], source
        if not self._far:
            near = self._search_near(source, wanted)
            if not isinstance(near, _TooFar):
                return near
        width = len(self.actions)
        columns = np.asarray(self._columns, dtype=np.int64)
        seen = np.zeros(len(self.label), dtype=bool)
        seen[source] = True
        level = np.asarray([source], dtype=np.int64)
        reached: list[IntArray] = []  # per level: where in the level before each state came from
        count = 1  # (the states met)
        while len(level):
            met = self.next[level[:, None], columns].ravel()  # (the level's rows only)
            where = np.flatnonzero(met >= 0)
            where = where[~seen[met[where]]]
            _, first = np.unique(met[where], return_index=True)
            where = where[np.sort(first)]  # each state where it was first met, in that order
            level = met[where]
            seen[level] = True
            reached.append(where)
            count += len(level)
            goals = np.flatnonzero(wanted[level])
            if len(goals):
                self._far = count > self.near_states
                at = int(goals[0])
                found = int(level[at])
                word: list[int] = []
                for came in reversed(reached):
                    word.append(self._ordered[int(came[at]) % width])
                    at = int(came[at]) // width
                word.reverse()
                return word, found
        self._far = count > self.near_states
        return None

    def _search_near(
        self, source: int, wanted: BoolArray
    ) -> tuple[list[int], int] | None | _TooFar:
        """:meth:`_search` one state at a time; :data:`_TOO_FAR` once it has met more than
        :attr:`near_states` states."""
        next_, columns, limit = self.next, self._columns, self.near_states
        parent: dict[int, tuple[int, int]] = {source: (source, -1)}
        queue = [source]
        for s in queue:
            row = next_[s].tolist()
            for i, k in enumerate(columns):
                t = row[k]
                if t < 0 or t in parent:
                    continue
                parent[t] = (s, i)
                if wanted[t]:
                    found, word = t, []
                    while t != source:
                        t, i = parent[t]
                        word.append(self._ordered[i])
                    word.reverse()
                    return word, found
                queue.append(t)
            if len(queue) > limit:
                return _TOO_FAR
        return None

    def around(self, source: int, radius: int) -> set[int]:
        """The states within ``radius`` confirmed transitions of ``source``, either way."""
        sources, columns = np.nonzero(self.next >= 0)
        targets = self.next[sources, columns]
        near = {source}
        frontier = {source}
        for _ in range(radius):
            touched = np.isin(sources, list(frontier)) | np.isin(targets, list(frontier))
            frontier = {int(v) for v in np.concatenate([sources[touched], targets[touched]])}
            frontier -= near
            near |= frontier
        return near

    def inverses(self) -> dict[int, int]:
        """Actions that undo others, as far as the confirmed transitions show.

        ``b`` undoes ``a`` when, of the confirmed ``s -a-> t`` (``t != s``) with a confirmed
        ``t -b->``, most have ``t -b-> s``: learned from the agent's own experience, used to
        guess, never to conclude. (Read from the counts :attr:`incoming` keeps, after each
        change of the hypothesis.)
        """
        if self._inverse[0] == self._edits:
            return self._inverse[1]
        inverse: dict[int, int] = {}
        back, known = self.incoming.back, self.incoming.known
        for ka, a in enumerate(self.actions):
            best, best_count = -1, 0
            for kb, count in enumerate(back[ka]):
                if count > best_count and 2 * count >= known[ka][kb]:
                    best, best_count = kb, count
            if best >= 0:
                inverse[a] = self.actions[best]
        self._inverse = (self._edits, inverse)
        return inverse

    def not_commuting(self) -> BoolArray:
        """``[ka, kb]``: the confirmed squares show actions ``ka`` and ``kb`` do not commute:
        of the states ``s`` with ``s -a-> -b->`` and ``s -b-> -a->`` both confirmed, at least
        :data:`EVIDENCE`, fewer than half reach one state both ways (a rover's turn and step,
        unlike two joints' turns). Too few squares show nothing."""
        if self._commuting[0] == self._edits:
            return self._commuting[1]
        squares = np.asarray(self.incoming.squares, dtype=np.int64)
        closed = np.asarray(self.incoming.closed, dtype=np.int64)
        shown = (squares >= EVIDENCE) & (2 * closed < squares)
        shown |= shown.T
        self._commuting = (self._edits, shown)
        return shown

    def reversible(self) -> bool:
        """Whether the confirmed transitions show an action undoing each action
        (:meth:`inverses`): then no move leads into a part of the world the agent cannot leave."""
        return len(self.inverses()) == len(self.actions)

    def irreversible(self) -> bool:
        """Whether the confirmed transitions show an action that no action undoes: one with
        at least :data:`EVIDENCE` confirmed moves ``s -a-> t`` (``t != s``) from states ``t``
        whose every transition is confirmed, and no action taking most of those ``t`` back
        to their ``s``. Too few such moves prove nothing: a world the agent has seen little
        of is not taken as one it cannot return from."""
        states = np.flatnonzero(self.alive)
        whole = states[(self.next[states] >= 0).all(axis=1)]
        known = np.zeros(len(self.label), dtype=bool)
        known[whole] = True
        for ka in range(len(self.actions)):
            t = self.next[states, ka]
            moved = (t >= 0) & (t != states)
            moved[moved] = known[t[moved]]
            sources, targets = states[moved], t[moved]
            if len(sources) < EVIDENCE:
                continue
            back = self.next[targets] == sources[:, None]
            if not (2 * back.sum(axis=0) >= len(sources)).any():
                return True
        return False

    def reachable(self) -> set[int]:
        """The states reachable from the landmark over confirmed transitions."""
        seen = {self.landmark}
        queue = deque([self.landmark])
        while queue:
            s = queue.popleft()
            for t in self.next[s].tolist():
                if t >= 0 and t not in seen:
                    seen.add(t)
                    queue.append(t)
        return seen

    def separating_word(self, a: int, b: int) -> list[int] | None:
        """A shortest confirmed word after which ``a`` and ``b`` predict different sensations.

        Breadth first over pairs of states, one numpy pass per level: a pair is kept unordered
        (the same words tell ``(s, t)`` and ``(t, s)`` apart) and dropped once its two states
        meet (no word tells a state from itself). Of the shortest words, the one found first
        by the pairs in the order they were reached and the actions in their order, as a
        pair-by-pair search would find it. None: nothing confirmed tells them apart.
        """
        if self.label[a] != self.label[b]:
            return []
        if a == b:
            return None
        alive = np.flatnonzero(self.alive)
        m = len(alive)
        index = np.full(len(self.label) + 1, -1, dtype=np.int64)  # (index[-1]: unconfirmed)
        index[alive] = np.arange(m)
        following = index[self.next[alive]].astype(np.int32)  # compact; -1: unconfirmed
        label = self.label[alive]
        first, second = int(index[a]), int(index[b])
        seen = np.zeros(m * m, dtype=bool)
        seen[min(first, second) * m + max(first, second)] = True
        low = np.asarray([first], dtype=np.int64)
        high = np.asarray([second], dtype=np.int64)
        levels: list[tuple[IntArray, IntArray]] = []  # per level: each pair's parent, action
        width = len(self.actions)
        while len(low):
            s, t = following[low], following[high]  # (pairs, actions), pair by pair
            known = (s >= 0) & (t >= 0) & (s != t)
            apart = known & (label[np.maximum(s, 0)] != label[np.maximum(t, 0)])
            if apart.any():
                at = int(np.flatnonzero(apart.ravel())[0])
                word = [self.actions[at % width]]
                parent = at // width
                for parents, actions in reversed(levels):
                    word.append(self.actions[int(actions[parent])])
                    parent = int(parents[parent])
                return word[::-1]
            found = np.flatnonzero(known.ravel())
            s, t = s.ravel()[found], t.ravel()[found]
            low, high = np.minimum(s, t), np.maximum(s, t)
            codes = low.astype(np.int64) * m + high
            fresh = np.flatnonzero(~seen[codes])
            codes, firsts = np.unique(codes[fresh], return_index=True)
            seen[codes] = True
            firsts = fresh[np.sort(firsts)]  # in the order in which the level reached them
            reached = found[firsts]
            levels.append((reached // width, reached % width))
            low, high = low[firsts], high[firsts]
        return None

    # ----------------------------------------------------------------- changes

    def _changed(self) -> None:
        """A change that may lengthen paths to the landmark: the guide is worked out afresh."""
        self._distance = None
        self._toward = None

    def confirm(self, s: int, action: int, t: int) -> None:
        """Make ``s -action-> t`` the confirmed successor (replacing the model's conjecture)."""
        k = self.column[action]
        before = int(self.next[s, k])
        if before != t:
            self._edits += 1
        if before < 0:
            self.unconfirmed -= 1
        self.incoming.set(self.next, s, k, t)
        old = self.target(s, action)
        if old != t:
            self.model.delete(s, old, action)
            self.model.add(s, t, action)
        if before < 0:
            self._added(s, t)
        elif before != t:
            self._changed()
        if self.one_to_one and t != s:
            self._look_for_twins(t, k)

    def _look_for_twins(self, t: int, k: int) -> None:
        """Queue as twins the states leading to ``t`` by column ``k`` that are shown to be
        other states than ``t`` (:meth:`apart`): a move from them, not a blocked one."""
        sources = [u for u, column in self.incoming.predecessors(t) if column == k and u != t]
        if len(sources) < 2:
            return
        moved = [u for u in sources if self.apart(u, t)]
        for u in moved[1:]:
            self.twins.append((min(moved[0], u), max(moved[0], u)))

    def apart(self, s: int, t: int) -> bool:
        """Whether the confirmed transitions show ``s`` and ``t`` are two world states: their
        labels differ, or one's path to the landmark, walked from the other, predicts another
        sensation on the way."""
        if self.labels[s] != self.labels[t]:
            return True
        distance, toward, label = self.distance, self.toward, self.label
        for first, second in ((s, t), (t, s)):
            if distance[first] >= FAR:
                continue
            a, b = first, second
            while a != self.landmark:
                k = int(toward[a])
                a, b = int(self.next[a, k]), int(self.next[b, k])
                if b < 0:
                    break
                if label[a] != label[b]:
                    return True
        return False

    def unify(self) -> list[tuple[int, int]]:
        """Merge the :attr:`twins` found, and the twins their merges show (their successors by
        one action, both confirmed, are twins too); the merges done, as ``(kept, gone)``.

        A pair the confirmed transitions show apart (:meth:`apart`) is not merged: a
        confirmation is wrong somewhere, which the counterexamples and the verification find."""
        merges: list[tuple[int, int]] = []
        alias: dict[int, int] = {}

        def find(s: int) -> int:
            while s in alias:
                s = alias[s]
            return s

        while self.twins:  # (queued only while one_to_one)
            a, b = self.twins.pop()
            a, b = find(a), find(b)
            if a == b:
                continue
            keep, gone = min(a, b), max(a, b)
            if self.apart(keep, gone):  # (a wrong confirmation somewhere: not merged)
                continue
            model = self.model
            for k, action in enumerate(self.actions):
                tk, tg = int(self.next[keep, k]), int(self.next[gone, k])
                if tg < 0:
                    continue
                tg = keep if tg == gone else tg
                if tk < 0:
                    self.confirm(keep, action, tg)
                elif find(tk) != find(tg):
                    self.twins.append((tk, tg))
            self.merge(keep, gone)
            alias[gone] = keep
            merges.append((keep, gone))
            for k, action in enumerate(self.actions):  # one successor by each action
                targets = model.successors(keep, action)
                wanted = int(self.next[keep, k])
                wanted = wanted if wanted >= 0 else targets[0]
                for v in targets:
                    if v != wanted:
                        model.delete(keep, v, action)
                if wanted not in targets:
                    model.add(keep, wanted, action)
            for k in range(len(self.actions)):
                self._look_for_twins(keep, k)
            self.twins = [(find(x), find(y)) for x, y in self.twins if find(x) != find(y)]
        return merges

    def unconfirm(self, s: int, action: int) -> None:
        """Withdraw a confirmed successor; the model keeps it as a conjecture."""
        k = self.column[action]
        if self.next[s, k] >= 0:
            self._edits += 1
            self.unconfirmed += 1
            self.incoming.set(self.next, s, k, -1)
            self._changed()

    def create(
        self, s: int, action: int, sensation: bool, access: tuple[int, ...], feel: float = np.nan
    ) -> int:
        """A new state for the world state ``s -action->`` leads to, by splitting the guess.

        The model's conjectured successor ``t`` of ``s`` by ``action`` turned out to stand for
        two world states: ``split(t)`` (the thesis's split), then the copied transitions that
        would make the model nondeterministic are deleted. The new state keeps copies of
        ``t``'s transitions as its conjectures (a self-loop of ``t`` becomes its own).
        """
        self._edits += 1
        model = self.model
        t = self.target(s, action)
        incoming = model.transitions_into(t)
        new = model.split(t)
        for u, a in incoming:
            if u == t:
                # t -a-> t was copied as t -a-> new, new -a-> t and new -a-> new.
                model.delete(new, t, a)
                if (u, a) == (s, action):
                    model.delete(t, t, a)
                else:
                    model.delete(t, new, a)
            elif (u, a) == (s, action):
                model.delete(u, t, a)
            else:
                model.delete(u, new, a)
        self._grow(new)
        self.alive[new] = True
        self.label[new] = sensation
        self.labels[new] = sensation
        self.feel[new] = feel
        self._refelt(new)
        self.access[new] = access
        for column in range(len(self.actions)):
            self.incoming.set(self.next, new, column, -1)
        self.incoming.open_row(new, self.next[new])
        self.unconfirmed += len(self.actions)
        k = self.column[action]
        before = int(self.next[s, k])
        if before < 0:
            self.unconfirmed -= 1
        self.incoming.set(self.next, s, k, new)
        if before >= 0:
            self._changed()
        return new

    def add_silent(self) -> int:
        """A new state for a part of the world that never senses: it predicts false, and every
        action leads back to it (confirmed). Made by splitting the landmark, its copied
        transitions then deleted."""
        self._edits += 1
        model = self.model
        new = model.split(self.landmark)
        for u, a, v in model.transitions():
            if new in (u, v):
                model.delete(u, v, a)
        for a in self.actions:
            model.add(new, new, a)
        self._grow(new)
        self.alive[new] = True
        self.label[new] = False
        self.feel[new] = np.nan
        self._refelt(new)
        self.labels[new] = False
        self.access[new] = ()
        for column in range(len(self.actions)):
            self.incoming.set(self.next, new, column, new)
        self.incoming.open_row(new, self.next[new])
        return new

    def merge(self, keep: int, gone: int) -> None:
        """``gone`` is the same world state as ``keep``: the model's merge, then the arrays."""
        self._edits += 1
        self.model.merge(keep, gone)
        felt = self.also_felt.pop(gone, set())
        felt.add(float(self.feel[gone]))
        felt.discard(float(self.feel[keep]))
        felt = {f for f in felt if f == f}
        if felt:
            self.also_felt.setdefault(keep, set()).update(felt)
            self._merged[keep] = True
        self._merged[gone] = False
        self.unconfirmed -= int(np.count_nonzero(self.next[gone] < 0))
        incoming = self.incoming
        for column in range(len(self.actions)):
            incoming.set(self.next, gone, column, -1)
        for u, column in incoming.predecessors(gone):
            incoming.set(self.next, u, column, keep)
        incoming.close_row(gone)
        self.alive[gone] = False
        self._refelt(gone)
        self._refelt(keep)
        del self.labels[gone]
        del self.access[gone]
        if self.landmark == gone:
            self.landmark = keep
        self._changed()

    def discard(self, gone: int) -> None:
        """Drop a state no confirmed path reaches: its transitions go, then it merges away."""
        model = self.model
        for action in self.actions:
            for t in model.successors(gone, action):
                model.delete(gone, t, action)
        self.feel[gone] = self.feel[self.landmark]  # (the landmark keeps its feels)
        self.also_felt.pop(gone, None)
        self._merged[gone] = False
        self.merge(self.landmark, gone)

    def _grow(self, s: int) -> None:
        capacity = len(self.label)
        if s < capacity:
            return
        size = max(2 * capacity, s + 1)
        grown = np.full((size, len(self.actions)), -1, dtype=np.int64)
        grown[:capacity] = self.next
        self.next = grown
        self.label = np.concatenate([self.label, np.zeros(size - capacity, dtype=bool)])
        self.alive = np.concatenate([self.alive, np.zeros(size - capacity, dtype=bool)])
        if self._distance is not None and self._toward is not None:
            self._distance = np.concatenate([self._distance, np.full(size - capacity, FAR)])
            self._toward = np.concatenate([self._toward, np.full(size - capacity, -1)])
        self.feel = np.concatenate([self.feel, np.full(size - capacity, np.nan)])
        self.incoming.grow(size)
        self._merged = np.concatenate([self._merged, np.zeros(size - capacity, dtype=bool)])

    def minimise(self) -> list[tuple[int, int]]:
        """Merge the states the complete hypothesis cannot tell apart (Moore's refinement).

        Returns the merges done, as ``(kept, gone)``; the oldest state of a class is kept.
        """
        states = np.flatnonzero(self.alive)
        index = np.full(len(self.label), -1, dtype=np.int64)
        index[states] = np.arange(len(states))
        block = moore_classes(index[self.next[states]], self.label[states])
        merges: list[tuple[int, int]] = []
        first: dict[int, int] = {}
        for s, b in zip(states.tolist(), block.tolist(), strict=True):
            keep = first.setdefault(b, s)
            if keep != s:
                merges.append((keep, s))
        for keep, gone in merges:
            self.merge(keep, gone)
        return merges
