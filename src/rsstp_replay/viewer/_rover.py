"""The rover for the viewer: the robot (a disk and an arrow for its heading) in its room,
among walls, one-way doors and obstacles, beside its feedback region."""

from __future__ import annotations

from typing import Any

import numpy as np
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

__all__ = ["ROBOT", "ROOM", "ROVER"]

ROBOT = "world/robot"
ROOM = "world/room"
_WALL = (60, 60, 60)
_DOOR = (150, 150, 150)


class _RoverView:
    """The rover's :class:`~rsstp_replay.viewer._world.BodyView`."""

    paths = (ROBOT, ROOM, f"{ROOM}/doors")

    def frame(self, scenario: Any) -> ViewFrame:
        """Its room with a margin, sized by half the room's longer side."""
        width, height = scenario.room
        side = max(width, height)
        return ViewFrame((width / 2, height / 2), 0.55 * side, side / 2)

    def distance_series(self, scenario: Any) -> list[tuple[str, str]]:
        return []  # (the rover has no obstacle sensor)

    def log_static(self, stream: rr.RecordingStream, scenario: Any) -> None:
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
                rr.Arrows2D(
                    origins=middles - toward / 2, vectors=toward, colors=_DOOR, draw_order=2.5
                ),
                static=True,
            )
        log_obstacles(stream, scenario)
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
        log_blocked_style(stream)

    def log_steps(
        self, stream: rr.RecordingStream, steps: pd.DataFrame, scenario: Any, *, sensor: bool
    ) -> dict[str, int]:
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
        logged |= log_blocked(stream, steps, position)
        return logged


ROVER = _RoverView()
