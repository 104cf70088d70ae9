"""A facade with the thesis-era ``msrgym.robot_arm`` interface, on top of this project.

A script written for the 2023 platform runs after one changed import line::

    from msrgym import robot_arm            # before
    from rsstp_sim.compat import robot_arm  # after

Method names, argument orders and meanings are the original's (including the
misspelt ``delete_conection_between_nodes``); the behaviour is this project's,
with the original platform's defects fixed (``docs/world.md``). The
differences a script can notice:

- **Nodes are matrix indices**, as in the original: node ``i`` is row ``i`` of
  :meth:`robot_arm.get_transition_matrix`. Internally states have stable ids;
  the facade maps indices to ids at every call, so after ``merge_nodes(n, m)``
  the rows above ``m`` move up by one exactly as the original's matrix did.
- **Invalid arguments raise** :class:`~rsstp_sim.errors.ModelError` (nodes,
  actions of the model), :class:`~rsstp_sim.errors.MemoryRangeError` (memory
  indices), :class:`~rsstp_sim.errors.ActionError` (an action the arm does not
  have) or :class:`~rsstp_sim.errors.ScenarioError` (constructor arguments).
  The original returned ``-1`` and printed a message, or silently did nothing.
- **The world always executes the action**; the internal state follows a
  transition of the model (a seeded choice among several; it stays when there
  is none). The original refused to move the arm when the model had no
  transition for the action, without a word (defect 8).
- **Goal tolerance.** The original compared coordinates rounded to 2 decimals
  with ``==``, rounding joint by joint (defect 4), so goals were written as
  rounded points like ``(-0.35, 1.97)``. Here a tip senses its goal point when
  it is within :data:`THESIS_GOAL_TOLERANCE` (``0.005 * sqrt(2)``, about
  0.0071 length units) of it: the circle around the 2-decimal rounding square
  of the goal, so every tip whose rounded coordinates equal the goal counts
  (the one-joint case exactly), and nothing a whole step away does for the
  arms of the thesis. The scenario stores it relative to the total arm length.
- **Collisions are checked along the whole swept motion** against the whole
  obstacle disk (the original tested the end pose against the circle's
  boundary only: defects 1 and 2).
- **Positions are not rounded**: :meth:`robot_arm.get_arm_position` returns
  float coordinates (the original returned them rounded to 2 decimals).
- **Nothing is printed** unless ``visualise_ext`` / ``visualise_int`` is set;
  then the position and matrix lines are printed to stdout (no matplotlib
  window, no ``tm_graph.png``: :meth:`robot_arm.draw_graph_from_tm` writes a
  picture only when given a path).
- **Memory indices are the thesis's**: index ``i`` is the entry written by the
  ``(i + 1)``-th :meth:`robot_arm.update_position` (the original memory had no
  entry for the start). :attr:`robot_arm.memory` is this project's
  :class:`~rsstp_sim.memory.Memory`, whose entry 0 is the start: thesis index
  ``i`` is its entry ``i + 1``. The memory records internal states by their
  stable ids (the matrix indices until a merge renumbers rows), so entries
  written before a merge keep telling the old states apart. Each arm has its
  own memory (defect 6).
- :meth:`robot_arm.is_deterministic` returns ``True`` when the model is
  deterministic (what the original did; its docstring said the opposite), and
  a repeated label inside one matrix cell is not nondeterminism (defect 10).
- :meth:`robot_arm.compare_memory` follows the thesis (section 4.2): the
  action that led to the two starting entries is not compared.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any, SupportsIndex

import numpy as np
from numpy.typing import NDArray

from rsstp_sim import graph
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.world import Blocker, World
from rsstp_sim.errors import MemoryRangeError, ModelError, RsstpError, ScenarioError
from rsstp_sim.memory import CompareKind, Memory
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.transition_system import TransitionSystem, as_int

__all__ = ["THESIS_GOAL_TOLERANCE", "robot_arm"]

THESIS_GOAL_TOLERANCE = 0.005 * math.sqrt(2.0)
"""Distance (length units) within which a tip senses its goal point: see the module docstring."""

_ORIGIN = "robot_arm"
_COMPARE_CODES = {
    CompareKind.UNKNOWN: 0,
    CompareKind.DIFFERENT_STATE: 1,
    CompareKind.DIFFERENT_SENSATION: 2,
    CompareKind.IDENTICAL: 3,
}

Matrix = list[list[list[int]]]


class robot_arm:  # noqa: N801 - the thesis-era name, kept on purpose
    """The thesis-era arm: the world, an internal model and a memory in one object.

    Arguments, in the original order:

    - ``joints_n``: number of joints (links), ``>= 1``.
    - ``initial_position``: start angles, integer degrees, one per joint
      (relative to the previous link; the first to the +x axis); a bare int for
      one joint. The caller's list is never modified (defect 5).
    - ``arm_lengths``: link lengths ``> 0``, one per joint; a bare number for one joint.
    - ``obstacles``: the original flat form ``[[x, y], r, [x, y], r, ...]``.
    - ``arm_steps``: the step of every move, integer degrees in 1..359.
    - ``goal_position``: the sensory feedback points, one ``(x, y)`` per joint tip;
      a single ``(x, y)`` for one joint. Sensed within ``goal_tolerance``.
    - ``actions``: the action ids the arm uses (``2k``: joint ``k`` turns by
      ``+arm_steps`` degrees, counter-clockwise; ``2k + 1``: by ``-arm_steps``).
    - ``visualise_ext`` / ``visualise_int``: print the position / the matrix after
      every move.

    Keyword-only additions: ``seed`` for the choice among several successors
    (default 0, so runs repeat), and ``goal_tolerance`` (default
    :data:`THESIS_GOAL_TOLERANCE`).

    The internal model starts as the original's: one state with a self-loop
    for every action. :attr:`scenario`, :attr:`world`, :attr:`model` and
    :attr:`memory` give the project's objects for anything beyond the original.
    Bad arguments raise :class:`~rsstp_sim.errors.ScenarioError`; past the
    checks of the thesis forms, its key paths are the scenario file's
    (``arm.initial_deg`` for ``initial_position``, ``arm.lengths``,
    ``obstacles[j]``, ``arm.step_deg``, ``feedback.points``, ``arm.actions``).

    >>> arm = robot_arm(1, [95], [2], [[1, 2], 1, [-1, -2], 1], 1, [(-0.35, 1.97)], [0, 1])
    >>> for _ in range(5):
    ...     arm.update_position(0)  # joint 0 turns by +1 degree
    >>> arm.get_arm_position()[0], arm.is_desired_position_reached()
    ([100], True)
    >>> arm.split_node(0)
    [[[0, 1], [0, 1]], [[0, 1], [0, 1]]]
    >>> arm.delete_conection_between_nodes(0, 1, 0)
    [[[0, 1], [1]], [[0, 1], [0, 1]]]
    >>> arm.get_memory_size(), arm.compare_memory(4, 3)  # 100 (sensed) vs 99 degrees
    (5, 2)
    """

    scenario: Scenario
    world: World
    model: TransitionSystem
    memory: Memory
    rng: np.random.Generator
    visualise_ext: bool
    visualise_int: bool
    last_blocker: Blocker | None
    _ext: _ExternalView

    def __init__(
        self,
        joints_n: int,
        initial_position: int | Sequence[int],
        arm_lengths: float | Sequence[float],
        obstacles: Sequence[object] | NDArray[Any] | None,
        arm_steps: int,
        goal_position: Sequence[object],
        actions: Iterable[SupportsIndex],
        visualise_ext: bool = False,
        visualise_int: bool = False,
        *,
        seed: int = 0,
        goal_tolerance: float = THESIS_GOAL_TOLERANCE,
    ) -> None:
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or seed < 0:
            raise ModelError(f"robot_arm: seed must be an integer >= 0, got {seed!r}")
        self.scenario = parse_scenario(
            _scenario_toml(
                joints_n,
                initial_position,
                arm_lengths,
                obstacles,
                arm_steps,
                goal_position,
                actions,
                goal_tolerance,
            ),
            origin=_ORIGIN,
        )
        self.visualise_ext = bool(visualise_ext)
        self.visualise_int = bool(visualise_int)
        self.world = World(self.scenario)
        self.model = TransitionSystem.universal(self.scenario.actions)
        self.memory = Memory()
        pose = self.world.current
        self.memory.reset(self.model.current, pose.sensation, pose.feedback)
        self.rng = np.random.default_rng(int(seed))
        self.last_blocker = None
        self._ext = _ExternalView(self)

    def __repr__(self) -> str:
        return (
            f"robot_arm(angles_deg={list(self.world.angles_deg)}, "
            f"internal_state={self.get_current_internal_state()}, states={len(self.model)}, "
            f"memory={self.get_memory_size()})"
        )

    # -- moving -----------------------------------------------------------------------------

    def update_position(self, action: SupportsIndex) -> None:
        """Execute ``action`` (the world may block it) and follow it in the internal model.

        The internal state moves to the successor of (current state, action);
        with several successors the arm's seeded generator picks one, with none
        the state stays. The move is appended to the memory.
        """
        action_id = _action(action, "update_position")
        blocker = self.world.move(action_id)
        self.last_blocker = blocker
        model = self.model
        successors = model.successors(model.current, action_id)
        if len(successors) == 1:
            model.current = successors[0]
        elif successors:
            model.current = successors[int(self.rng.integers(len(successors)))]
        pose = self.world.current
        self.memory.append(action_id, model.current, pose.sensation, pose.feedback)
        if self.visualise_ext or self.visualise_int:
            self._print_update(blocker)

    def _print_update(self, blocker: Blocker | None) -> None:
        print("_" * 78)
        if self.visualise_int:
            print("Transition matrix: ")
            print(self.get_transition_matrix())
            deterministic = self.model.is_deterministic()
            print(f"Transition matrix is {'' if deterministic else 'not '}deterministic")
        if self.visualise_ext:
            if blocker is not None:
                print(f"Move blocked: {blocker.describe()}")
            angles, tips = self.get_arm_position()
            shown = [(round(x, 2), round(y, 2)) for x, y in tips]
            print(f"Updated position: {(angles, shown)}")
            print(f"Internal state after update: {self.get_current_internal_state()}")
            print()
            if self.is_desired_position_reached():
                print("Home position reached")

    # -- the world --------------------------------------------------------------------------

    def get_arm_position(self) -> tuple[list[int], list[tuple[float, float]]]:
        """(joint angles in degrees, ``(x, y)`` of every link tip), coordinates not rounded."""
        tips = self.world.joint_positions[1:]
        return list(self.world.angles_deg), [(float(x), float(y)) for x, y in tips.tolist()]

    def is_desired_position_reached(self) -> bool:
        """Whether every tip is at its goal point (the boolean sensation)."""
        return self.world.sensation

    def get_sensory_data_float(self) -> float:
        """Closeness to the goal points in [0, 1], 1 at the goal (thesis 4.6)."""
        return self.world.feedback

    def distance_from_obstacle(self) -> list[list[float]]:
        """``[joint][obstacle]``: distance from each tip to each obstacle's surface (thesis 4.5)."""
        distances: list[list[float]] = self.world.distances.tolist()
        return distances

    # -- the internal model -----------------------------------------------------------------

    def get_current_internal_state(self) -> int:
        """The current internal state, as a matrix index."""
        return self.model.index_of(self.model.current)

    def get_transition_matrix(self) -> Matrix:
        """The thesis matrix: cell ``[i][j]`` is the sorted list of actions from node i to j."""
        return self.model.to_matrix()

    def split_node(self, n: SupportsIndex) -> Matrix:
        """Duplicate node ``n`` with all its transitions (the new node is the last row)."""
        self.model.split(self._state(n, "split_node"))
        return self.get_transition_matrix()

    def merge_nodes(self, n: SupportsIndex, m: SupportsIndex) -> Matrix:
        """Merge node ``m`` into node ``n`` (union of their transitions); row ``m`` disappears."""
        s = self._state(n, "merge_nodes")
        t = self._state(m, "merge_nodes")
        if s == t:
            raise ModelError(f"merge_nodes: cannot merge node {n} with itself")
        self.model.merge(s, t)
        return self.get_transition_matrix()

    def add_connection_between_nodes(
        self, n: SupportsIndex, m: SupportsIndex, k: SupportsIndex
    ) -> Matrix:
        """Add the transition ``n -k-> m`` (no change if it exists)."""
        return self._edit(self.model.add, "add_connection_between_nodes", n, m, k)

    def delete_connection_between_nodes(
        self, n: SupportsIndex, m: SupportsIndex, k: SupportsIndex
    ) -> Matrix:
        """Delete the transition ``n -k-> m`` (no change if it does not exist)."""
        return self._edit(self.model.delete, "delete_connection_between_nodes", n, m, k)

    def _edit(
        self,
        operation: Callable[[int, int, int], bool],
        method: str,
        n: SupportsIndex,
        m: SupportsIndex,
        k: SupportsIndex,
    ) -> Matrix:
        """Apply ``operation`` (add or delete) to ``n -k-> m``, named ``method`` in errors."""
        s, t = self._state(n, method), self._state(m, method)
        operation(s, t, self._model_action(k, method))
        return self.get_transition_matrix()

    def delete_conection_between_nodes(
        self, n: SupportsIndex, m: SupportsIndex, k: SupportsIndex
    ) -> Matrix:
        """The original's spelling of :meth:`delete_connection_between_nodes`."""
        return self.delete_connection_between_nodes(n, m, k)

    def is_deterministic(self) -> bool:
        """``True`` when every (node, action) has at most one successor."""
        deterministic = self.model.is_deterministic()
        if self.visualise_int:
            print(f"Transition matrix is {'' if deterministic else 'not '}deterministic")
        return deterministic

    def draw_graph_from_tm(
        self, tm: Sequence[Sequence[Sequence[int]]] | None = None, path: str | Path | None = None
    ) -> str:
        """The DOT source of the graph of ``tm`` (default: the current matrix).

        Nodes are named by matrix index; the current internal state is filled
        when ``tm`` is the arm's own matrix. With ``path`` the picture is also
        written there (``.svg``, ``.png``, ``.pdf`` drawn by Graphviz, ``.dot``/``.gv`` the
        source); without it nothing is written.
        """
        matrix = self.get_transition_matrix() if tm is None else tm
        view = TransitionSystem.from_matrix(matrix, actions=self.scenario.actions)
        if tm is None:
            view.current = self.get_current_internal_state()
        if path is not None:
            graph.render(view, path)
        return graph.to_dot(view)

    # -- memory -----------------------------------------------------------------------------

    def get_memory_size(self) -> int:
        """The number of moves remembered (the original's memory length)."""
        return len(self.memory) - 1

    def compare_memory(self, n: SupportsIndex, m: SupportsIndex) -> int:
        """Compare the sub-memories from thesis indices ``n`` and ``m`` (thesis 4.2).

        Returns 0 unknown (actions differ), 1 different (internal state),
        2 different (sensation), 3 unknown (identical). ``n == m`` or an index
        outside ``0 .. get_memory_size() - 1`` raises
        :class:`~rsstp_sim.errors.MemoryRangeError` (the original returned -1).
        """
        size = self.get_memory_size()
        first, second = _index(n, "compare_memory"), _index(m, "compare_memory")
        if not (0 <= first < size and 0 <= second < size):
            valid = "none (no move yet)" if size == 0 else f"0 .. {size - 1}"
            raise MemoryRangeError(
                f"compare_memory({first}, {second}): indices must be in {valid} "
                f"(get_memory_size() is {size})"
            )
        if first == second:
            raise MemoryRangeError(f"compare_memory({first}, {second}): the indices must differ")
        return _COMPARE_CODES[self.memory.compare(first + 1, second + 1).kind]

    # -- helpers ----------------------------------------------------------------------------

    def _state(self, node: object, operation: str) -> int:
        index = _node(node, operation)
        size = len(self.model)
        if not 0 <= index < size:
            raise ModelError(
                f"{operation}: node {index} is not a matrix index 0..{size - 1} "
                f"(the matrix has {size} rows)"
            )
        return self.model.state_at(index)

    def _model_action(self, k: object, operation: str) -> int:
        action = _action(k, operation, error=ModelError)
        if action not in self.scenario.actions:
            raise ModelError(
                f"{operation}: action {action} is not one of the arm's actions "
                f"{list(self.scenario.actions)}"
            )
        return action


class _ExternalView:
    """The original's ``arm._ext`` for the few scripts that reached into it."""

    def __init__(self, arm: robot_arm) -> None:
        self._arm = arm

    def get_sensory_data(self) -> bool:
        return self._arm.is_desired_position_reached()

    def get_sensory_data_float(self) -> float:
        return self._arm.get_sensory_data_float()

    def get_position(self) -> tuple[list[int], list[tuple[float, float]]]:
        return self._arm.get_arm_position()

    def distance_from_obstacle(self) -> list[list[float]]:
        return self._arm.distance_from_obstacle()


# -- arguments ---------------------------------------------------------------------------------


def _node(value: object, operation: str) -> int:
    return as_int(value, f"{operation}: a node (matrix index)", ModelError)


def _index(value: object, operation: str) -> int:
    return as_int(value, f"{operation}: a memory index", MemoryRangeError)


def _action(value: object, operation: str, *, error: type[RsstpError] = ModelError) -> int:
    return as_int(value, f"{operation}: an action", error)


def _is_number(value: object) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def _number(value: object, where: str) -> str:
    """``value`` as a TOML number literal (ints stay ints so the validator can insist on them)."""
    if not _is_number(value):
        raise ScenarioError(f"{_ORIGIN}: {where}: expected a number, found {value!r}")
    if isinstance(value, numbers.Integral):
        return str(int(value))
    number = float(value)  # type: ignore[arg-type]
    if math.isnan(number):
        return "nan"
    if math.isinf(number):
        return "inf" if number > 0 else "-inf"
    return repr(number)


def _per_joint(value: object, joints_n: int, where: str, what: str) -> list[object]:
    """A per-joint list; a bare number stands for a one-joint list."""
    if _is_number(value):
        items: list[object] = [value]
    elif isinstance(value, Sequence | np.ndarray) and not isinstance(value, str | bytes):
        items = list(value)
    else:
        raise ScenarioError(f"{_ORIGIN}: {where}: expected {what}, one per joint, found {value!r}")
    if len(items) != joints_n:
        raise ScenarioError(
            f"{_ORIGIN}: {where}: expected {joints_n} {what} (joints_n), found {len(items)}"
        )
    return items


def _point(value: object, where: str) -> str:
    if (
        not isinstance(value, Sequence | np.ndarray)
        or isinstance(value, str | bytes)
        or len(value) != 2
    ):
        raise ScenarioError(f"{_ORIGIN}: {where}: expected a point [x, y], found {value!r}")
    return f"[{_number(value[0], f'{where}[0]')}, {_number(value[1], f'{where}[1]')}]"


def _obstacles_toml(obstacles: object) -> list[str]:
    """``[[obstacles]]`` tables from the original flat form ``[[x, y], r, ...]``."""
    if obstacles is None:
        return []
    if not isinstance(obstacles, Sequence | np.ndarray) or isinstance(obstacles, str | bytes):
        raise ScenarioError(
            f"{_ORIGIN}: obstacles: expected the flat form [[x, y], r, [x, y], r, ...], "
            f"found {obstacles!r}"
        )
    items = list(obstacles)
    if len(items) % 2:
        raise ScenarioError(
            f"{_ORIGIN}: obstacles: expected the flat form [[x, y], r, [x, y], r, ...] "
            f"(an even number of items), found {len(items)} items"
        )
    lines: list[str] = []
    for i in range(0, len(items), 2):
        center = _point(items[i], f"obstacles[{i}] (centre of obstacle {i // 2})")
        radius = _number(items[i + 1], f"obstacles[{i + 1}] (radius of obstacle {i // 2})")
        lines += ["", "[[obstacles]]", f"center = {center}", f"radius = {radius}"]
    return lines


def _goal_points(goal_position: object, joints_n: int) -> list[object]:
    """One point per joint; a lone ``(x, y)`` is the one joint's point."""
    if (
        isinstance(goal_position, Sequence | np.ndarray)
        and not isinstance(goal_position, str | bytes)
        and len(goal_position) == 2
        and all(_is_number(v) for v in goal_position)
    ):
        goal_position = [goal_position]
    return _per_joint(goal_position, joints_n, "goal_position", "points (x, y)")


def _scenario_toml(
    joints_n: object,
    initial_position: object,
    arm_lengths: object,
    obstacles: object,
    arm_steps: object,
    goal_position: object,
    actions: object,
    goal_tolerance: object,
) -> str:
    """The scenario file the constructor's arguments describe."""
    if isinstance(joints_n, bool) or not isinstance(joints_n, numbers.Integral) or joints_n < 1:
        raise ScenarioError(f"{_ORIGIN}: joints_n: expected an integer >= 1, found {joints_n!r}")
    n = int(joints_n)
    angles = _per_joint(initial_position, n, "initial_position", "angles in degrees")
    lengths = _per_joint(arm_lengths, n, "arm_lengths", "lengths")
    points = _goal_points(goal_position, n)
    if isinstance(actions, str | bytes) or not isinstance(actions, Iterable):
        raise ScenarioError(f"{_ORIGIN}: actions: expected a list of action ids, found {actions!r}")
    action_ids = list(actions)
    if not _is_number(goal_tolerance) or not float(goal_tolerance) >= 0:  # type: ignore[arg-type]
        raise ScenarioError(
            f"{_ORIGIN}: goal_tolerance: expected a number >= 0, found {goal_tolerance!r}"
        )

    length_literals = [_number(v, f"arm_lengths[{i}]") for i, v in enumerate(lengths)]
    total_length = math.fsum(float(v) for v in length_literals)
    relative = float(goal_tolerance) / total_length if total_length > 0 else 0.0  # type: ignore[arg-type]

    def array(values: list[str]) -> str:
        return "[" + ", ".join(values) + "]"

    lines = [
        'name = "thesis-compat"',
        'description = "Built by rsstp_sim.compat.robot_arm from thesis-era arguments"',
        "",
        "[arm]",
        f"lengths = {array(length_literals)}",
        "initial_deg = "
        + array([_number(v, f"initial_position[{i}]") for i, v in enumerate(angles)]),
        f"step_deg = {_number(arm_steps, 'arm_steps')}",
        "actions = " + array([_number(v, f"actions[{i}]") for i, v in enumerate(action_ids)]),
        *_obstacles_toml(obstacles),
        "",
        "[feedback]",
        "points = " + array([_point(p, f"goal_position[{i}]") for i, p in enumerate(points)]),
        'mode = "bool"',
        f"tolerance = {relative!r}",
        "",
        "[motion]",
        'collision = "swept"',
        "",
    ]
    return "\n".join(lines)
