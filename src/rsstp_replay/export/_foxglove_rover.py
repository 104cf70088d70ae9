"""The rover in a Foxglove scene (:mod:`rsstp_replay.export.foxglove`): its room once, then the
robot at step 0 and at every step where it moved or turned.

- ``/rsstp/scene/static``: entity ``room`` (line strips: the room's edges and its walls, and
  its one-way doors lighter, each with an arrow the way it opens), ``obstacles`` (flat
  cylinders) and ``feedback`` (a flat disk, the region).
- ``/rsstp/scene``: entity ``robot`` in frame ``world``: a flat cylinder of the robot's
  radius at its cell's centre, and an arrow along its heading.
- ``/rsstp/transforms``: ``world -> room`` (identity) once, and ``world -> robot`` (the
  robot's centre, turned by its heading about z) at every pose.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pandas as pd
from foxglove.messages import (
    ArrowPrimitive,
    CylinderPrimitive,
    FrameTransform,
    FrameTransforms,
    LinePrimitive,
    LinePrimitiveLineType,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    Vector3,
)

from rsstp_replay.export._foxglove_shapes import (
    WORLD_FRAME,
    color,
    pose_rows,
    step_numbers,
    timestamp,
    turn,
)
from rsstp_sim import palette
from rsstp_sim.rover import RoverScenario

__all__ = ["ROVER_SCENE", "RoverDrawing", "RoverPoses"]

_WALL = (60, 60, 60)
_DOOR = (150, 150, 150)


@dataclass(frozen=True)
class RoverPoses:
    """The robot at step 0 and at every step where it moved or turned: ``steps``, ``codes``
    (its pose codes), ``cells`` (``(m, 2)``) and ``headings_deg``."""

    steps: npt.NDArray[np.int64]
    codes: npt.NDArray[np.int64]
    cells: npt.NDArray[np.int64]
    headings_deg: npt.NDArray[np.int64]

    @classmethod
    def from_steps(
        cls, steps: pd.DataFrame, scenario: RoverScenario, *, source: Path
    ) -> RoverPoses:
        numbers = step_numbers(steps, source=source)
        values = steps[["cell_x", "cell_y", "heading_deg"]].to_numpy(np.int64)
        moved = np.ones(len(numbers), bool)
        moved[1:] = (values[1:] != values[:-1]).any(axis=1)
        values = values[moved]
        width, height = scenario.room
        codes = values[:, 0] + width * (values[:, 1] + height * (values[:, 2] // scenario.turn_deg))
        return cls(numbers[moved], codes, values[:, :2], values[:, 2])

    def __len__(self) -> int:
        return len(self.steps)

    def rows(self) -> Iterator[tuple[int, int]]:
        """``(step, pose code)`` of every row as Python numbers, a block at a time."""
        return pose_rows(self.steps, self.codes)


class RoverDrawing:
    """The scene's messages for one rover scenario; what never changes is built once."""

    def __init__(self, scenario: RoverScenario, poses: RoverPoses) -> None:
        self.scenario = scenario
        self.poses = poses
        self.upright = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
        self.origin = Vector3(x=0.0, y=0.0, z=0.0)
        diameter = 2 * max(scenario.robot_radius, 0.2)
        self.robot_size = Vector3(x=diameter, y=diameter, z=0.1)

    def _pose(self, x: float, y: float, heading_deg: float = 0.0) -> Pose:
        return Pose(position=Vector3(x=x, y=y, z=0.0), orientation=turn(heading_deg))

    def _line(self, points: list[tuple[float, float]], rgb: tuple[int, int, int]) -> LinePrimitive:
        return LinePrimitive(
            type=LinePrimitiveLineType.LineStrip,
            pose=self._pose(0.0, 0.0),
            thickness=0.08,
            points=[Point3(x=x, y=y, z=0.0) for x, y in points],
            color=color(rgb),
        )

    def static_scene(self) -> SceneUpdate:
        """The room, its walls and doors, the obstacles and the feedback region, forever."""
        s, stamp = self.scenario, timestamp(0)
        width, height = s.room
        lines = [self._line([(0, 0), (width, 0), (width, height), (0, height), (0, 0)], _WALL)]
        lines += [self._line([w.start, w.end], _WALL) for w in s.walls]
        lines += [self._line([d.start, d.end], _DOOR) for d in s.doors]
        arrows = []
        for door in s.doors:
            mx, my = np.add(door.start, door.end) / 2
            angle = math.degrees(math.atan2(door.toward[1], door.toward[0]))
            arrows.append(
                ArrowPrimitive(
                    pose=self._pose(float(mx), float(my), angle),
                    shaft_length=0.3,
                    shaft_diameter=0.06,
                    head_length=0.2,
                    head_diameter=0.2,
                    color=color(_DOOR),
                )
            )
        obstacles = [
            CylinderPrimitive(
                pose=self._pose(*o.center),
                size=Vector3(x=2 * o.radius, y=2 * o.radius, z=0.05),
                bottom_scale=1.0,
                top_scale=1.0,
                color=color(palette.OBSTACLE, 0.8),
            )
            for o in s.obstacles
        ]
        region = 2 * max(s.feedback_radius, 0.1)
        feedback = CylinderPrimitive(
            pose=self._pose(*s.feedback_center),
            size=Vector3(x=region, y=region, z=0.02),
            bottom_scale=1.0,
            top_scale=1.0,
            color=color(palette.FEEDBACK, 0.6),
        )
        return SceneUpdate(
            entities=[
                SceneEntity(
                    timestamp=stamp, frame_id=WORLD_FRAME, id="room", lines=lines, arrows=arrows
                ),
                SceneEntity(
                    timestamp=stamp, frame_id=WORLD_FRAME, id="obstacles", cylinders=obstacles
                ),
                SceneEntity(
                    timestamp=stamp, frame_id=WORLD_FRAME, id="feedback", cylinders=[feedback]
                ),
            ]
        )

    def fixed_transforms(self) -> FrameTransforms:
        """``world -> room``, which never changes."""
        return FrameTransforms(
            transforms=[
                FrameTransform(
                    timestamp=timestamp(0),
                    parent_frame_id=WORLD_FRAME,
                    child_frame_id="room",
                    translation=self.origin,
                    rotation=self.upright,
                )
            ]
        )

    def body(self, row: int) -> SceneUpdate:
        """The robot at row ``row`` of the poses: its disk and its heading's arrow."""
        (x, y), heading = self.poses.cells[row] + 0.5, float(self.poses.headings_deg[row])
        robot = CylinderPrimitive(
            pose=self._pose(float(x), float(y)),
            size=self.robot_size,
            bottom_scale=1.0,
            top_scale=1.0,
            color=color(palette.ARM),
        )
        arrow = ArrowPrimitive(
            pose=self._pose(float(x), float(y), heading),
            shaft_length=0.25,
            shaft_diameter=0.08,
            head_length=0.2,
            head_diameter=0.2,
            color=color(palette.JOINT),
        )
        entity = SceneEntity(frame_id=WORLD_FRAME, id="robot", cylinders=[robot], arrows=[arrow])
        return SceneUpdate(entities=[entity])

    def frames(self, row: int) -> FrameTransforms:
        """``world -> robot`` at row ``row`` of the poses."""
        (x, y), heading = self.poses.cells[row] + 0.5, float(self.poses.headings_deg[row])
        return FrameTransforms(
            transforms=[
                FrameTransform(
                    parent_frame_id=WORLD_FRAME,
                    child_frame_id="robot",
                    translation=Vector3(x=float(x), y=float(y), z=0.0),
                    rotation=turn(heading),
                )
            ]
        )


class _RoverScene:
    """The rover's :class:`~rsstp_replay.export._foxglove_body.BodyScene`."""

    needs_geometry = False  # (its cell and heading say everything)

    def poses(self, steps: pd.DataFrame, scenario: RoverScenario, *, source: Path) -> RoverPoses:
        return RoverPoses.from_steps(steps, scenario, source=source)

    def drawing(self, scenario: RoverScenario, poses: RoverPoses) -> RoverDrawing:
        return RoverDrawing(scenario, poses)


ROVER_SCENE = _RoverScene()
