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

That is the arm's scene (:mod:`rsstp_replay.export._foxglove_arm`); a rover's recording gives
the same topics with the rover's entities and frames
(:mod:`rsstp_replay.export._foxglove_rover`): its room on the static topic, the robot on
``/rsstp/scene``, ``world -> robot`` on the transforms. Each body draws itself through its
:class:`~rsstp_replay.export._foxglove_body.BodyScene`, registered by a line.

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
import pandas as pd
from foxglove.messages import (
    FrameTransforms,
    Log,
    LogLevel,
    SceneUpdate,
)

from rsstp_format.schemas import STEP_NS
from rsstp_replay.export._foxglove_body import BodyDrawing, BodyPoses, body_scene
from rsstp_replay.export._foxglove_shapes import timestamp
from rsstp_replay.export._foxglove_stamps import PoseMessages
from rsstp_sim import __version__
from rsstp_sim.files import written_whole
from rsstp_sim.recording.chunks import ChunkedWriter, Message
from rsstp_sim.recording.output import SideFileWriter
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
_WARNING_KINDS = frozenset({"blocked", "contradiction"})

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
    body = body_scene(scenario.body)
    steps = recording.steps(geometry=body.needs_geometry)
    n_steps = len(steps)
    poses = body.poses(steps, scenario, source=recording.path)
    draw = body.drawing(scenario, poses)
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
    draw: BodyDrawing,
    poses: BodyPoses,
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
