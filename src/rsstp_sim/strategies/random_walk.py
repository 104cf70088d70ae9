"""The ``random`` strategy: uniformly random actions, no learning."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from rsstp_sim.strategies._base import AgentView, StrategyBase

__all__ = ["RandomStrategy"]


class RandomStrategy(StrategyBase):
    """Uniformly random actions from the run's generator; the model is never refined.

    Draws are taken from ``agent.rng`` in blocks of ``block`` (a pure speed
    measure: the sequence is a function of the seed alone).
    """

    name: ClassVar[str] = "random"

    def __init__(self, *, block: int = 4096) -> None:
        self._block = block
        self._buffer: list[int] = []
        self._index = 0

    def params(self) -> Mapping[str, Any]:
        return {}

    def reset(self, agent: AgentView) -> None:
        self._buffer, self._index = [], 0

    def choose_action(self, agent: AgentView) -> int:
        if self._index == len(self._buffer):
            picks = agent.rng.integers(0, len(agent.actions), size=self._block)
            self._buffer = [agent.actions[i] for i in picks.tolist()]
            self._index = 0
        action = self._buffer[self._index]
        self._index += 1
        return action
