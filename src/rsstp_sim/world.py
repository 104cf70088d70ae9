"""The world (the thesis's *external system*): the arm among circular obstacles.

The world knows nothing about the agent, its model or any recording. Its answer
for a move depends only on the pose and the action, and the pose space is
finite (integer angles), so every pose's moves are computed once, all actions
in one vectorised call, and cached.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rsstp_sim import geometry
from rsstp_sim.errors import ActionError
from rsstp_sim.geometry import ArmGeometry, Blocker, FloatArray, IntArray
from rsstp_sim.scenario import Scenario

__all__ = ["Pose", "World"]

_FIRST_BOX = 350
"""Lattice poses computed together at the first cache miss (a cube around the pose)."""
_BOX_GROWTH = 1.5
_LAST_BOX = 4096
"""The cube grows by :data:`_BOX_GROWTH` at every miss, up to this many poses."""


@dataclass(frozen=True, slots=True, eq=False)
class Pose:
    """Everything the world knows about one pose (cached, read-only).

    - ``angles_deg``: relative joint angles, integer degrees in [0, 360).
    - ``joint_positions``: ``(n + 1, 2)`` float64, the base (origin) then every link tip.
    - ``sensation``: every tip within tolerance of its feedback point.
    - ``feedback``: float closeness to the feedback points, in [0, 1].
    - ``distances``: ``(n, m)`` distance from tip ``k`` to obstacle ``j``'s surface.
    """

    code: int
    angles_deg: tuple[int, ...]
    joint_positions: FloatArray
    sensation: bool
    feedback: float
    distances: FloatArray


class World:
    """A 2D arm of ``n`` links, moved one joint at a time by ``step_deg``.

    Actions are integers ``0 .. 2n-1`` (restricted to ``scenario.actions``):
    joint ``a // 2`` turns by ``+step_deg`` (counter-clockwise) for even ``a`` and
    by ``-step_deg`` for odd ``a``. A blocked move leaves the arm where it is
    and :meth:`move` returns its :class:`~rsstp_sim.geometry.Blocker`.

    Observation available to an agent: :attr:`sensation` (bool) and
    :attr:`feedback` (float in [0, 1]). Everything else (angles, positions,
    blockers, obstacle distances) is ground truth for analysis.
    """

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.geometry = ArmGeometry.from_scenario(scenario)
        n = scenario.n_joints
        self._radix = np.array([360**i for i in range(n)], dtype=np.int64)
        self._points = np.asarray(scenario.feedback_points, dtype=np.float64)
        self._tolerance_abs = scenario.tolerance * scenario.total_length
        actions = np.asarray(scenario.actions, dtype=np.int64)
        self._action_joint = actions // 2
        self._action_delta = np.where(actions % 2 == 0, scenario.step_deg, -scenario.step_deg)
        self._box_poses = _FIRST_BOX
        self._offsets = self._box_offsets()
        self._blockers: dict[int, Blocker] = {}
        self._poses: dict[int, Pose] = {}
        self._moves: dict[int, dict[int, tuple[int, Blocker | None]]] = {}
        self._start = self._encode(scenario.initial_deg)
        self._code = self._start
        self._pose = self.pose(self._start)
        self.last_blocker: Blocker | None = None

    # -- poses ---------------------------------------------------------------

    def _encode(self, angles_deg: tuple[int, ...]) -> int:
        return int(np.dot(np.asarray(angles_deg, dtype=np.int64) % 360, self._radix))

    def _decode(self, code: int) -> tuple[int, ...]:
        return tuple(int(v) for v in (code // self._radix) % 360)

    def pose(self, code: int) -> Pose:
        """The cached :class:`Pose` for a pose code (see :attr:`pose_code`)."""
        pose = self._poses.get(code)
        if pose is None:
            self._prefetch(code)
            pose = self._poses[code]
        return pose

    def _box_offsets(self) -> IntArray:
        """Angle offsets of the poses computed together on a cache miss: a cube of about
        ``self._box_poses`` lattice poses around the pose missed."""
        n = self.scenario.n_joints
        radius = max(1, int(round((self._box_poses ** (1.0 / n) - 1) / 2)))
        span = np.arange(-radius, radius + 1, dtype=np.int64) * self.scenario.step_deg
        grid = np.stack(np.meshgrid(*([span] * n), indexing="ij"), axis=-1)
        return grid.reshape(-1, n)

    def _prefetch(self, code: int) -> None:
        """Compute, in one vectorised batch, the poses and moves around ``code``.

        Numpy's per-call overhead dwarfs the arithmetic for one pose, so a miss
        fills a box of neighbouring poses at once (invalid ones included: they
        are never reached, so their entries are never read).
        """
        angles = np.asarray(self._decode(code), dtype=np.int64)
        box = (angles + self._offsets) % 360
        codes = box @ self._radix
        codes, first = np.unique(codes, return_index=True)
        box = box[first]
        fresh = np.array([c not in self._moves for c in codes.tolist()], dtype=bool)
        # A pose that is itself invalid (a link in an obstacle, links crossing, a fold) is
        # never reached (a move into it is blocked): its moves are not computed, which
        # saves the most expensive part, the swept checks, for about half of a box near
        # obstacles. The pose asked for is always computed.
        fresh &= (geometry.pose_blockers(self.geometry, box) == 0) | (codes == code)
        box, codes = box[fresh], codes[fresh]
        # A run that keeps missing is a long one that will visit most poses: each miss makes
        # the next box larger, so numpy's cost per call is spread over more poses.
        if self._box_poses < _LAST_BOX:
            self._box_poses = min(_LAST_BOX, int(self._box_poses * _BOX_GROWTH))
            self._offsets = self._box_offsets()

        n_actions = len(self._action_joint)
        starts = np.repeat(box, n_actions, axis=0)
        joints = np.tile(self._action_joint, len(box))
        deltas = np.tile(self._action_delta, len(box))
        blockers = geometry.move_blockers(self.geometry, starts, joints, deltas)
        rows = np.arange(len(starts))
        turned = (starts[rows, joints] + deltas) % 360
        turn = (turned - starts[rows, joints]) * self._radix[joints]
        targets = np.repeat(codes, n_actions) + turn
        targets = np.where(blockers == 0, targets, np.repeat(codes, n_actions))
        decode = self._blocker
        actions = self.scenario.actions
        target_list, blocker_list = targets.tolist(), blockers.tolist()
        for i, pose_code in enumerate(codes.tolist()):
            base = i * n_actions
            self._moves[pose_code] = {
                action: (target_list[base + k], decode(blocker_list[base + k]))
                for k, action in enumerate(actions)
            }

        missing = np.array([c not in self._poses for c in codes.tolist()], dtype=bool)
        self._make_poses(box[missing], codes[missing])
        if code not in self._poses:  # only when the box held it already (cannot happen twice)
            self._make_poses(angles[None, :], np.array([code]))

    def _blocker(self, blocker_code: int) -> Blocker | None:
        if not blocker_code:
            return None
        blocker = self._blockers.get(blocker_code)
        if blocker is None:
            decoded = self.geometry.decode(blocker_code)
            assert decoded is not None  # a non-zero code always names a blocker
            blocker = self._blockers[blocker_code] = decoded
        return blocker

    def _make_poses(self, angles: IntArray, codes: IntArray) -> None:
        positions = geometry.joint_positions(angles, self.geometry.lengths)
        positions.flags.writeable = False
        tips = positions[:, 1:]
        sensation, closeness = geometry.feedback(
            tips, self._points, self.geometry.lengths, self._tolerance_abs
        )
        distances = geometry.obstacle_distances(tips, self.geometry.centers, self.geometry.radii)
        distances.flags.writeable = False
        for i, (pose_code, sensed, close) in enumerate(
            zip(codes.tolist(), sensation.tolist(), closeness.tolist(), strict=True)
        ):
            self._poses[pose_code] = Pose(
                pose_code, tuple(angles[i].tolist()), positions[i], sensed, close, distances[i]
            )

    # -- the current pose ----------------------------------------------------

    def reset(self) -> Pose:
        """Put the arm back at the scenario's start pose."""
        self._code = self._start
        self._pose = self.pose(self._start)
        self.last_blocker = None
        return self._pose

    def _outcome(self, action: int) -> tuple[int, Blocker | None]:
        """(pose code reached, blocker) for ``action`` from the current pose; cached."""
        moves = self._moves.get(self._code)
        if moves is None:
            self._prefetch(self._code)
            moves = self._moves[self._code]
        try:
            if action.__class__ is bool:  # True would pass for action 1
                raise KeyError(action)
            return moves[action]
        except KeyError:
            raise ActionError(
                f"action {action!r} is not one of the scenario's actions {list(moves)}"
            ) from None

    def move(self, action: int) -> Blocker | None:
        """Execute an action; return None when the arm moved, else why it was blocked."""
        code, blocker = self._outcome(action)
        if code != self._code:
            self._code = code
            pose = self._poses.get(code)
            self._pose = pose if pose is not None else self.pose(code)
        self.last_blocker = blocker
        return blocker

    def peek(self, action: int) -> tuple[Pose, Blocker | None]:
        """Where an action would lead from the current pose, without moving."""
        code, blocker = self._outcome(action)
        return self.pose(code), blocker

    @property
    def current(self) -> Pose:
        return self._pose

    @property
    def pose_code(self) -> int:
        return self._code

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

    def cache_info(self) -> tuple[int, int]:
        """(poses cached, poses whose moves are cached)."""
        return len(self._poses), len(self._moves)
