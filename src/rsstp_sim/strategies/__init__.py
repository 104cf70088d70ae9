"""Strategies: the protocol, the built-in strategies by name, and the user's own.

``make_strategy(name)`` takes a built-in name (``random``, ``learner``, ...), the name of an
entry point in the group ``rsstp.strategies`` (a package declares one in its
``pyproject.toml``: ``[project.entry-points."rsstp.strategies"] mine =
"my_package.module:MyStrategy"``), or an import path ``package.module:Class`` (a module on
``sys.path``, e.g. beside the scenario file, with ``PYTHONPATH``). What it finds must be a
class whose instances have the :class:`Strategy` methods.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib import metadata
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
    "ENTRY_POINT_GROUP",
    "StrategyOrigin",
    "builtin_strategies",
    "make_strategy",
    "plugin_strategies",
    "strategy_origin",
]

_BUILTIN: dict[str, Callable[..., Strategy]] = {
    "learner": LearnerStrategy,
    "random": RandomStrategy,
    "roulette": RouletteStrategy,
    "script": ScriptStrategy,
    "splitter": SplitterStrategy,
}


ENTRY_POINT_GROUP = "rsstp.strategies"
"""The entry-point group in which a distribution declares its strategies."""


def builtin_strategies() -> tuple[str, ...]:
    return tuple(sorted(_BUILTIN))


def plugin_strategies() -> dict[str, str]:
    """The strategies declared by installed distributions: name -> ``module:Class (dist
    version)``."""
    found: dict[str, str] = {}
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        dist = entry.dist
        origin = f" ({dist.name} {dist.version})" if dist is not None else ""
        found.setdefault(entry.name, f"{entry.value}{origin}")
    return dict(sorted(found.items()))


def make_strategy(name: str, params: Mapping[str, Any] | None = None) -> Strategy:
    """Build a strategy by name (built-in, entry point, or ``package.module:Class``) with
    keyword parameters; :class:`StrategyError` names what could not be found or built."""
    factory = _BUILTIN.get(name) or _plugin(name)
    _check_parameter_names(name, factory, params or {})
    try:
        strategy = factory(**dict(params or {}))
    except TypeError as exc:
        raise StrategyError(
            f"strategy {name!r}: invalid parameters {dict(params or {})}: {exc}"
        ) from None
    if not isinstance(strategy, Strategy):
        missing = [m for m in _METHODS if not callable(getattr(strategy, m, None))]
        raise StrategyError(
            f"strategy {name!r}: {type(strategy).__name__} is not a strategy (missing "
            f"{', '.join(missing) or 'name'}; subclass rsstp_sim.StrategyBase)"
        )
    return strategy


def _check_parameter_names(name: str, factory: Any, params: Mapping[str, Any]) -> None:
    """One line naming a parameter the strategy does not take, and the ones it does."""
    import inspect

    try:
        signature = inspect.signature(factory)
    except (TypeError, ValueError):  # no signature to read: the call says what is wrong
        return
    kinds = {p.kind for p in signature.parameters.values()}
    if inspect.Parameter.VAR_KEYWORD in kinds:
        return
    takes = [
        p.name
        for p in signature.parameters.values()
        if p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    ]
    for key in params:
        if key not in takes:
            accepted = ", ".join(f"{t}=VALUE" for t in takes) or "no parameters"
            raise StrategyError(
                f"strategy {name!r}: unknown parameter {key!r} (it takes {accepted})"
            )


@dataclass(frozen=True, slots=True)
class StrategyOrigin:
    """Where a strategy's class comes from: ``import_path`` (``package.module:Class``), and
    the installed distribution that provides its top-level package with that
    distribution's version (None for a module found on ``sys.path`` that no distribution
    provides)."""

    import_path: str
    distribution: str | None
    version: str | None


_DECLARED_BY: dict[type, tuple[str, str]] = {}
"""Classes loaded through an entry point -> the distribution that declares it, and its
version."""


def strategy_origin(strategy: Strategy) -> StrategyOrigin:
    """The :class:`StrategyOrigin` of ``strategy`` (what a recording states of it): for a
    class loaded through an entry point, the distribution that declares it; else the one that
    provides its top-level package."""
    cls = type(strategy)
    import_path = f"{cls.__module__}:{cls.__qualname__}"
    declared = _DECLARED_BY.get(cls)
    if declared is not None:
        return StrategyOrigin(import_path, *declared)
    top = cls.__module__.partition(".")[0]
    if top == "rsstp_sim":  # ours: no scan of the installed distributions
        from rsstp_sim import __version__

        return StrategyOrigin(import_path, "rsstp", __version__)
    names = sorted(set(metadata.packages_distributions().get(top, ())))
    if not names:
        return StrategyOrigin(import_path, None, None)
    try:
        version = metadata.version(names[0])
    except metadata.PackageNotFoundError:
        version = None
    return StrategyOrigin(import_path, names[0], version)


_METHODS = ("params", "initial_model", "reset", "choose_action", "refine")


def _plugin(name: str) -> Callable[..., Strategy]:
    """The class behind an entry point or an import path."""
    if ":" in name:
        module_name, _, attribute = name.partition(":")
        try:
            module = importlib.import_module(module_name)
        except Exception as exc:  # the user's module: any error while importing it
            raise StrategyError(
                f"strategy {name!r}: cannot import {module_name!r}: {type(exc).__name__}: {exc}"
            ) from None
        found = getattr(module, attribute, None)
        if found is None:
            raise StrategyError(f"strategy {name!r}: {module_name!r} has no {attribute!r}")
    else:
        entries = [e for e in metadata.entry_points(group=ENTRY_POINT_GROUP) if e.name == name]
        if not entries:
            plugins = ", ".join(plugin_strategies()) or "none installed"
            raise StrategyError(
                f"unknown strategy {name!r} (built-in: {', '.join(builtin_strategies())}; "
                f"plugins: {plugins}; or give package.module:Class)"
            )
        try:
            found = entries[0].load()
        except Exception as exc:  # the plugin's module: any error while importing it
            raise StrategyError(
                f"strategy {name!r}: cannot load {entries[0].value!r}: {type(exc).__name__}: {exc}"
            ) from None
        dist = entries[0].dist
        if dist is not None and isinstance(found, type):
            _DECLARED_BY[found] = (dist.name, dist.version)
    if not callable(found):
        raise StrategyError(f"strategy {name!r}: {found!r} is not a class")
    factory: Callable[..., Strategy] = found
    return factory
