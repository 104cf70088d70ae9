"""The rover's whole world as arrays: every pose's moves, blockers, sensation and feedback.

A pose is a cell and a heading, numbered ``code = x + W * (y + H * h)`` in a room of
``W x H`` cells. Turning never meets anything (the robot is round and turns in place). A
step forward or back goes from the cell's centre to the neighbouring cell's centre along the
heading (a diagonal one at 45 degrees); it is blocked when the disk of the robot's radius,
swept along that segment, leaves the room, touches an obstacle's disk or a wall, or touches a
one-way door while not moving along the door's ``toward``. The blocked robot stays where it
is. Everything is computed for every pose at once, one numpy expression per obstacle, wall
or door, so a room of a few hundred thousand poses takes well under a second.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from rsstp_sim.arrays import BoolArray, FloatArray, IntArray
from rsstp_sim.errors import ScenarioError
from rsstp_sim.interface import PoseMachine
from rsstp_sim.moore import reached
from rsstp_sim.rover.scenario import Door, RoverScenario, Wall

__all__ = [
    "ROOM_EDGES",
    "RoverTable",
    "cell_clearance",
    "check_start",
    "headings_xy",
    "segment_distance",
]

ROOM_EDGES = 4
"""Blocker codes 1 to 4 are the room's edges: east (x = width), north, west, south."""


def headings_xy(turn_deg: int) -> IntArray:
    """The cell step ``(dx, dy)`` of each heading, ``(headings, 2)``."""
    angles = np.deg2rad(np.arange(0, 360, turn_deg))
    return np.stack([np.rint(np.cos(angles)), np.rint(np.sin(angles))], axis=1).astype(np.int64)


def _point_segment(px: FloatArray, py: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance from points ``(px, py)`` to the segments ``a``-``b`` (broadcast)."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(length2 > 0, ((px - a[0]) * dx + (py - a[1]) * dy) / length2, 0.0)
    t = np.clip(t, 0.0, 1.0)
    return np.asarray(np.hypot(a[0] + t * dx - px, a[1] + t * dy - py))


def segment_distance(p: FloatArray, q: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance between segments ``p``-``q`` (arrays of points, ``(..., 2)`` split as
    ``p[0], p[1]``) and ``a``-``b``: 0 where they cross, else the least endpoint distance."""

    def orient(o: FloatArray, s: FloatArray, t: FloatArray) -> FloatArray:
        return np.asarray((s[0] - o[0]) * (t[1] - o[1]) - (s[1] - o[1]) * (t[0] - o[0]))

    d1, d2 = orient(a, b, p), orient(a, b, q)
    d3, d4 = orient(p, q, a), orient(p, q, b)
    crossing = (d1 * d2 < 0) & (d3 * d4 < 0)
    near = np.minimum.reduce(
        [
            _point_segment(p[0], p[1], a, b),
            _point_segment(q[0], q[1], a, b),
            _point_segment(a[0], a[1], p, q),
            _point_segment(b[0], b[1], p, q),
        ]
    )
    return np.asarray(np.where(crossing, 0.0, near))


@dataclass(frozen=True, eq=False)
class RoverTable:
    """Every pose of a rover scenario: ``next_code[c, k]`` is where action ``actions[k]``
    takes pose ``c`` (``c`` itself when blocked), ``blocker[c, k]`` why it was blocked (0: it
    moved), ``free[c]`` whether the robot fits at the pose's cell. Raises
    :class:`~rsstp_sim.errors.ScenarioError` when it does not fit at its start
    (:func:`check_start`)."""

    scenario: RoverScenario
    next_code: IntArray
    blocker: IntArray
    free: BoolArray
    sensation: BoolArray
    feedback: FloatArray

    @classmethod
    def of(cls, scenario: RoverScenario) -> RoverTable:
        """The table of ``scenario``: computed once, then shared (it is read-only), so the
        command's warnings, its world and the ground truth tabulate the room once."""
        return _table(scenario)

    @classmethod
    def _compute(cls, scenario: RoverScenario) -> RoverTable:
        width, height = scenario.room
        n_headings = scenario.headings
        codes = np.arange(width * height * n_headings, dtype=np.int64)
        x, rest = codes % width, codes // width
        y, heading = rest % height, rest // height
        centers = np.stack([x + 0.5, y + 0.5]).astype(np.float64)
        free = cell_clearance(scenario, centers)
        check_start(scenario, bool(free[scenario.start[0] + width * scenario.start[1]]))

        steps = headings_xy(scenario.turn_deg)
        moves = {0: 1, 1: -1}  # forward, back: +/- the heading's cell step
        next_code = np.empty((len(codes), len(scenario.actions)), np.int64)
        blocker = np.zeros((len(codes), len(scenario.actions)), np.int64)
        for k, action in enumerate(scenario.actions):
            if action in moves:
                sign = moves[action]
                dx, dy = sign * steps[heading, 0], sign * steps[heading, 1]
                tx, ty = x + dx, y + dy
                code = _move_blocker(scenario, centers, dx, dy)
                # The room's edge it would cross comes first (at a corner, east or west).
                edge = np.select(
                    [tx >= width, tx < 0, ty >= height, ty < 0], [1, 3, 2, 4], default=0
                )
                code = np.where(edge > 0, edge, code)
                moved = code == 0
                next_code[:, k] = np.where(moved, codes + dx + width * dy, codes)
                blocker[:, k] = code
            else:
                turn = 1 if action == 2 else -1
                next_code[:, k] = x + width * (y + height * ((heading + turn) % n_headings))

        gap = np.hypot(
            centers[0] - scenario.feedback_center[0], centers[1] - scenario.feedback_center[1]
        )
        sensation = gap <= scenario.feedback_radius
        if scenario.feedback_heading is not None:
            sensation &= heading == scenario.feedback_heading
        diagonal = float(np.hypot(width, height))
        feedback = np.clip(1.0 - np.maximum(gap - scenario.feedback_radius, 0.0) / diagonal, 0, 1)
        if scenario.feedback_heading is not None:
            feedback = np.where(heading == scenario.feedback_heading, feedback, 0.5 * feedback)
        for array in (next_code, blocker, free, sensation, feedback):
            array.flags.writeable = False
        return cls(scenario, next_code, blocker, free, sensation, feedback)

    @property
    def start_code(self) -> int:
        s = self.scenario
        width, height = s.room
        return s.start[0] + width * (s.start[1] + height * s.start_heading)

    def machine(self) -> PoseMachine:
        """The poses reached from the start, breadth first, in code order."""
        s = self.scenario
        n_codes = len(self.next_code)
        tail = np.repeat(np.arange(n_codes, dtype=np.int64), len(s.actions))
        codes = np.flatnonzero(reached(tail, self.next_code.ravel(), self.start_code, n_codes))
        rank = np.full(n_codes, -1, dtype=np.int64)
        rank[codes] = np.arange(len(codes))
        values = self.values_of(codes)
        values[:, 2] *= s.turn_deg
        width, height = s.room
        return PoseMachine(
            codes=codes.astype(np.int64),
            values=values,
            next_pose=rank[self.next_code[codes]],
            sensation=self.sensation[codes],
            start_index=int(rank[self.start_code]),
            value_names=("cell_x", "cell_y", "heading_deg"),
            radices=(width, height, s.headings),
            units=(1, 1, s.turn_deg),
            wrap=False,
        )

    def values_of(self, codes: IntArray) -> IntArray:
        """The ``(x, y, heading)`` of pose codes, ``(B, 3)``."""
        width, height = self.scenario.room
        codes = np.asarray(codes, np.int64)
        return np.stack([codes % width, codes // width % height, codes // (width * height)], 1)


@functools.lru_cache(maxsize=4)
def _table(scenario: RoverScenario) -> RoverTable:
    return RoverTable._compute(scenario)


def cell_clearance(scenario: RoverScenario, centers: FloatArray) -> BoolArray:
    """Whether the robot's disk at each of ``centers`` (``(2, B)``) touches nothing."""
    r = scenario.robot_radius
    free = np.ones(centers.shape[1], np.bool_)
    for obstacle in scenario.obstacles:
        gap = np.hypot(centers[0] - obstacle.center[0], centers[1] - obstacle.center[1])
        free &= gap > obstacle.radius + r
    segments: list[Wall | Door] = [*scenario.walls, *scenario.doors]
    for segment in segments:
        a, b = np.array(segment.start), np.array(segment.end)
        free &= _point_segment(centers[0], centers[1], a, b) > r
    return free


def check_start(scenario: RoverScenario, free: bool | None = None) -> None:
    """Raise :class:`~rsstp_sim.errors.ScenarioError` when the robot at its start cell touches
    a wall, a door or an obstacle; ``free``: whether it fits there, when already known (the
    table's)."""
    x, y = scenario.start
    if free is None:
        free = bool(cell_clearance(scenario, np.array([[x + 0.5], [y + 0.5]]))[0])
    if not free:
        raise ScenarioError(
            f"{scenario.origin}: rover.start: the robot at cell {[x, y]} touches a wall, a "
            "door or an obstacle"
        )


def _move_blocker(
    scenario: RoverScenario, centers: FloatArray, dx: IntArray, dy: IntArray
) -> IntArray:
    """The blocker code of the move by ``(dx, dy)`` from each centre (0: nothing met; the
    room's edge is the caller's)."""
    r = scenario.robot_radius
    p = centers
    q = np.stack([centers[0] + dx, centers[1] + dy])
    code = np.zeros(centers.shape[1], np.int64)
    base = 1 + ROOM_EDGES
    for j, obstacle in enumerate(scenario.obstacles):
        centre = np.array(obstacle.center)
        met = _point_segment(centre[0], centre[1], p, q) <= obstacle.radius + r
        code = np.where((code == 0) & met, base + j, code)
    base += len(scenario.obstacles)
    for w, wall in enumerate(scenario.walls):
        met = segment_distance(p, q, np.array(wall.start), np.array(wall.end)) <= r
        code = np.where((code == 0) & met, base + w, code)
    base += len(scenario.walls)
    for d, door in enumerate(scenario.doors):
        met = segment_distance(p, q, np.array(door.start), np.array(door.end)) <= r
        along = dx * door.toward[0] + dy * door.toward[1] > 0
        code = np.where((code == 0) & met & ~along, base + d, code)
    return code
