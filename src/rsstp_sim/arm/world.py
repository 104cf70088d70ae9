"""The world (the thesis's *external system*): the arm among circular obstacles.

The world knows nothing about the agent, its model or any recording. Its answer
for a move depends only on the pose and the action, and the pose space is
finite (integer angles), so every answer comes from the scenario's
:class:`~rsstp_sim.arm.table.WorldTable`, computed once and read back with a
couple of array lookups per move: a small pose space's in vectorised blocks
around the arm, a large one's (many links, small steps) or a costly one's (many
obstacles) move by move, each new move checked alone.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rsstp_format.records import (
    BlockedByRecord,
    DistancesRecord,
    FeedbackRecord,
    PointRecord,
    ScenarioRecord,
    TruthRecord,
    encode_json,
)
from rsstp_sim.arm.geometry import Blocker
from rsstp_sim.arm.scenario import Scenario, parse_arm
from rsstp_sim.arm.table import (
    MAX_TABULATION_CHECKS,
    WorldTable,
    check_start,
    pose_space_size,
    tabulation_checks,
    unsensable,
)
from rsstp_sim.arrays import BoolArray, FloatArray, IntArray
from rsstp_sim.errors import ActionError, TruthError, UnknownPose
from rsstp_sim.interface import PoseMachine
from rsstp_sim.scenario import MANY_OBSTACLES

__all__ = ["ARM", "Blocker", "Pose", "World"]

_FIRST_BLOCK = 256
"""The poses a table grown in blocks grows by at its first miss (doubling at each)."""


@dataclass(frozen=True, slots=True, eq=False)
class Pose:
    """Everything the world knows about one pose (cached, read-only).

    - ``angles_deg``: relative joint angles, integer degrees in [0, 360).
    - ``joint_positions``: ``(n + 1, 2)`` float64, the base (origin) then every link tip.
    - ``sensation``: every tip within tolerance of its feedback point.
    - ``feedback``: float closeness to the feedback points, in [0, 1].
    - ``distances``: ``(n, m)`` distance from tip ``k`` to obstacle ``j``'s surface.

    The sensation and the feedback are read at every step; the rest is computed from the
    world table's row at first use (most poses of a long run are never asked for it), and
    kept, but for the distances of a table that keeps none (many obstacles), computed at
    every read.
    """

    code: int
    sensation: bool
    feedback: float
    _table: WorldTable = field(repr=False)
    _row: int = field(repr=False)
    _angles: tuple[int, ...] | None = field(default=None, init=False, repr=False)
    _positions: FloatArray | None = field(default=None, init=False, repr=False)
    _distances: FloatArray | None = field(default=None, init=False, repr=False)

    @property
    def angles_deg(self) -> tuple[int, ...]:
        if self._angles is None:
            object.__setattr__(self, "_angles", tuple(self._table.angles_of(self.code)))
        assert self._angles is not None
        return self._angles

    @property
    def joint_positions(self) -> FloatArray:
        if self._positions is None:
            object.__setattr__(self, "_positions", self._table.positions_of(self._row))
        assert self._positions is not None
        return self._positions

    @property
    def distances(self) -> FloatArray:
        if self._distances is not None:
            return self._distances
        distances = self._table.distances_of(self._row)
        if self._table.keeps_distances:  # else too many to keep for every pose visited
            object.__setattr__(self, "_distances", distances)
        return distances

    def truth_values(self) -> tuple[list[int], list[float], list[float]]:
        """:attr:`angles_deg`, :attr:`joint_positions` and :attr:`distances` as flat lists of
        plain numbers (positions ``x0, y0, x1, y1, ...``; distances tip by tip): the same
        values, without numpy arrays."""
        return self._table.truth_values(self._row)

    def truth_json(self) -> tuple[bytes, bytes]:
        """The pose's members of its ``rsstp.Step`` truth (JSON, keys in schema order) before
        its ``blocked`` field (angles, joint positions) and after it (distances): numbers into
        templates, one encoder call a pose."""
        angles, positions, distances = self.truth_values()
        n = len(angles)
        before, after = _truth_templates(n, len(distances) // n)
        texts = encode_json([*positions, *distances])[1:-1].split(b",")
        points = len(positions)
        return before % (*angles, *texts[:points]), after % tuple(texts[points:])

    def truth_record(self, blocker: Blocker | None) -> TruthRecord:
        """The truth record of a step ending here after a move that ``blocker`` blocked
        (None: it moved)."""
        return _truth_record(self, blocker)


class World:
    """A 2D arm of ``n`` links, moved one joint at a time by ``step_deg``.

    Actions are integers ``0 .. 2n-1`` (restricted to ``scenario.actions``):
    joint ``a // 2`` turns by ``+step_deg`` (counter-clockwise) for even ``a`` and
    by ``-step_deg`` for odd ``a``. A blocked move leaves the arm where it is
    and :meth:`move` returns its :class:`~rsstp_sim.arm.geometry.Blocker`.

    Observation available to an agent: :attr:`sensation` (bool) and
    :attr:`feedback` (float in [0, 1]). Everything else (angles, positions,
    blockers, obstacle distances) is ground truth for analysis.
    """

    def __init__(self, scenario: Scenario, *, per_move: bool | None = None) -> None:
        """``per_move``: grow the world table move by move (True) or in blocks of poses
        (False); by default per move exactly when the pose space is too large for a dense
        table, or the whole table would cost more than
        :data:`~rsstp_sim.arm.table.MAX_TABULATION_CHECKS` (many obstacles), since the
        blocks double until they hold it (see :mod:`rsstp_sim.arm.table`). Both give the
        same answers."""
        self.scenario = scenario
        self.table = WorldTable(scenario)
        if per_move is None:
            per_move = not self.table.dense or self.table.heavy
        self.per_move = per_move
        self.geometry = self.table.geometry
        self._actions = {action: k for k, action in enumerate(self.table.actions)}
        self._n_actions = len(self._actions)
        self._next = self.table.next_row
        self._blocker_codes = self.table.blocker
        self._blockers: dict[int, Blocker] = {}
        self._poses: dict[int, Pose] = {}
        self._block = _FIRST_BLOCK
        self._row = 0
        self._pose = self.pose_at(0)
        self.last_blocker: Blocker | None = None

    # -- poses ---------------------------------------------------------------

    def pose_at(self, row: int) -> Pose:
        """The :class:`Pose` of a row of the world's table (a row :meth:`walk` gives)."""
        pose = self._poses.get(row)
        if pose is None:
            table = self.table
            pose = self._poses[row] = Pose(
                table.codes[row], bool(table.sensation[row]), table.feedback[row], table, row
            )
        return pose

    def pose(self, code: int) -> Pose:
        """The :class:`Pose` of a pose code the world has reached (see :attr:`pose_code`)."""
        row = self.table.row_of(code)
        if row < 0:
            raise UnknownPose(f"pose code {code} has not been reached")
        return self.pose_at(row)

    def _expand(self, row: int) -> None:
        """Compute the moves of ``row`` and of a block of poses around it: the block doubles
        at every miss, from :data:`_FIRST_BLOCK` (a short run pays for a few hundred poses, a
        long one for the whole space in a dozen misses)."""
        budget, self._block = self._block, self._block * 2
        self.table.expand(row, budget)

    def _blocker(self, blocker_code: int) -> Blocker | None:
        if not blocker_code:
            return None
        blocker = self._blockers.get(blocker_code)
        if blocker is None:
            decoded = self.geometry.decode(blocker_code)
            assert decoded is not None  # a non-zero code always names a blocker
            blocker = self._blockers[blocker_code] = decoded
        return blocker

    # -- the current pose ----------------------------------------------------

    def reset(self) -> Pose:
        """Put the arm back at the scenario's start pose."""
        self._row = 0
        self._pose = self.pose_at(0)
        self.last_blocker = None
        return self._pose

    def _outcome(self, action: int) -> tuple[int, int]:
        """(row reached, blocker code) for ``action`` from the current pose."""
        k = self._actions.get(action) if action.__class__ is not bool else None
        if k is None:  # True would pass for action 1
            raise ActionError(
                f"action {action!r} is not one of the scenario's actions {list(self._actions)}"
            )
        at = self._row * self._n_actions + k
        row = self._next[at]
        if row < 0:
            if self.per_move:
                row = self.table.step(self._row, k)
            else:
                self._expand(self._row)
                row = self._next[at]
        return row, self._blocker_codes[at]

    def move(self, action: int) -> Blocker | None:
        """Execute an action; return None when the arm moved, else why it was blocked."""
        row, blocker_code = self._outcome(action)
        if row != self._row:
            self._row = row
            pose = self._poses.get(row)
            self._pose = pose if pose is not None else self.pose_at(row)
        blocker = self.last_blocker = self._blocker(blocker_code) if blocker_code else None
        return blocker

    def walk(self, actions: Sequence[int]) -> tuple[IntArray, IntArray]:
        """Take ``actions`` in order from the current pose (the arm moves as :meth:`move`
        moves it); return the table row of the pose after each move and each move's blocker
        code (0 when it moved; :meth:`blocker_of` decodes one). The row of a pose code is
        ``table.codes[row]``. One array lookup per move, for re-simulating long runs."""
        rows: list[int] = []
        codes: list[int] = []
        add_row, add_code = rows.append, codes.append
        n_actions, nxt, blocker = self._n_actions, self._next, self._blocker_codes
        index = self._actions
        row = self._row
        for action in actions:
            k = index.get(action) if action.__class__ is not bool else None
            if k is None:
                raise ActionError(
                    f"action {action!r} is not one of the scenario's actions {list(index)}"
                )
            at = row * n_actions + k
            reached = nxt[at]
            if reached < 0:
                if self.per_move:
                    reached = self.table.step(row, k)
                else:
                    self._expand(row)
                    reached = nxt[at]
            add_row(reached)
            add_code(blocker[at])
            row = reached
        self._row = row
        self._pose = self.pose_at(row)
        self.last_blocker = self.blocker_of(codes[-1]) if codes else None
        return np.array(rows, np.int64), np.array(codes, np.int64)

    def blocker_of(self, blocker_code: int) -> Blocker | None:
        """The :class:`~rsstp_sim.arm.geometry.Blocker` of a blocker code (None for 0: it moved)."""
        return self._blocker(blocker_code) if blocker_code else None

    def peek(self, action: int) -> tuple[Pose, Blocker | None]:
        """Where an action would lead from the current pose, without moving."""
        row, blocker_code = self._outcome(action)
        return self.pose_at(row), self._blocker(blocker_code)

    @property
    def current(self) -> Pose:
        return self._pose

    @property
    def pose_code(self) -> int:
        return self._pose.code

    @property
    def angles_deg(self) -> tuple[int, ...]:
        return self._pose.angles_deg

    @property
    def joint_positions(self) -> FloatArray:
        return self._pose.joint_positions

    @property
    def sensation(self) -> bool:
        return self._pose.sensation

    @property
    def feedback(self) -> float:
        return self._pose.feedback

    @property
    def distances(self) -> FloatArray:
        return self._pose.distances

    # -- following a recorded run (the physics check) ------------------------------------

    def follow(self, actions: IntArray, recorded: Any = None) -> tuple[IntArray, IntArray]:
        """From the start pose, the table row of every step's pose (step 0's: the start,
        row 0) and each move's blocker code (0 at step 0) of ``actions[1:]``; raises
        :class:`~rsstp_sim.errors.ActionError` at an action the scenario does not have.
        ``recorded`` (a steps table with the recorded angles, or None) lets a long run be
        followed in numpy, a block of steps at a time, on the whole table: where the
        recorded poses are where the table moves each one before, the answer is theirs;
        else (or at the first step where they are not) the arm walks move by move."""
        if (
            recorded is not None
            and not self.per_move
            and len(actions) > pose_space_size(self.scenario)
        ):
            self.table.complete()  # a long walk meets most poses: all at once costs less
            followed = _followed(self.table, actions, recorded)
            if followed is not None:
                return followed
        rows, blockers = self.walk(actions[1:].tolist())
        return np.concatenate([[0], rows]), np.concatenate([[0], blockers])

    def senses(self) -> tuple[BoolArray, FloatArray]:
        """The sensation and the feedback of every row of the world's table."""
        sensation = np.frombuffer(self.table.sensation, np.int8).astype(bool)
        return sensation, np.frombuffer(self.table.feedback, np.float64)

    def truth_at(self, row: int, blocker_code: int) -> TruthRecord:
        """The truth record of a step ending at ``row`` after a move blocked by
        ``blocker_code`` (0: it moved)."""
        return self.pose_at(row).truth_record(self.blocker_of(blocker_code))

    def check_size(self, *, max_poses: int, max_checks: int | None) -> None:
        s, table = self.scenario, self.table
        counts = (len(s.actions), s.n_joints, len(s.obstacles))
        _check_size(s.name, table.pose_space, table.checks, counts, max_poses, max_checks)

    def machine(self) -> PoseMachine:
        """The world's table completed (:meth:`~rsstp_sim.arm.table.WorldTable.machine`)."""
        return self.table.machine()

    def cache_info(self) -> tuple[int, int]:
        """(poses in the world's table, poses with at least one move computed)."""
        return len(self.table), self.table.moves_computed()


_BLOCK_STEPS = 1 << 20
"""Steps :func:`_followed` takes at once (its temporary arrays stay a few tens of MB)."""


def _followed(table: WorldTable, actions: IntArray, steps: Any) -> tuple[IntArray, IntArray] | None:
    """The rows and blockers of :meth:`World.follow`, from a whole world table and the recorded
    poses, when each step's pose is where the world's table moves the one before by the
    step's action (checked in numpy, a block of steps at a time, not move by move); None at
    the first step where it is not, which the walk then finds."""
    names = [f"angle_deg_{j}" for j in range(len(table.radix))]
    if not set(names) <= set(steps.columns) or len(steps) != len(actions):
        return None
    index = np.full(max(table.actions) + 1, -1, np.int64)
    index[list(table.actions)] = np.arange(len(table.actions))
    table_codes = np.frombuffer(table.codes, np.int64)
    next_rows, blocker_codes = table.next_array(), table.blocker_array()
    columns = [steps[name].to_numpy() for name in names]
    rows = np.empty(len(steps), np.int64)
    blockers = np.zeros(len(steps), np.int64)
    before = 0  # the row of the step before the block (the start pose's: row 0)
    for first in range(0, len(steps), _BLOCK_STEPS):
        block = slice(first, first + _BLOCK_STEPS)
        angles = np.stack([column[block] for column in columns], axis=1).astype(np.int64)
        found = table.rows_at(angles)
        if (found < 0).any() or not np.array_equal(table_codes[found], angles @ table.radix):
            return None
        moves = actions[block]
        if first == 0:  # step 0 is the reset, to the start pose
            if found[0] != 0:
                return None
            found, moves = found[1:], moves[1:]
            if not len(found):  # the reset alone
                break
        if ((moves < 0) | (moves >= len(index))).any() or (index[moves] < 0).any():
            return None
        k = index[moves]
        came_from = np.concatenate([[before], found[:-1]])
        if not np.array_equal(next_rows[came_from, k], found):
            return None
        where = slice(max(first, 1), block.stop)
        rows[where] = found
        blockers[where] = blocker_codes[came_from, k]
        before = int(found[-1])
    rows[0] = 0
    return rows, blockers


@functools.lru_cache(maxsize=1 << 12)
def _truth_record(pose: Pose, blocker: Blocker | None) -> TruthRecord:
    """Poses are cached read-only objects, so a random walk revisiting them gets the same
    immutable record."""
    angles, points, distances = pose.truth_values()
    m = len(distances) // len(angles)
    return TruthRecord(
        angles_deg=tuple(angles),
        joint_positions=tuple(
            [PointRecord(x=x, y=y) for x, y in zip(points[0::2], points[1::2], strict=True)]
        ),
        blocked=blocker is not None,
        blocked_by=BlockedByRecord.of(blocker),
        distances=tuple(
            [
                DistancesRecord(obstacles=tuple(distances[k * m : (k + 1) * m]))
                for k in range(len(angles))
            ]
        ),
    )


@functools.lru_cache(maxsize=64)
def _truth_templates(n: int, m: int) -> tuple[bytes, bytes]:
    """The truth record of an arm of ``n`` links among ``m`` obstacles, before its
    ``blocked`` field (angles, then the points' float texts) and after it (the distances')."""
    angles = b",".join([b"%d"] * n)
    points = b",".join([b'{"x":%b,"y":%b}'] * (n + 1))
    tips = b",".join([b'{"obstacles":[' + b",".join([b"%b"] * m) + b"]}"] * n)
    return (
        b'"angles_deg":[' + angles + b'],"joint_positions":[' + points + b"],",
        b',"distances":[' + tips + b"]",
    )


class _Arm:
    """The arm as a body (:class:`~rsstp_sim.interface.Body`)."""

    name = "arm"

    def parse(self, data: Mapping[str, object], text: str, origin: str) -> Scenario:
        return parse_arm(data, text, origin)

    def check_start(self, scenario: Scenario) -> None:
        check_start(scenario)

    def world(self, scenario: Scenario) -> World:
        return World(scenario)

    def scenario_record(self, scenario: Scenario, common: dict[str, Any]) -> ScenarioRecord:
        target = scenario.feedback_target_deg
        return ScenarioRecord(
            n_joints=scenario.n_joints,
            lengths=tuple(float(v) for v in scenario.lengths),
            initial_deg=tuple(int(v) for v in scenario.initial_deg),
            step_deg=int(scenario.step_deg),
            feedback=FeedbackRecord(
                mode=scenario.feedback_mode,
                tolerance=float(scenario.tolerance),
                tolerance_abs=float(scenario.tolerance * scenario.total_length),
                points=tuple(PointRecord.of(xy) for xy in scenario.feedback_points),
                target_deg=None if target is None else tuple(int(v) for v in target),
            ),
            collision=scenario.collision,
            **common,
        )

    def describe(self, scenario: Scenario) -> list[str]:
        lengths = ", ".join(f"{length:g}" for length in scenario.lengths)
        obstacles = "; ".join(
            f"centre ({o.center[0]:g}, {o.center[1]:g}) radius {o.radius:g}"
            for o in scenario.obstacles
        )
        return [
            f"  joints: {scenario.n_joints} (lengths {lengths}; start "
            f"{list(scenario.initial_deg)} deg; step {scenario.step_deg} deg; actions "
            f"{list(scenario.actions)})",
            f"  obstacles: {len(scenario.obstacles)}" + (f": {obstacles}" if obstacles else ""),
            f"  feedback: {scenario.feedback_mode} (tolerance {scenario.tolerance:g}); "
            f"collision: {scenario.collision}",
        ]

    def pose_info(self, pose: Pose) -> dict[str, Any]:
        """Angles, joint positions (``(n + 1, 2)``) and obstacle distances (``(n, m)``)."""
        return {
            "angles_deg": pose.angles_deg,
            "joint_positions": pose.joint_positions.copy(),
            "distances": pose.distances.copy(),
        }

    def picture(self, scenario: Scenario) -> Any:
        from rsstp_sim.arm.picture import ArmPicture  # (drawing imports the world)

        return ArmPicture(scenario)

    def warnings(self, scenario: Scenario) -> list[str]:
        """A feedback point no pose can sense, and so many obstacles that steps slow down."""
        found = []
        problem = unsensable(scenario)
        if problem is not None:
            found.append(
                f"no pose can sense the feedback point, every sensation will be false: {problem}"
            )
        n = len(scenario.obstacles)
        if n > MANY_OBSTACLES:
            found.append(
                f"{n:,} obstacles: every step measures each joint's distance to each of them, "
                f"so steps run about {1 + n / 60:.0f} times slower than with a few"
            )
        return found

    def check_size(self, scenario: Scenario, *, max_poses: int, max_checks: int | None) -> None:
        bound, checks = pose_space_size(scenario), tabulation_checks(scenario)
        counts = (len(scenario.actions), scenario.n_joints, len(scenario.obstacles))
        _check_size(scenario.name, bound, checks, counts, max_poses, max_checks)

    def machine(self, scenario: Scenario) -> PoseMachine:
        """The world table completed (breadth first, whole frontiers per vectorised batch),
        its rows put in code order (:meth:`~rsstp_sim.arm.table.WorldTable.machine`)."""
        return WorldTable(scenario).machine()


def _check_size(
    name: str,
    bound: int,
    checks: int,
    counts: tuple[int, int, int],
    max_poses: int,
    max_checks: int | None,
) -> None:
    """Refuse the ground truth of the world ``name`` of ``bound`` lattice poses whose whole
    table costs ``checks`` link-obstacle checks, ``counts`` its actions, links and obstacles
    (:meth:`~rsstp_sim.interface.Body.check_size`)."""
    if max_checks is None:
        max_checks = MAX_TABULATION_CHECKS
    if bound > max_poses:
        raise TruthError(
            f"{name}: the pose space has {bound:,} poses, more than the "
            f"limit of {max_poses:,} (pass a larger max_poses)"
        )
    n_actions, n_links, n_obstacles = counts
    if checks > max_checks:
        raise TruthError(
            f"{name}: refused: tabulating the world would take about {checks:,} "
            f"link-obstacle checks ({bound:,} poses x {n_actions} moves x {n_links} links x "
            f"{n_obstacles:,} obstacles), more than the {max_checks:,} (about "
            "20 s) the ground truth takes on"
        )


ARM = _Arm()
"""The arm, as the body registry (:mod:`rsstp_sim.bodies`) names it."""
