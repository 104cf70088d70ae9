"""A recording as a Foxglove scene: a companion MCAP of well-known Foxglove schemas (protobuf).

>>> with open_recording("run.mcap") as recording:  # doctest: +SKIP
...     export_foxglove(recording, "run.scene.mcap")

The recording itself is JSON described by this project's schemas: Foxglove plots it, but its
3D panel has nothing to draw. The scene file tells the same run in schemas the viewers know:

- ``/rsstp/scene`` (``foxglove.SceneUpdate``): entity ``arm`` in frame ``world``, a line strip
  through the joint positions (base first) with a sphere at every joint; at step 0 and then
  only at the steps where the arm moved (a blocked move leaves it where it was: nothing is
  sent). Each update replaces the previous ``arm``; no lifetime (it stays until replaced).
- ``/rsstp/scene/static`` (``foxglove.SceneUpdate``): once, at step 0, no lifetime: entity
  ``obstacles`` (flat cylinders of the obstacles' radii) and entity ``feedback`` (a small
  sphere at every feedback point). A topic of its own: a viewer that jumps on the timeline
  shows the latest message of each topic, and on the arm's topic they would vanish.
- ``/rsstp/transforms`` (``foxglove.FrameTransforms``): at step 0, ``world -> base``
  (identity) and ``link{n-1} -> tip`` (the last link's length along x); at step 0 and at every
  step the arm moved, ``base -> link0 -> ... -> link{n-1}``: link ``k``'s frame sits at the
  end of link ``k - 1`` (at the base for ``k = 0``), turned by ``angle_deg_k`` about z.
- ``/rsstp/log`` (``foxglove.Log``): one per event, at its step: ``name`` the kind, ``message``
  its text; level WARNING for ``blocked`` and ``contradiction``, INFO for the others.

A rover's recording gives the same topics with the rover's entities and frames
(:mod:`rsstp_replay.export._foxglove_rover`): its room on the static topic, the robot on
``/rsstp/scene``, ``world -> robot`` on the transforms.

A metadata record ``rsstp.scene`` names what the scene was made from (scenario and its
SHA-256, strategy, seed, steps) and by which ``rsstp``. The world is the plane z = 0, in the
recording's length unit. The ``log_time`` (and ``publish_time``) and the ``timestamp`` of
every message of step ``t`` are ``t * 1,000,000`` ns, as in the recording, and nothing else
holds a time: the same recording gives the same bytes (with the same foxglove-sdk, whose
version the file's header gives).

The messages are foxglove-sdk's (its schemas, registered as it registers them, and its
protobuf encoding); the file is written by the recorder's chunked MCAP writer
(:mod:`rsstp_sim.recording.chunks`, zstd chunks, every index), not by one SDK call per
message: the arm's entity and the links' transforms of a pose are encoded once without their
timestamp, which each step puts in front (it is the first field of both, see
:mod:`rsstp_replay.export._foxglove_stamps`).
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import metadata as distributions
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
import pandas as pd
from foxglove.messages import (
    CylinderPrimitive,
    FrameTransform,
    FrameTransforms,
    LinePrimitive,
    LinePrimitiveLineType,
    Log,
    LogLevel,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    SceneUpdate,
    SpherePrimitive,
    Timestamp,
    Vector3,
)

from rsstp_format.schemas import STEP_NS
from rsstp_replay.export._foxglove_rover import RoverDrawing, RoverPoses
from rsstp_replay.export._foxglove_shapes import color, pose_rows, step_numbers, timestamp, turn
from rsstp_replay.export._foxglove_stamps import PoseMessages
from rsstp_sim import __version__, palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.files import written_whole
from rsstp_sim.recording.chunks import ChunkedWriter, Message
from rsstp_sim.recording.output import SideFileWriter
from rsstp_sim.rover import RoverScenario
from rsstp_sim.words import counted

if TYPE_CHECKING:
    from rsstp_replay.reader.recording import Recording

__all__ = [
    "ARM_TOPIC",
    "LOG_TOPIC",
    "STATIC_TOPIC",
    "TRANSFORMS_TOPIC",
    "SceneExport",
    "export_foxglove",
]

ARM_TOPIC = "/rsstp/scene"
STATIC_TOPIC = "/rsstp/scene/static"
TRANSFORMS_TOPIC = "/rsstp/transforms"
LOG_TOPIC = "/rsstp/log"
WORLD_FRAME = "world"
_WARNING_KINDS = frozenset({"blocked", "contradiction"})

# Sizes relative to the arm's total length, so that every scenario reads alike.
_LINE_THICKNESS = 0.015
_JOINT_DIAMETER = 0.04
_FEEDBACK_DIAMETER = 0.03
_OBSTACLE_HEIGHT = 0.01

_CACHED_POSES = 65_536
"""Poses whose encoded messages are kept (three-joint has 39,232 reachable poses)."""
_CHUNK_SIZE = 1024 * 1024
"""Bytes of messages per zstd chunk (foxglove-sdk's writer's default too)."""


@dataclass(frozen=True)
class SceneExport:
    """What :func:`export_foxglove` wrote: ``path``; ``steps`` (the recording's, the reset
    included); ``arm_poses`` (``/rsstp/scene`` updates: step 0 and every step the arm moved);
    ``logs`` (``/rsstp/log`` messages, one per event); ``size`` (bytes)."""

    path: Path
    steps: int
    arm_poses: int
    logs: int
    size: int

    def to_text(self) -> str:
        return (
            f"wrote {self.path} ({self.size:,} bytes): the body at {self.arm_poses:,} of "
            f"{counted(self.steps, 'step')} (where it moved), {counted(self.logs, 'event')} as log "
            "messages"
        )


def export_foxglove(recording: Recording, path: str | os.PathLike[str]) -> SceneExport:
    """Write ``recording`` as a Foxglove scene to ``path`` (see the module's docstring).

    The recording is read whole before the file is opened, so a damaged one raises its
    :class:`~rsstp_replay.errors.ReplayError` and writes nothing. The file goes to a side file
    renamed onto ``path`` when whole (:func:`rsstp_sim.files.written_whole`): a failed write
    is an :class:`~rsstp_sim.errors.OutputError` and leaves ``path`` as it was.
    """
    out = Path(path)
    scenario = recording.scenario
    steps = recording.steps(geometry=not isinstance(scenario, RoverScenario))
    n_steps = len(steps)
    poses: _ArmPoses | RoverPoses
    draw: _Drawing | RoverDrawing
    if isinstance(scenario, RoverScenario):
        poses = RoverPoses.from_steps(steps, scenario, source=recording.path)
        draw = RoverDrawing(scenario, poses)
    else:
        poses = _ArmPoses.from_steps(steps, scenario, source=recording.path)
        draw = _Drawing(scenario, poses)
    del steps  # the poses where the body moved are all that is kept of it
    events = recording.events()
    metadata = {
        "package": "rsstp",
        "package_version": __version__,
        "scenario": scenario.name,
        "scenario_sha256": scenario.sha256,
        "strategy": recording.strategy,
        "seed": str(recording.seed),
        "steps": str(recording.n_steps),
    }
    with written_whole(out) as side:
        output = SideFileWriter(io.FileIO(side, "w"))
        try:
            writer = ChunkedWriter(output, chunk_size=_CHUNK_SIZE)
            _write_scene(writer, draw, poses, events, metadata)
        except BaseException:  # a full disk, Ctrl-C: no part of a scene stays
            output.close()
            side.unlink(missing_ok=True)
            raise
        output.close()
    return SceneExport(
        path=out,
        steps=n_steps,
        arm_poses=len(poses),
        logs=len(events),
        size=out.stat().st_size,
    )


def _write_scene(
    writer: ChunkedWriter,
    draw: _Drawing | RoverDrawing,
    poses: _ArmPoses | RoverPoses,
    events: pd.DataFrame,
    metadata: dict[str, str],
) -> None:
    """The scene's records, in the order foxglove-sdk's writer gives them: the channels as
    first logged on, the metadata, then the messages in step order."""
    library = f"rsstp {__version__} (foxglove-sdk {_sdk_version()} messages)"
    writer.start(profile="", library=library)
    schemas = {
        message: writer.register_schema(schema.name, schema.encoding, schema.data)
        for message in (SceneUpdate, FrameTransforms, Log)
        for schema in (message.get_schema(),)
    }
    static, transforms, arm, logs = (
        writer.register_channel(topic, "protobuf", schemas[message])
        for topic, message in (
            (STATIC_TOPIC, SceneUpdate),
            (TRANSFORMS_TOPIC, FrameTransforms),
            (ARM_TOPIC, SceneUpdate),
            (LOG_TOPIC, Log),
        )
    )
    writer.add_metadata("rsstp.scene", metadata)

    def messages() -> Iterator[Message]:
        yield static, 0, draw.static_scene().encode(), b""
        yield transforms, 0, draw.fixed_transforms().encode(), b""
        log_events = _EventLogs(events, logs)
        poses_at = PoseMessages(draw.body, draw.frames, cached=_CACHED_POSES).at
        next_event = log_events.next_step
        for row, (step, code) in enumerate(poses.rows()):
            if step > next_event:
                yield from log_events.before(step)
                next_event = log_events.next_step
            head, tail, links = poses_at(step, code, row)
            log_time = step * STEP_NS
            yield arm, log_time, head, tail
            yield transforms, log_time, links, b""
        yield from log_events.before(math.inf)

    writer.add_messages(messages())
    writer.finish()


def _sdk_version() -> str:
    try:
        return distributions.version("foxglove-sdk")
    except distributions.PackageNotFoundError:  # pragma: no cover - it is a dependency
        return "unknown"


class _EventLogs:
    """The events as ``foxglove.Log`` messages on ``channel``, in step order."""

    def __init__(self, events: pd.DataFrame, channel: int) -> None:
        self.steps: list[int] = events["step"].to_numpy(np.int64).tolist()
        self.kinds: list[str] = events["kind"].astype(str).tolist()
        self.texts: list[str] = events["text"].astype(str).tolist()
        self.channel = channel
        self.written = 0
        self.next_step: float = self.steps[0] if self.steps else math.inf
        """The step of the next event not yet written."""

    def before(self, step: float) -> Iterator[Message]:
        """The messages of the events of the steps before ``step`` not yet written."""
        steps, kinds, texts = self.steps, self.kinds, self.texts
        while self.written < len(steps) and steps[self.written] < step:
            at, kind = steps[self.written], kinds[self.written]
            level = LogLevel.Warning if kind in _WARNING_KINDS else LogLevel.Info
            message = Log(
                timestamp=timestamp(at), level=level, message=texts[self.written], name=kind
            )
            self.written += 1
            self.next_step = steps[self.written] if self.written < len(steps) else math.inf
            yield self.channel, at * STEP_NS, message.encode(), b""


@dataclass(frozen=True)
class _ArmPoses:
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
    def from_steps(cls, steps: pd.DataFrame, scenario: Scenario, *, source: Path) -> _ArmPoses:
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


class _Drawing:
    """The scene's messages for one arm scenario; what never changes is built once."""

    def __init__(self, scenario: Scenario, poses: _ArmPoses | None = None) -> None:
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
