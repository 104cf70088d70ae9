"""The world interface: what everything downstream of the agent knows of a body.

A *body* (the arm, the rover) is a finite deterministic world: poses numbered by integer
codes, actions that move between them or are blocked, and in each pose a boolean sensation
and a float feedback in ``[0, 1]``. The runner drives a :class:`World` through
:meth:`World.reset` and :meth:`World.move` and reads the current :class:`Pose`'s sensation and
feedback; the ground truth reads the body's :class:`PoseMachine`. A body is registered in
:mod:`rsstp_sim.bodies` as a :class:`Body`: how its scenario table is parsed, how its world is
made, and how its reachable poses are enumerated (from a scenario before any world, or by
the world built).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from rsstp_sim.arrays import BoolArray, IntArray

__all__ = [
    "Blocker",
    "Body",
    "Pose",
    "PoseMachine",
    "World",
    "WorldScenario",
]


class WorldScenario(Protocol):
    """What every body's scenario says: its name, its actions, how feedback is read."""

    @property
    def name(self) -> str: ...
    @property
    def description(self) -> str: ...
    @property
    def actions(self) -> tuple[int, ...]: ...
    @property
    def feedback_mode(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def origin(self) -> str: ...
    @property
    def sha256(self) -> str: ...
    @property
    def body(self) -> str: ...


class Pose(Protocol):
    """One pose of a body: its code, and what the agent senses there."""

    @property
    def code(self) -> int: ...
    @property
    def sensation(self) -> bool: ...
    @property
    def feedback(self) -> float: ...
    def truth_json(self) -> tuple[bytes, bytes]:
        """The pose's members of its step message's ``truth`` (JSON, keys in schema order),
        before its ``blocked`` field and after it: what a step's message repeats at every
        visit (the recorder's byte templates)."""

    def truth_record(self, blocker: Any) -> Any:
        """The truth record (:mod:`rsstp_format.records`) of a step ending here after a move
        that ``blocker`` blocked (None: it moved)."""


class Blocker(Protocol):
    """Why a move was blocked: a kind and the indices of what blocked it."""

    @property
    def kind(self) -> str: ...
    @property
    def indices(self) -> tuple[int, ...]: ...
    def describe(self) -> str: ...


class World(Protocol):
    """A body in its world, one pose at a time."""

    @property
    def scenario(self) -> Any: ...
    def reset(self) -> Any: ...
    def move(self, action: int) -> Any:
        """Execute an action: None when the body moved, else its :class:`Blocker`."""

    @property
    def current(self) -> Any: ...
    @property
    def last_blocker(self) -> Any:
        """What blocked the last move (None when it moved, and after a reset)."""

    @property
    def sensation(self) -> bool: ...
    @property
    def feedback(self) -> float: ...
    def follow(self, actions: IntArray, recorded: Any = None) -> tuple[IntArray, IntArray]:
        """From the start pose, walking ``actions[1:]`` (``actions[0]``, step 0's, is the
        reset): the row of every step's pose in the world's own numbering (step 0's the
        start) and each move's blocker code (0: it moved, and at step 0). ``recorded``, the
        recording's steps table, is a hint a world may use to go faster. Raises
        :class:`~rsstp_sim.errors.ActionError` at an action the scenario does not have."""

    def senses(self) -> tuple[BoolArray, Any]:
        """The sensation and the float feedback of every row :meth:`follow` gives."""

    def truth_at(self, row: int, blocker_code: int) -> Any:
        """The truth record of a step ending at ``row`` after a move blocked by
        ``blocker_code``: what the recorder writes there."""

    def check_size(self, *, max_poses: int, max_checks: int | None) -> None:
        """:meth:`Body.check_size` of the world's scenario, read from the world: refuse
        before enumerating it."""

    def machine(self) -> PoseMachine:
        """:meth:`Body.machine` of the world's scenario, from the world's own table (completed
        in place), not another one: what the ground truth of a world already built reads."""


@dataclass(frozen=True, eq=False)
class PoseMachine:
    """A body's reachable poses as a machine, sorted by code: ``next_pose[p, k]`` is the
    index of the pose action ``actions[k]`` leads to from pose ``p`` (``p`` itself when
    blocked). ``values[p]`` says the pose in the columns ``value_names`` of a steps table;
    value ``i`` is digit ``values[p, i] // units[i]`` of the code in base ``radices[i]``, taken
    modulo the radix when ``wrap`` (angles)."""

    codes: IntArray
    values: IntArray
    next_pose: IntArray
    sensation: BoolArray
    start_index: int
    value_names: tuple[str, ...]
    radices: tuple[int, ...]
    units: tuple[int, ...]
    wrap: bool


class Body(Protocol):
    """A kind of body, as the registry (:mod:`rsstp_sim.bodies`) holds it."""

    name: str
    """The scenario table that picks it (``[arm]``, ``[rover]``)."""

    def parse(self, data: Mapping[str, object], text: str, origin: str) -> Any:
        """The validated scenario of a parsed TOML document that has this body's table: every
        key checked, not the start pose's geometry (:meth:`check_start`)."""

    def check_start(self, scenario: Any) -> None:
        """Raise :class:`~rsstp_sim.errors.ScenarioError` (one line naming the file and the
        key) when the body cannot stand at the scenario's start pose: what building its world
        finds, without building it."""

    def world(self, scenario: Any) -> Any:
        """A :class:`World` at the scenario's start pose."""

    def scenario_record(self, scenario: Any, common: dict[str, Any]) -> Any:
        """The run's scenario message (:mod:`rsstp_format.records`), from the body's scenario
        and the fields every body's message has (``common``: name, actions, obstacles,
        seed, strategy, ...)."""

    def describe(self, scenario: Any) -> list[str]:
        """The body in its world, a few indented lines (``rsstp-replay info``)."""

    def pose_info(self, pose: Any) -> dict[str, Any]:
        """A pose's ground truth for a Gymnasium ``info`` (fresh arrays, plain values)."""

    def picture(self, scenario: Any) -> Any:
        """What draws the body's frames: ``draw(world, *, blocked)`` gives a
        ``(400, 400, 3)`` uint8 picture (:mod:`rsstp_sim.canvas`)."""

    def warnings(self, scenario: Any) -> list[str]:
        """What a user should hear before a run of ``scenario`` (one line each): a feedback
        region nothing can sense, a world whose steps are slow."""

    def check_size(self, scenario: Any, *, max_poses: int, max_checks: int | None) -> None:
        """Refuse (:class:`~rsstp_sim.errors.TruthError`), before any work, a world whose
        enumeration would pass ``max_poses`` poses or ``max_checks`` collision checks (None:
        the body's own bound)."""

    def machine(self, scenario: Any) -> PoseMachine:
        """Every pose reachable from the start."""
