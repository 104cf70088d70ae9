"""The ``splitter`` strategy: the original platform's contradiction-splitting learner, fixed."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar

from rsstp_sim.errors import StrategyError
from rsstp_sim.strategies._base import AgentView, StrategyBase
from rsstp_sim.strategies.random_walk import RandomStrategy
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["SplitterStrategy"]

_Key = tuple[int, int]
"""A point in a history: (context id of the pairs seen so far, the next action)."""
_Row = tuple[int, int]
"""A row of the model: (state, action)."""

_FALSE, _TRUE = 1, 2
"""Bits of a mask: which sensations followed a key."""
_BOTH = _FALSE | _TRUE


def _bit(sensation: bool) -> int:
    return _TRUE if sensation else _FALSE


def _conflict(a: int, b: int) -> bool:
    """One mask saw a sensation the other saw the opposite of."""
    return bool((a & _FALSE and b & _TRUE) or (a & _TRUE and b & _FALSE))


_Owner = TypeVar("_Owner", int, _Row)


def _mark(
    masks_by: dict[_Owner, dict[_Key, int]],
    index: dict[tuple[_Key, int], set[_Owner]],
    owner: _Owner,
    key: _Key,
    bit: int,
) -> int | None:
    """Set ``bit`` of ``key`` for ``owner`` (and index it): the mask before, or None when the
    bit was already set."""
    masks = masks_by.get(owner)
    if masks is None:
        masks = masks_by[owner] = {}
    old = masks.get(key, 0)
    if old & bit:
        return None
    masks[key] = old | bit
    holders = index.get((key, bit))
    if holders is None:
        index[(key, bit)] = {owner}
    else:
        holders.add(owner)
    return old


@dataclass(slots=True)
class _Visit:
    """A history being written: the visit of ``state`` at time ``time``.

    ``context`` names the (action, sensation) pairs seen since the visit; ``shifted`` is the row
    ``(state at time - 1, action at time)`` whose continuation this history also is, or None
    when time - 1 is before the histories began.
    """

    time: int
    state: int
    context: int
    shifted: _Row | None


class _Histories:
    """Per-state histories since the last split, indexed for contradictions and pruning.

    A history key ``(c, a)`` is a context ``c`` (the pairs ``(a_1, o_1) .. (a_{k-1}, o_{k-1})``
    after a visit, interned to an int) and the next action ``a = a_k``; its mask says which
    sensations ``o_k`` followed. ``own[s]`` holds the keys of the histories of state ``s``;
    ``shifted[(u, a)]`` the keys of the histories of ``u`` that began with action ``a``, with
    that first pair dropped (what ``u`` predicts after ``a``: what its ``a``-successor must
    not contradict). Two inverted indexes answer "which states / rows saw the opposite after
    this key" in time proportional to the answer; ``inconsistent[(u, a)]`` gathers the states
    that ``u -a->`` must not lead to.
    """

    def __init__(self) -> None:
        self.intern: dict[tuple[int, int, bool], int] = {}
        self.own: dict[int, dict[_Key, int]] = {}
        self.shifted: dict[_Row, dict[_Key, int]] = {}
        self.own_index: dict[tuple[_Key, int], set[int]] = {}
        self.shifted_index: dict[tuple[_Key, int], set[_Row]] = {}
        self.inconsistent: dict[_Row, set[int]] = {}
        self.visits: dict[int, list[int]] = {}
        self.barred: set[_Row] = set()
        """Rows whose barred set grew since the last prune."""

    def child(self, context: int, action: int, sensation: bool) -> int:
        key = (context, action, sensation)
        found = self.intern.get(key)
        if found is None:
            found = self.intern[key] = len(self.intern) + 1  # 0 is the empty context
        return found

    def observe_own(self, state: int, key: _Key, bit: int) -> bool:
        """Record ``key -> bit`` for ``state``; True when that makes a contradiction."""
        old = _mark(self.own, self.own_index, state, key, bit)
        if old is None:
            return False
        for row in self.shifted_index.get((key, _BOTH - bit), ()):
            bar = self.inconsistent.get(row)
            if bar is None:
                self.inconsistent[row] = {state}
                self.barred.add(row)
            elif state not in bar:
                bar.add(state)
                self.barred.add(row)
        return old != 0

    def observe_shifted(self, row: _Row, key: _Key, bit: int) -> None:
        """Record ``key -> bit`` for the continuation of ``row``."""
        if _mark(self.shifted, self.shifted_index, row, key, bit) is None:
            return
        opposite = self.own_index.get((key, _BOTH - bit))
        if not opposite:
            return
        bar = self.inconsistent.get(row)
        if bar is None:
            self.inconsistent[row] = set(opposite)
            self.barred.add(row)
        elif not opposite <= bar:
            bar |= opposite
            self.barred.add(row)


class SplitterStrategy(StrategyBase):
    """The contradiction-splitting learner of the original platform (its ``algo.py``), fixed.

    **Actions.** Uniformly random, drawn from ``agent.rng`` exactly as the ``random``
    strategy draws them.

    **Histories.** Every time ``t`` is a visit of the internal state ``s_t`` the memory
    records. The strategy keeps, per state, the histories that followed its visits: the
    ``(action, sensation)`` pairs after ``t``, up to ``horizon`` of them, since the last split.
    Each state has its own histories (the original shared one list between every state, so
    every state's histories were every state's).

    **Split.** A state whose histories contradict (two visits, the same actions, the same
    sensations, then a different sensation: docs/model.md, within the horizon) is split
    in two: the state keeps the side of the contradiction its first visit was on, the new state
    takes the other side (the original made one copy per contradicting history; one per side is
    enough, two sides being all a boolean sensation has). As the original's trim did, a
    transition ``u -a->`` into either half is then deleted when what ``u``'s histories show
    after ``a`` contradicts that half's side (the halves judged by their own side's histories),
    and a row left empty goes to every state. Then every history is forgotten, as in the
    original: the old visits carry the old label and would contradict again.

    **Pruning**, every step: ``u -a-> j`` is deleted when some history of ``u`` that began with
    ``a`` contradicts, from there on, some history of ``j`` (had the visit after ``a`` been in
    ``j``, ``j`` would have a contradiction). When that would leave ``u`` with no ``a``
    transition, ``u -a->`` goes to every state not barred (to every state if all are): the
    original's "untrim", without its delete-and-re-add churn at every step.

    **Where it fails.** It only splits and deletes, never merges, so the redundant states a
    wrong split creates stay. It forgets every history at every split, so evidence is gathered
    again from scratch. Pruning that runs out of candidates refills a row with every state,
    making the model nondeterministic; the runner then picks successors at random, the memory's
    labels stop meaning anything, and the histories produce new contradictions, so the model
    keeps growing and stays nondeterministic. Contradictions longer than ``horizon`` are not
    seen. On ``thesis-algo`` (360 true states) with seed 1 it has 11 states after 1000 steps,
    19 of their 22 (state, action) pairs nondeterministic.

    ``horizon`` (>= 1): the most pairs a history keeps.
    """

    name: ClassVar[str] = "splitter"

    def __init__(self, *, horizon: int = 8) -> None:
        if isinstance(horizon, bool) or not isinstance(horizon, int) or horizon < 1:
            raise StrategyError(
                "splitter: parameter horizon: expected an integer >= 1 (horizon=3), got "
                f"{horizon!r}"
            )
        self._horizon = horizon
        self._explorer = RandomStrategy()
        self._histories = _Histories()
        self._active: list[_Visit] = []
        self._since = 0

    def params(self) -> Mapping[str, Any]:
        return {"horizon": self._horizon}

    def reset(self, agent: AgentView) -> None:
        self._explorer.reset(agent)
        self._forget(agent, 0)

    def choose_action(self, agent: AgentView) -> int:
        return self._explorer.choose_action(agent)

    # -- what a test or a viewer may ask -------------------------------------------------------

    @property
    def histories_since(self) -> int:
        """The time of the first visit of the current histories (the last split's step)."""
        return self._since

    def visits(self, state: int) -> tuple[int, ...]:
        """The times whose histories ``state`` keeps (its visits since the last split)."""
        return tuple(self._histories.visits.get(state, ()))

    # -- one step ------------------------------------------------------------------------------

    def refine(self, agent: AgentView) -> None:
        entry = agent.memory[-1]
        now = agent.step
        action = entry.action
        if action is None:  # entry 0: nothing has followed any visit yet
            return
        bit = _bit(entry.sensation)
        histories = self._histories
        contradicted: list[tuple[int, _Key]] = []
        still: list[_Visit] = []
        horizon = self._horizon
        for visit in self._active:
            key = (visit.context, action)
            if histories.observe_own(visit.state, key, bit):
                contradicted.append((visit.state, key))
            if now - visit.time < horizon:
                if visit.shifted is not None:
                    histories.observe_shifted(visit.shifted, key, bit)
                visit.context = histories.child(visit.context, action, entry.sensation)
                still.append(visit)
        # The history from now continues the one from now - 1 after its first pair.
        previous = self._active[-1] if self._active else None
        shifted = None
        if previous is not None and previous.time == now - 1:
            shifted = (previous.state, action)
        still.append(_Visit(now, entry.internal_state, 0, shifted))
        histories.visits.setdefault(entry.internal_state, []).append(now)
        self._active = still
        if histories.barred:
            self._prune(agent.model, histories.barred)
            histories.barred = set()
        if contradicted:
            state, key = min(contradicted)
            self._split(agent, state, key)

    def _prune(self, model: TransitionSystem, rows: Iterable[_Row]) -> None:
        """Delete the barred successors of ``rows``; refill a row that would be left empty."""
        inconsistent = self._histories.inconsistent
        for u, a in sorted(rows):
            if u not in model:
                continue
            bar = inconsistent[(u, a)]
            successors = model.successors(u, a)
            bad = [j for j in successors if j in bar]
            if len(bad) < len(successors):
                for j in bad:
                    model.delete(u, j, a)
                continue
            # Nothing would be left. The original's "untrim" sends the row to every state
            # (and deletes it again at the next step); here to every state not barred, or to
            # every state when all are.
            free = [j for j in model.states if j not in bar]
            for j in bad if free else ():
                model.delete(u, j, a)
            for j in free or model.states:
                model.add(u, j, a)

    # -- split ---------------------------------------------------------------------------------

    def _split(self, agent: AgentView, state: int, key: _Key) -> None:
        """Split ``state`` along the contradiction at ``key``; trim; forget every history."""
        model, memory = agent.model, agent.memory
        actions = memory.actions.tolist()
        sensations = memory.sensations.tolist()
        now = len(actions) - 1
        sides: dict[int, list[int]] = {_FALSE: [], _TRUE: []}
        for visit in self._histories.visits.get(state, ()):
            for k, bit in self._walk(visit, actions, sensations, self._horizon):
                if k == key:
                    sides[bit].append(visit)
                    break
        first, second = sorted(sides.values(), key=lambda times: times[0])
        new = model.split(state)
        agent.note(
            f"contradiction in state {state}: visits {first[0]} and {second[0]} differ after "
            f"the same actions; split off state {new}"
        )
        groups = {state: first, new: second}
        own = {s: self._own_masks(times, actions, sensations) for s, times in groups.items()}
        shifted = {
            s: self._shifted_masks(times, actions, sensations) for s, times in groups.items()
        }
        index = self._histories.shifted_index
        touched: set[_Row] = set()
        for target, masks in own.items():
            # Sources other than the two halves: their current histories, through the index.
            barred = {
                row
                for k, mask in masks.items()
                for bit in (_FALSE, _TRUE)
                if mask & bit
                for row in index.get((k, _BOTH - bit), ())
                if row[0] not in groups
            }
            # The two halves: the histories of their own side.
            for source in groups:
                for a, continuation in shifted[source].items():
                    if any(_conflict(m, masks.get(k, 0)) for k, m in continuation.items()):
                        barred.add((source, a))
            for u, a in sorted(barred):
                if model.delete(u, target, a):
                    touched.add((u, a))
        states = model.states
        for u, a in sorted(touched):
            if not model.successors(u, a):
                for j in states:
                    model.add(u, j, a)
        self._forget(agent, now)

    def _walk(
        self, start: int, actions: list[int], sensations: list[bool], limit: int
    ) -> Iterable[tuple[_Key, int]]:
        """The keys and sensation bits of the history from ``start``, at most ``limit`` pairs."""
        context, t, end = 0, start, min(len(actions) - 1, start + limit)
        while t < end:
            t += 1
            yield (context, actions[t]), _bit(sensations[t])
            found = self._histories.intern.get((context, actions[t], sensations[t]))
            if found is None:
                return
            context = found

    def _own_masks(
        self, times: list[int], actions: list[int], sensations: list[bool]
    ) -> dict[_Key, int]:
        masks: dict[_Key, int] = {}
        for start in times:
            for k, bit in self._walk(start, actions, sensations, self._horizon):
                masks[k] = masks.get(k, 0) | bit
        return masks

    def _shifted_masks(
        self, times: list[int], actions: list[int], sensations: list[bool]
    ) -> dict[int, dict[_Key, int]]:
        by_action: dict[int, dict[_Key, int]] = {}
        for start in times:
            if start + 1 >= len(actions):
                continue
            masks = by_action.setdefault(actions[start + 1], {})
            for k, bit in self._walk(start + 1, actions, sensations, self._horizon - 1):
                masks[k] = masks.get(k, 0) | bit
        return by_action

    def _forget(self, agent: AgentView, now: int) -> None:
        """Drop every history; the next one starts with the visit at ``now``."""
        self._histories = _Histories()
        state = int(agent.memory.internal_states[now])
        self._active = [_Visit(now, state, 0, None)]
        self._histories.visits[state] = [now]
        self._since = now
