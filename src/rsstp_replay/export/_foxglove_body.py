"""What the Foxglove scene (:mod:`rsstp_replay.export.foxglove`) asks of a body: its poses
where it moved, and the drawing of its world and of each pose. One module a body, registered
by a line in :data:`BODY_SCENES`."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any, Protocol

import pandas as pd
from foxglove.messages import FrameTransforms, SceneUpdate

from rsstp_sim.bodies import registered

__all__ = ["BODY_SCENES", "BodyDrawing", "BodyPoses", "BodyScene", "body_scene"]


class BodyPoses(Protocol):
    """The body at step 0 and at every step where it moved."""

    def __len__(self) -> int: ...
    def rows(self) -> Iterator[tuple[int, int]]:
        """``(step, pose code)`` of every row as Python numbers."""


class BodyDrawing(Protocol):
    """The scene's messages of one scenario's body; what never changes is built once."""

    def static_scene(self) -> SceneUpdate:
        """The world that does not move (``/rsstp/scene/static``), at step 0."""

    def fixed_transforms(self) -> FrameTransforms:
        """The frames that do not move, at step 0."""

    def body(self, row: int) -> SceneUpdate:
        """The body at row ``row`` of the poses (``/rsstp/scene``), without a timestamp."""

    def frames(self, row: int) -> FrameTransforms:
        """The body's frames at row ``row`` of the poses, without a timestamp."""


class BodyScene(Protocol):
    """How one body is drawn in a Foxglove scene."""

    needs_geometry: bool
    """Whether its poses are read from the steps table's geometry columns."""

    def poses(self, steps: pd.DataFrame, scenario: Any, *, source: Path) -> BodyPoses:
        """Its poses where it moved, from the recording's steps table (``source``: the
        recording's path, for errors)."""

    def drawing(self, scenario: Any, poses: Any) -> BodyDrawing:
        """The drawing of ``scenario``'s body at ``poses``."""


BODY_SCENES: dict[str, str] = {
    "arm": "rsstp_replay.export._foxglove_arm:ARM_SCENE",
    "rover": "rsstp_replay.export._foxglove_rover:ROVER_SCENE",
}
"""Body name -> ``module:attribute`` of its :class:`BodyScene` (one line a body)."""


def body_scene(name: str) -> BodyScene:
    """The registered scene of body ``name`` (KeyError for none)."""
    scene: BodyScene = registered(BODY_SCENES, name)
    return scene
