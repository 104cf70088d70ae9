"""The arm in a Foxglove scene (:mod:`rsstp_replay.export.foxglove`): its obstacles and feedback
points once, then the arm at step 0 and at every step where it moved.

- ``/rsstp/scene/static``: entity ``obstacles`` (flat cylinders of the obstacles' radii) and
  ``feedback`` (a small sphere at every feedback point).
- ``/rsstp/scene``: entity ``arm`` in frame ``world``, a line strip through the joint
  positions (base first) with a sphere at every joint.
- ``/rsstp/transforms``: at step 0, ``world -> base`` (identity) and ``link{n-1} -> tip``
  (the last link's length along x); at step 0 and at every step the arm moved, ``base ->
  link0 -> ... -> link{n-1}``: link ``k``'s frame sits at the end of link ``k - 1`` (at the
  base for ``k = 0``), turned by ``angle_deg_k`` about z.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from foxglove.messages import (
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
    SpherePrimitive,
    Timestamp,
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

__all__ = ["ARM_SCENE", "ArmDrawing", "ArmPoses"]

# Sizes relative to the arm's total length, so that every scenario reads alike.
_LINE_THICKNESS = 0.015
_JOINT_DIAMETER = 0.04
_FEEDBACK_DIAMETER = 0.03
_OBSTACLE_HEIGHT = 0.01


@dataclass(frozen=True)
class ArmPoses:
    """The arm at step 0 and at every step where it moved: ``steps`` (m), ``codes`` (m pose
    codes, ``sum_j angle_j * 360**j``), ``points`` (m rows of the ``n + 1`` joint positions,
    base first, as x0, y0, x1, y1, ...) and ``angles_deg`` (m rows of the ``n`` relative
    joint angles). The points are the recording's (its steps table's joint positions).
    """

    steps: npt.NDArray[np.int64]
    codes: npt.NDArray[np.int64]
    points: npt.NDArray[np.float64]
    angles_deg: npt.NDArray[np.int64]

    @classmethod
    def from_steps(cls, steps: pd.DataFrame, scenario: Any, *, source: Path) -> ArmPoses:
        """From a steps table with its joint positions (as the recording holds them)."""
        numbers = step_numbers(steps, source=source)
        n = scenario.n_joints
        angles = steps[[f"angle_deg_{j}" for j in range(n)]].to_numpy(np.int64)
        moved = np.ones(len(numbers), bool)
        moved[1:] = (angles[1:] != angles[:-1]).any(axis=1)
        names = [f"joint{k}_{axis}" for k in range(n + 1) for axis in ("x", "y")]
        points = steps[names].to_numpy(np.float64)[moved]
        angles = angles[moved]
        codes = angles @ 360 ** np.arange(n, dtype=np.int64)
        return cls(numbers[moved], codes, points, angles)

    def __len__(self) -> int:
        return len(self.steps)

    def rows(self) -> Iterator[tuple[int, int]]:
        """``(step, pose code)`` of every row as Python numbers, a block at a time."""
        return pose_rows(self.steps, self.codes)


class ArmDrawing:
    """The scene's messages for one arm scenario; what never changes is built once."""

    def __init__(self, scenario: Any, poses: ArmPoses | None = None) -> None:
        self.scenario = scenario
        self.poses = poses
        self.n_joints = scenario.n_joints
        total = scenario.total_length
        self.thickness = _LINE_THICKNESS * total
        diameter = _JOINT_DIAMETER * total
        self.joint_size = Vector3(x=diameter, y=diameter, z=diameter)
        self.arm_color = color(palette.ARM)
        self.joint_color = color(palette.JOINT)
        self.upright = Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)
        self.identity = Pose(position=Vector3(x=0.0, y=0.0, z=0.0), orientation=self.upright)
        self.turns = [turn(angle) for angle in range(360)]
        self.link_frames = [f"link{k}" for k in range(self.n_joints)]
        self.parents = ["base", *self.link_frames[:-1]]
        origin = Vector3(x=0.0, y=0.0, z=0.0)
        ends = [Vector3(x=length, y=0.0, z=0.0) for length in scenario.lengths]
        self.origin, self.tip_offset = origin, ends[-1]
        self.link_offsets = [origin, *ends[:-1]]  # link k starts where link k - 1 ends

    def static_scene(self) -> SceneUpdate:
        """The obstacles and the feedback points, in ``world``, forever."""
        total = self.scenario.total_length
        stamp = timestamp(0)
        height = _OBSTACLE_HEIGHT * total
        cylinders = [
            CylinderPrimitive(
                pose=Pose(
                    position=Vector3(x=o.center[0], y=o.center[1], z=0.0),
                    orientation=self.upright,
                ),
                size=Vector3(x=2 * o.radius, y=2 * o.radius, z=height),
                bottom_scale=1.0,
                top_scale=1.0,
                color=color(palette.OBSTACLE, 0.8),
            )
            for o in self.scenario.obstacles
        ]
        diameter = _FEEDBACK_DIAMETER * total
        spheres = [
            SpherePrimitive(
                pose=Pose(position=Vector3(x=x, y=y, z=0.0), orientation=self.upright),
                size=Vector3(x=diameter, y=diameter, z=diameter),
                color=color(palette.FEEDBACK),
            )
            for x, y in self.scenario.feedback_points
        ]
        return SceneUpdate(
            entities=[
                SceneEntity(
                    timestamp=stamp, frame_id=WORLD_FRAME, id="obstacles", cylinders=cylinders
                ),
                SceneEntity(timestamp=stamp, frame_id=WORLD_FRAME, id="feedback", spheres=spheres),
            ]
        )

    def fixed_transforms(self) -> FrameTransforms:
        """``world -> base`` and ``link{n-1} -> tip``, which never change."""
        stamp = timestamp(0)
        return FrameTransforms(
            transforms=[
                FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=WORLD_FRAME,
                    child_frame_id="base",
                    translation=self.origin,
                    rotation=self.upright,
                ),
                FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=self.link_frames[-1],
                    child_frame_id="tip",
                    translation=self.tip_offset,
                    rotation=self.upright,
                ),
            ]
        )

    def links(self, stamp: Timestamp | None, angles_deg: list[int]) -> FrameTransforms:
        """Every link's frame in its parent's at one pose (relative angles, base first)."""
        return FrameTransforms(
            transforms=[
                FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=parent,
                    child_frame_id=child,
                    translation=offset,
                    rotation=self.turns[angle % 360],
                )
                for parent, child, offset, angle in zip(
                    self.parents, self.link_frames, self.link_offsets, angles_deg, strict=True
                )
            ]
        )

    def body(self, row: int) -> SceneUpdate:
        """The arm at row ``row`` of the poses, without a timestamp."""
        assert self.poses is not None  # (given for an export)
        return self.arm(None, self.poses.points[row].tolist())

    def frames(self, row: int) -> FrameTransforms:
        """The links' frames at row ``row`` of the poses, without a timestamp."""
        assert self.poses is not None  # (given for an export)
        return self.links(None, self.poses.angles_deg[row].tolist())

    def arm(self, stamp: Timestamp | None, points: list[float]) -> SceneUpdate:
        """The arm at one pose (``x0, y0, x1, y1, ...``): a line strip through the joints, a
        sphere on each."""
        line, joints = self._arm_primitives(points)
        entity = SceneEntity(
            timestamp=stamp, frame_id=WORLD_FRAME, id="arm", lines=line, spheres=joints
        )
        return SceneUpdate(entities=[entity])

    def _arm_primitives(
        self, points: list[float]
    ) -> tuple[list[LinePrimitive], list[SpherePrimitive]]:
        xs, ys = points[0::2], points[1::2]
        line = LinePrimitive(
            type=LinePrimitiveLineType.LineStrip,
            pose=self.identity,
            thickness=self.thickness,
            points=[Point3(x=x, y=y, z=0.0) for x, y in zip(xs, ys, strict=True)],
            color=self.arm_color,
        )
        joints = [
            SpherePrimitive(
                pose=Pose(position=Vector3(x=x, y=y, z=0.0), orientation=self.upright),
                size=self.joint_size,
                color=self.joint_color,
            )
            for x, y in zip(xs, ys, strict=True)
        ]
        return [line], joints


class _ArmScene:
    """The arm's :class:`~rsstp_replay.export._foxglove_body.BodyScene`."""

    needs_geometry = True  # (its joint positions, as the recording holds them)

    def poses(self, steps: pd.DataFrame, scenario: Any, *, source: Path) -> ArmPoses:
        return ArmPoses.from_steps(steps, scenario, source=source)

    def drawing(self, scenario: Any, poses: Any) -> ArmDrawing:
        return ArmDrawing(scenario, poses)


ARM_SCENE = _ArmScene()
