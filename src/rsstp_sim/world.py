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
from rsstp_sim.geometry import ArmGeometry, Blocker, FloatArray
from rsstp_sim.scenario import Scenario

__all__ = ["Pose", "World"]


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
            pose = self._make_pose(code)
            self._poses[code] = pose
        return pose

    def _make_pose(self, code: int) -> Pose:
        angles = self._decode(code)
        positions = geometry.joint_positions(angles, self.geometry.lengths)
        positions.flags.writeable = False
        tips = positions[1:]
        sensation, closeness = geometry.feedback(
            tips, self._points, self.geometry.lengths, self._tolerance_abs
        )
        distances = geometry.obstacle_distances(tips, self.geometry.centers, self.geometry.radii)
        distances.flags.writeable = False
        return Pose(code, angles, positions, bool(sensation), float(closeness), distances)

    def _make_moves(self, code: int) -> dict[int, tuple[int, Blocker | None]]:
        angles = np.asarray(self._decode(code), dtype=np.int64)
        batch = np.broadcast_to(angles, (len(self._action_joint), len(angles)))
        codes = geometry.move_blockers(self.geometry, batch, self._action_joint, self._action_delta)
        moves: dict[int, tuple[int, Blocker | None]] = {}
        for action, joint, delta, blocker_code in zip(
            self.scenario.actions, self._action_joint, self._action_delta, codes.tolist(),
            strict=True,
        ):
            if blocker_code:
                moves[action] = (code, self.geometry.decode(blocker_code))
            else:
                turned = (int(angles[joint]) + int(delta)) % 360
                moves[action] = (code + (turned - int(angles[joint])) * int(self._radix[joint]),
                                 None)
        return moves

    # -- the current pose ----------------------------------------------------

    def reset(self) -> Pose:
        """Put the arm back at the scenario's start pose."""
        self._code = self._start
        self._pose = self.pose(self._start)
        self.last_blocker = None
        return self._pose

    def move(self, action: int) -> Blocker | None:
        """Execute an action; return None when the arm moved, else why it was blocked."""
        moves = self._moves.get(self._code)
        if moves is None:
            moves = self._moves[self._code] = self._make_moves(self._code)
        try:
            code, blocker = moves[action]
        except KeyError:
            raise ActionError(
                f"action {action!r} is not one of the scenario's actions {list(moves)}"
            ) from None
        if code != self._code:
            self._code = code
            pose = self._poses.get(code)
            self._pose = pose if pose is not None else self.pose(code)
        self.last_blocker = blocker
        return blocker

    def peek(self, action: int) -> tuple[Pose, Blocker | None]:
        """Where an action would lead from the current pose, without moving."""
        moves = self._moves.get(self._code)
        if moves is None:
            moves = self._moves[self._code] = self._make_moves(self._code)
        if action not in moves:
            raise ActionError(f"action {action!r} is not one of the scenario's actions "
                              f"{list(moves)}")
        code, blocker = moves[action]
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
