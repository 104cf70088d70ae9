"""The ``script`` strategy: a given action sequence, repeated."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

from rsstp_sim.errors import StrategyError
from rsstp_sim.strategies._base import AgentView, StrategyBase

__all__ = ["ScriptStrategy"]


class ScriptStrategy(StrategyBase):
    """Plays ``actions`` in order and starts again at the end; the model is never refined.

    With no actions given it cycles through every action of the scenario once
    per round (``0, 1, ..., 2n-1, 0, ...``).
    """

    name: ClassVar[str] = "script"

    def __init__(self, actions: Sequence[int] = ()) -> None:
        if not isinstance(actions, list | tuple) or any(
            isinstance(a, bool) or not isinstance(a, int) or a < 0 for a in actions
        ):
            raise StrategyError(
                f"script: parameter actions: expected a list of integers >= 0 (actions=[0,1]), "
                f"got {actions!r}"
            )
        self._actions = tuple(actions)
        self._plan: tuple[int, ...] = ()
        self._index = 0

    def params(self) -> Mapping[str, Any]:
        return {"actions": list(self._actions)}

    def reset(self, agent: AgentView) -> None:
        plan = self._actions or agent.actions
        unknown = sorted(set(plan) - set(agent.actions))
        if unknown:
            raise StrategyError(
                f"script: actions {unknown} are not among the scenario's actions "
                f"{list(agent.actions)}"
            )
        self._plan, self._index = plan, 0

    def choose_action(self, agent: AgentView) -> int:
        action = self._plan[self._index]
        self._index = (self._index + 1) % len(self._plan)
        return action
