"""The arm for the viewer: its links and joints, the obstacle sensor, among its obstacles and
feedback points."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_replay.viewer._chunks import send_rows
from rsstp_replay.viewer._world import (
    FEEDBACK_POINTS,
    WORLD,
    ViewFrame,
    log_blocked,
    log_blocked_style,
    log_obstacles,
)
from rsstp_sim import palette

__all__ = ["ARM", "ARM_PATH", "SENSOR", "distance_name", "joint_positions", "sensor_segments"]

ARM_PATH = "world/arm"
SENSOR = "world/sensor"

_Floats = npt.NDArray[np.float64]


def distance_name(link: int, obstacle: int) -> str:
    """The name of the series of the distance from link ``link``'s tip to ``obstacle``."""
    return f"tip of link {link} to obstacle {obstacle}"


def joint_positions(steps: pd.DataFrame, n_joints: int) -> _Floats:
    """``(rows, n + 1, 2)``: the base and every link's tip at each step (columns
    ``joint{k}_x``, ``joint{k}_y`` of :meth:`Recording.steps`)."""
    names = [f"joint{k}_{axis}" for k in range(n_joints + 1) for axis in ("x", "y")]
    return steps[names].to_numpy(np.float64).reshape(len(steps), n_joints + 1, 2)


def sensor_segments(positions: _Floats, scenario: Any) -> _Floats:
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


class _ArmView:
    """The arm's :class:`~rsstp_replay.viewer._world.BodyView`."""

    paths = (ARM_PATH, SENSOR)

    def frame(self, scenario: Any) -> ViewFrame:
        """Centred on the base: its reach and every obstacle with a margin, sized by its
        length."""
        reach = 1.1 * scenario.total_length
        for obstacle in scenario.obstacles:
            reach = max(reach, 1.05 * (float(np.hypot(*obstacle.center)) + obstacle.radius))
        return ViewFrame((0.0, 0.0), reach, scenario.total_length)

    def distance_series(self, scenario: Any) -> list[tuple[str, str]]:
        pairs = [(k, j) for k in range(scenario.n_joints) for j in range(len(scenario.obstacles))]
        return [(f"dist_{k}_{j}", distance_name(k, j)) for k, j in pairs]

    def log_static(self, stream: rr.RecordingStream, scenario: Any) -> None:
        """The y-up transform, the obstacles (filled disks with their outline) and the feedback
        points, as static data; the styles of the per-step entities."""
        stream.log(WORLD, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)
        log_obstacles(stream, scenario)
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
            ARM_PATH,
            rr.LineStrips2D.from_fields(radii=rr.Radius.ui_points(3.0), draw_order=5.0),
            rr.Points2D.from_fields(
                radii=rr.Radius.ui_points(4.0), colors=palette.JOINT, draw_order=6.0
            ),
            static=True,
        )
        log_blocked_style(stream)

    def log_steps(
        self, stream: rr.RecordingStream, steps: pd.DataFrame, scenario: Any, *, sensor: bool
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
        colors = np.where(blocked[arm_rows, None], palette.ARM_BLOCKED, palette.ARM).astype(
            np.uint8
        )
        logged = {
            ARM_PATH: send_rows(
                stream,
                ARM_PATH,
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
                lambda rows: rr.LineStrips2D.columns(
                    strips=segments[rows].reshape(-1, 2, 2)
                ).partition(np.full(len(segments[rows]), n * m)),
            )
        logged |= log_blocked(stream, steps, positions[:, -1, :])
        return logged


ARM = _ArmView()
