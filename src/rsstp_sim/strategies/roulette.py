"""The ``roulette`` strategy: the thesis's own learning algorithm (section 5.3), reproduced."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from rsstp_sim.errors import StrategyError
from rsstp_sim.memory import CompareKind
from rsstp_sim.strategies._base import AgentView, StrategyBase
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["RouletteStrategy"]


class RouletteStrategy(StrategyBase):
    """The thesis's algorithm (section 5.3, Figure 19): one action, compare, split, rewire.

    **Actions.** Always the same one, ``action`` (an action of the scenario: joint
    ``action // 2`` turns by ``+step_deg`` when even, ``-step_deg`` when odd; the thesis's "move
    to the right"); by default the scenario's first action. **Observations:** the boolean
    sensations in the memory and the ``compare`` of sub-memories, nothing else. The thesis ran it
    on ``thesis-roulette``: one joint, 90-degree steps, one action, so four poses with the
    sensation true at the start pose only.

    **Model.** It starts from the thesis's initial matrix, one state with a self-loop
    (:meth:`TransitionSystem.universal`). It keeps the model a chain
    ``0 -> 1 -> ... -> last`` with a self-loop on ``last`` for ``action``, so the internal state
    walks along the chain and then stays in the last state.

    **Refinement**, after every move, as the thesis's demo script (``Demo_roulette.py``) did:
    compare the newest sub-memory with the one starting one entry earlier
    (``memory.compare(T, T-1)``), then ``(T-1, T-2)`` and so on backwards, while the comparison
    finds a *sensation* difference. For every such difference it splits the most recent state
    (the chain's last) and deletes the transitions the split copied that break the chain
    (``prev -> new``, ``last -> last``, ``new -> last``), so the chain continues into the new
    state, which gets the self-loop. The first comparison that is not a sensation difference (a
    different internal state, or identical sub-memories) ends the refinement of that step.
    Every model change is a ``split`` or a ``delete``; every split is noted with the pair of
    entries that caused it.

    The thesis's memory had no entry for the start pose (its index ``i`` is the entry written by
    the ``(i + 1)``-th move, our entry ``i + 1``), so its comparisons went down to its indices
    ``(1, 0)``, our entries ``(2, 1)``: the reset entry takes no part, as in the thesis. (Taking
    it in changes nothing at 30, 100 or 300 moves; 502 states instead of 501 at 1000.)

    **Where it fails** (thesis 5.3, last paragraph): it never merges and it cannot recognise a
    state it has already created. Every return to the feedback point looks like a new
    inconsistency, so it keeps splitting: on ``thesis-roulette`` it has 16 states after 30 moves,
    52 after 100 and 152 after 300 (the true model has 4), one new state every two moves, without
    bound. The internal states in the memory run along a chain, never round a cycle, and the last
    state of each moment stands for several poses: the memory itself contradicts half of them
    (75 of the 152 states at 300 moves), however long it runs.
    """

    name: ClassVar[str] = "roulette"

    def __init__(self, *, action: int | None = None) -> None:
        if action is not None and (
            isinstance(action, bool) or not isinstance(action, int) or action < 0
        ):
            raise StrategyError(
                f"roulette: parameter action: expected an integer >= 0 (action=0), got {action!r}"
            )
        self._action_param = action
        self._action = 0
        self._chain: list[int] = []

    def params(self) -> Mapping[str, Any]:
        return {"action": self._action_param}

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        return TransitionSystem.universal(actions)

    def reset(self, agent: AgentView) -> None:
        action = agent.actions[0] if self._action_param is None else self._action_param
        if action not in agent.actions:
            raise StrategyError(
                f"roulette: action {action} is not among the scenario's actions "
                f"{list(agent.actions)}"
            )
        self._action = action
        self._chain = [agent.model.current]

    def choose_action(self, agent: AgentView) -> int:
        return self._action

    def refine(self, agent: AgentView) -> None:
        memory = agent.memory
        for t in range(len(memory) - 1, 1, -1):
            result = memory.compare(t, t - 1)
            if result.kind is not CompareKind.DIFFERENT_SENSATION:
                return
            new = self._extend_chain(agent.model)
            agent.note(
                f"compare({t}, {t - 1}): sensation differs at offset {result.offset}; "
                f"split state {self._chain[-2]} into {new}"
            )

    def _extend_chain(self, model: TransitionSystem) -> int:
        """Split the chain's last state and rewire so that the chain ends ``last -> new -> new``."""
        a = self._action
        last = self._chain[-1]
        new = model.split(last)
        # The split copied ``prev -> last`` into ``prev -> new`` and the self-loop into
        # ``last -> last``, ``last -> new``, ``new -> last`` and ``new -> new``; the demo
        # script deleted, row by row, every transition of the action off the chain.
        if len(self._chain) > 1:
            model.delete(self._chain[-2], new, a)
        model.delete(last, last, a)
        model.delete(new, last, a)
        self._chain.append(new)
        return new
