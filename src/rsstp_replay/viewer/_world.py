"""The world for the viewer: the arm among its obstacles, in the plane.

Everything here is logged with ``send_columns``, a row only at the steps where what an entity
shows changes; the obstacles and the feedback points do not move and are logged as static
data.
Coordinates are the recording's, in its length unit, in the world frame (x right, y up):
the ``world`` entity carries a static transform that mirrors y, because Rerun's 2D views
draw y downwards.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_replay.reader._decode import blocker_texts
from rsstp_replay.viewer._chunks import send_rows
from rsstp_sim import palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.rover import RoverScenario

__all__ = [
    "ARM",
    "BLOCKED",
    "ROBOT",
    "ROOM",
    "FEEDBACK_POINTS",
    "OBSTACLES",
    "SENSOR",
    "WORLD",
    "joint_positions",
    "log_rover",
    "log_rover_static",
    "log_world",
    "log_world_static",
    "sensor_segments",
]

WORLD = "world"
ARM = "world/arm"
ROBOT = "world/robot"
ROOM = "world/room"
OBSTACLES = "world/obstacles"
FEEDBACK_POINTS = "world/feedback_points"
SENSOR = "world/sensor"
BLOCKED = "world/blocked"


_Floats = npt.NDArray[np.float64]


def _log_obstacles(stream: rr.RecordingStream, scenario: Scenario | RoverScenario) -> None:
    """The obstacles: filled disks with their outline, labelled."""
    if scenario.obstacles:
        centers = np.array([obstacle.center for obstacle in scenario.obstacles], np.float64)
        radii = np.array([obstacle.radius for obstacle in scenario.obstacles], np.float64)
        labels = [f"obstacle {j}" for j in range(len(radii))]
        stream.log(
            OBSTACLES,
            rr.Points2D(
                centers, radii=radii, colors=palette.OBSTACLE, labels=labels, draw_order=1.0
            ),
            rr.Ellipses2D(
                centers=centers,
                half_sizes=np.stack([radii, radii], axis=1),
                colors=palette.OBSTACLE_EDGE,
                line_radii=rr.Radius.ui_points(1.5),
                draw_order=2.0,
            ),
            static=True,
        )


def log_world_static(stream: rr.RecordingStream, scenario: Scenario) -> None:
    """The y-up transform, the obstacles (filled disks with their outline) and the feedback
    points, as static data; the styles of the per-step entities."""
    stream.log(WORLD, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)
    _log_obstacles(stream, scenario)
    if scenario.obstacles:
        radii = np.array([obstacle.radius for obstacle in scenario.obstacles], np.float64)
        colors = [palette.SENSORS[j % len(palette.SENSORS)] for j in range(len(radii))]
        stream.log(
            SENSOR,
            rr.LineStrips2D.from_fields(
                colors=colors * scenario.n_joints,
                radii=rr.Radius.ui_points(0.75),
                draw_order=3.0,
            ),
            static=True,
        )
    points = np.array(scenario.feedback_points, np.float64).reshape(-1, 2)
    stream.log(
        FEEDBACK_POINTS,
        rr.Points2D(
            points,
            radii=rr.Radius.ui_points(5.0),
            colors=palette.FEEDBACK,
            labels=[f"f{k}" for k in range(len(points))],
            draw_order=4.0,
        ),
        static=True,
    )
    stream.log(
        ARM,
        rr.LineStrips2D.from_fields(radii=rr.Radius.ui_points(3.0), draw_order=5.0),
        rr.Points2D.from_fields(
            radii=rr.Radius.ui_points(4.0), colors=palette.JOINT, draw_order=6.0
        ),
        static=True,
    )
    _log_blocked_style(stream)


def joint_positions(steps: pd.DataFrame, n_joints: int) -> _Floats:
    """``(rows, n + 1, 2)``: the base and every link's tip at each step (columns
    ``joint{k}_x``, ``joint{k}_y`` of :meth:`Recording.steps`)."""
    names = [f"joint{k}_{axis}" for k in range(n_joints + 1) for axis in ("x", "y")]
    return steps[names].to_numpy(np.float64).reshape(len(steps), n_joints + 1, 2)


def sensor_segments(positions: _Floats, scenario: Scenario) -> _Floats:
    """``(rows, n, m, 2, 2)``: for every step, tip ``k`` (of link ``k``) and obstacle ``j``,
    the segment from the tip to the obstacle's nearest point ``c + r (p - c) / |p - c|``
    (thesis figure 17); its length is the sensor reading ``|p - c| - r``."""
    centers = np.array([obstacle.center for obstacle in scenario.obstacles], np.float64)
    radii = np.array([obstacle.radius for obstacle in scenario.obstacles], np.float64)
    tips = positions[:, 1:, None, :]  # (rows, n, 1, 2)
    away = tips - centers[None, None, :, :]  # (rows, n, m, 2)
    norm = np.hypot(away[..., 0], away[..., 1])[..., None]
    # A tip exactly on a centre (impossible in a valid pose) has no direction: take +x.
    unit = np.divide(away, norm, out=np.tile([1.0, 0.0], away.shape[:-1] + (1,)), where=norm > 0)
    nearest = centers[None, None, :, :] + radii[None, None, :, None] * unit
    return np.stack([np.broadcast_to(tips, nearest.shape), nearest], axis=-2)


def log_world(
    stream: rr.RecordingStream,
    steps: pd.DataFrame,
    scenario: Scenario,
    *,
    sensor: bool = True,
) -> dict[str, int]:
    """The arm with its joints, the obstacle sensor (unless not ``sensor``: a long run's
    overview leaves it out, the distances stay as plots) and the blocked moves over the steps
    of ``steps``, a row only where something changed (the pose, or whether the move was
    blocked): Rerun shows the latest row at the time cursor. Returns rows per entity path."""
    times = steps.index.to_numpy(np.int64)
    n = scenario.n_joints
    positions = joint_positions(steps, n)
    blocked = steps["blocked"].to_numpy(np.bool_)
    moved = np.r_[True, (positions[1:] != positions[:-1]).any(axis=(1, 2))]
    arm_rows = np.flatnonzero(moved | np.r_[True, blocked[1:] != blocked[:-1]])
    strips = positions[arm_rows].astype(np.float32)  # what Rerun stores
    colors = np.where(blocked[arm_rows, None], palette.ARM_BLOCKED, palette.ARM).astype(np.uint8)
    logged = {
        ARM: send_rows(
            stream,
            ARM,
            times[arm_rows],
            lambda rows: [
                *rr.LineStrips2D.columns(strips=strips[rows], colors=colors[rows]),
                *rr.Points2D.columns(positions=strips[rows].reshape(-1, 2)).partition(
                    np.full(len(strips[rows]), n + 1)
                ),
            ],
        ),
    }
    m = len(scenario.obstacles)
    if m and sensor:
        pose_rows = np.flatnonzero(moved)
        segments = sensor_segments(positions[pose_rows], scenario).astype(np.float32)
        logged[SENSOR] = send_rows(
            stream,
            SENSOR,
            times[pose_rows],
            lambda rows: rr.LineStrips2D.columns(strips=segments[rows].reshape(-1, 2, 2)).partition(
                np.full(len(segments[rows]), n * m)
            ),
        )
    logged |= _log_blocked(stream, steps, positions[:, -1, :])
    return logged


def _log_blocked_style(stream: rr.RecordingStream) -> None:
    """The blocked-move marker's style, static: every body's."""
    stream.log(
        BLOCKED,
        rr.Points2D.from_fields(
            radii=rr.Radius.ui_points(8.0), colors=palette.ARM_BLOCKED, draw_order=7.0
        ),
        static=True,
    )


def _log_blocked(
    stream: rr.RecordingStream, steps: pd.DataFrame, places: _Floats
) -> dict[str, int]:
    """A marker at ``places`` (a row a step: the arm's tip, the robot) at every blocked move,
    labelled with what blocked it, gone at the next step; rows logged by path."""
    blocked = steps["blocked"].to_numpy(np.bool_)
    if not blocked.any():
        return {}
    times = steps.index.to_numpy(np.int64)
    rows_at = np.flatnonzero(blocked | np.r_[False, blocked[:-1]])
    labels = "blocked: " + blocker_texts(steps, rows_at)
    return {
        BLOCKED: send_rows(
            stream,
            BLOCKED,
            times[rows_at],
            lambda rows: _blocked(places[rows_at], labels, blocked[rows_at], rows),
        )
    }


def _blocked(
    tips: _Floats, labels: npt.NDArray[np.object_], blocked: npt.NDArray[np.bool_], rows: slice
) -> rr.ComponentColumnList:
    """The marker at the arm's tip, with what blocked the move, at the blocked steps of
    ``rows``; no point at the others (so the marker disappears)."""
    mask = blocked[rows]
    if not mask.any():
        return rr.Points2D.columns(positions=np.zeros((0, 2)), labels=[]).partition(
            np.zeros(len(mask), np.int64)
        )
    return rr.Points2D.columns(
        positions=tips[rows][mask], labels=labels[rows][mask].tolist()
    ).partition(mask.astype(np.int64))


# -- the rover ------------------------------------------------------------------------------

_WALL = (60, 60, 60)
_DOOR = (150, 150, 150)


def log_rover_static(stream: rr.RecordingStream, scenario: RoverScenario) -> None:
    """The y-up transform, the room's edges, walls, one-way doors (an arrow across each, the
    way it opens), obstacles and the feedback region, as static data; the robot's style."""
    stream.log(WORLD, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)
    width, height = scenario.room
    edges = [[(0.0, 0.0), (width, 0.0), (width, height), (0.0, height), (0.0, 0.0)]]
    walls = [[w.start, w.end] for w in scenario.walls]
    stream.log(
        ROOM,
        rr.LineStrips2D(
            edges + walls,
            colors=_WALL,
            radii=rr.Radius.ui_points(2.0),
            labels=["room"] + [f"wall {w}" for w in range(len(walls))],
            draw_order=2.0,
        ),
        static=True,
    )
    if scenario.doors:
        doors = [[d.start, d.end] for d in scenario.doors]
        middles = np.array([np.add(d.start, d.end) / 2 for d in scenario.doors], np.float64)
        toward = np.array([d.toward for d in scenario.doors], np.float64)
        toward = 0.6 * toward / np.hypot(toward[:, 0], toward[:, 1])[:, None]
        stream.log(
            f"{ROOM}/doors",
            rr.LineStrips2D(
                doors,
                colors=_DOOR,
                radii=rr.Radius.ui_points(2.0),
                labels=[f"door {d} (one way)" for d in range(len(doors))],
                draw_order=2.0,
            ),
            rr.Arrows2D(origins=middles - toward / 2, vectors=toward, colors=_DOOR, draw_order=2.5),
            static=True,
        )
    _log_obstacles(stream, scenario)
    stream.log(
        FEEDBACK_POINTS,
        rr.Ellipses2D(
            centers=[scenario.feedback_center],
            half_sizes=[(scenario.feedback_radius, scenario.feedback_radius)],
            colors=palette.FEEDBACK,
            line_radii=rr.Radius.ui_points(2.0),
            labels=["feedback region"],
            draw_order=4.0,
        ),
        static=True,
    )
    stream.log(
        ROBOT,
        rr.Points2D.from_fields(radii=max(scenario.robot_radius, 0.2), draw_order=5.0),
        rr.Arrows2D.from_fields(colors=palette.JOINT, draw_order=6.0),
        static=True,
    )
    _log_blocked_style(stream)


def log_rover(stream: rr.RecordingStream, steps: pd.DataFrame) -> dict[str, int]:
    """The robot (its disk, and an arrow for its heading) and the blocked moves over the steps
    of ``steps``, a row only where something changed. Returns rows per entity path."""
    times = steps.index.to_numpy(np.int64)
    position = steps[["x", "y"]].to_numpy(np.float64)
    heading = np.radians(steps["heading_deg"].to_numpy(np.float64))
    blocked = steps["blocked"].to_numpy(np.bool_)
    turned = np.r_[True, heading[1:] != heading[:-1]]
    moved = np.r_[True, (position[1:] != position[:-1]).any(axis=1)] | turned
    rows_at = np.flatnonzero(moved | np.r_[True, blocked[1:] != blocked[:-1]])
    points = position[rows_at].astype(np.float32)
    vectors = (0.45 * np.stack([np.cos(heading), np.sin(heading)], axis=1))[rows_at]
    colors = np.where(blocked[rows_at, None], palette.ARM_BLOCKED, palette.ARM).astype(np.uint8)
    logged = {
        ROBOT: send_rows(
            stream,
            ROBOT,
            times[rows_at],
            lambda rows: [
                *rr.Points2D.columns(positions=points[rows], colors=colors[rows]),
                *rr.Arrows2D.columns(
                    origins=points[rows], vectors=vectors[rows].astype(np.float32)
                ),
            ],
        )
    }
    logged |= _log_blocked(stream, steps, position)
    return logged
