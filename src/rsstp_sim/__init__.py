"""RSSTP simulator: a 2D multi-joint arm, its internal model, memory and strategies.

The world (:class:`World`) is the arm among circular obstacles; the agent
keeps a :class:`Memory` and an internal :class:`TransitionSystem`; a
:class:`Strategy` decides actions and refinements; a :class:`Runner` couples
them one step at a time with one seeded generator per run.
"""

from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.world import Blocker, Pose, World
from rsstp_sim.env import ArmEnv, register_envs
from rsstp_sim.errors import (
    ActionError,
    GraphvizFailed,
    MemoryRangeError,
    ModelError,
    RecordingError,
    RsstpError,
    ScenarioError,
    StrategyError,
)
from rsstp_sim.memory import CompareKind, CompareResult, Memory, MemoryEntry
from rsstp_sim.runner import Event, Runner, RunSummary, StepOutcome
from rsstp_sim.scenario import Obstacle, builtin_scenarios, load_scenario, parse_scenario
from rsstp_sim.strategies import (
    AgentView,
    RandomStrategy,
    ScriptStrategy,
    Strategy,
    StrategyBase,
    builtin_strategies,
    make_strategy,
)
from rsstp_sim.transition_system import DeterminismReport, Operation, TransitionSystem

register_envs()


def _version() -> str:
    from importlib import metadata

    try:
        return metadata.version("rsstp")
    except metadata.PackageNotFoundError:  # run from a source tree that was never installed
        return "0+unknown"


__version__ = _version()
"""The installed distribution's version (pyproject.toml's), from the package metadata."""

__all__ = [
    "ActionError",
    "AgentView",
    "ArmEnv",
    "Blocker",
    "CompareKind",
    "CompareResult",
    "DeterminismReport",
    "Event",
    "GraphvizFailed",
    "Memory",
    "MemoryEntry",
    "MemoryRangeError",
    "ModelError",
    "Obstacle",
    "Operation",
    "Pose",
    "RandomStrategy",
    "RecordingError",
    "RsstpError",
    "RunSummary",
    "Runner",
    "Scenario",
    "ScenarioError",
    "ScriptStrategy",
    "StepOutcome",
    "Strategy",
    "StrategyBase",
    "StrategyError",
    "TransitionSystem",
    "World",
    "__version__",
    "builtin_scenarios",
    "builtin_strategies",
    "load_scenario",
    "make_strategy",
    "parse_scenario",
]
