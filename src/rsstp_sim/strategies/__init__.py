"""Strategies: the protocol, and the built-in strategies by name."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from rsstp_sim.errors import StrategyError
from rsstp_sim.strategies._base import AgentView, Strategy, StrategyBase
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.strategies.random_walk import RandomStrategy
from rsstp_sim.strategies.roulette import RouletteStrategy
from rsstp_sim.strategies.script import ScriptStrategy
from rsstp_sim.strategies.splitter import SplitterStrategy

__all__ = [
    "AgentView",
    "LearnerStrategy",
    "RandomStrategy",
    "RouletteStrategy",
    "ScriptStrategy",
    "SplitterStrategy",
    "Strategy",
    "StrategyBase",
    "builtin_strategies",
    "make_strategy",
]

_BUILTIN: dict[str, Callable[..., Strategy]] = {
    "learner": LearnerStrategy,
    "random": RandomStrategy,
    "roulette": RouletteStrategy,
    "script": ScriptStrategy,
    "splitter": SplitterStrategy,
}


def builtin_strategies() -> tuple[str, ...]:
    return tuple(sorted(_BUILTIN))


def make_strategy(name: str, params: Mapping[str, Any] | None = None) -> Strategy:
    """Build a built-in strategy by name with keyword parameters."""
    factory = _BUILTIN.get(name)
    if factory is None:
        raise StrategyError(
            f"unknown strategy {name!r} (built-in: {', '.join(builtin_strategies())})"
        )
    try:
        return factory(**dict(params or {}))
    except TypeError as exc:
        raise StrategyError(
            f"strategy {name!r}: invalid parameters {dict(params or {})}: {exc}"
        ) from None
