"""The world for the viewer: a body in its world, in the plane.

Everything here is logged with ``send_columns``, a row only at the steps where what an entity
shows changes; what does not move (obstacles, walls, the feedback) is logged as static data.
Coordinates are the recording's, in its length unit, in the world frame (x right, y up):
the ``world`` entity carries a static transform that mirrors y, because Rerun's 2D views
draw y downwards. A body draws itself through its :class:`BodyView`
(:data:`BODY_VIEWS`: the arm's in :mod:`~rsstp_replay.viewer._arm`, the rover's in
:mod:`~rsstp_replay.viewer._rover`); what every body shares (obstacles, the blocked-move
marker) is here.
"""

from __future__ import annotations

from typing import Any, NamedTuple, Protocol

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_replay.reader import blocker_texts
from rsstp_replay.viewer._chunks import send_rows
from rsstp_sim import palette
from rsstp_sim.bodies import registered

__all__ = [
    "BLOCKED",
    "BODY_VIEWS",
    "FEEDBACK_POINTS",
    "OBSTACLES",
    "WORLD",
    "BodyView",
    "ViewFrame",
    "body_view",
    "log_blocked",
    "log_blocked_style",
    "log_obstacles",
]

WORLD = "world"
OBSTACLES = "world/obstacles"
FEEDBACK_POINTS = "world/feedback_points"
BLOCKED = "world/blocked"

_Floats = npt.NDArray[np.float64]


class ViewFrame(NamedTuple):
    """The square both 2D views frame: its centre and half its side (world frame, length
    units), and the length that sizes what is drawn on it (offsets, label room)."""

    center: tuple[float, float]
    half: float
    scale: float


class BodyView(Protocol):
    """How the viewer draws one body (:data:`BODY_VIEWS`)."""

    paths: tuple[str, ...]
    """The entity paths it writes, besides the shared ones."""

    def frame(self, scenario: Any) -> ViewFrame:
        """The square the 2D views frame."""

    def log_static(self, stream: rr.RecordingStream, scenario: Any) -> None:
        """The y-up transform, the body's world (static) and the styles of its entities."""

    def log_steps(
        self, stream: rr.RecordingStream, steps: pd.DataFrame, scenario: Any, *, sensor: bool
    ) -> dict[str, int]:
        """The body over ``steps`` (a steps table with its geometry), a row only where
        something changed, and its blocked moves (``sensor``: what a long run's overview
        leaves out). Returns rows per entity path."""

    def distance_series(self, scenario: Any) -> list[tuple[str, str]]:
        """The steps table's distance columns to plot, each with its series name."""


BODY_VIEWS: dict[str, str] = {
    "arm": "rsstp_replay.viewer._arm:ARM",
    "rover": "rsstp_replay.viewer._rover:ROVER",
}
"""Body name -> ``module:attribute`` of its :class:`BodyView` (one line a body)."""


def body_view(name: str) -> BodyView:
    """The registered view of body ``name`` (KeyError for none)."""
    view: BodyView = registered(BODY_VIEWS, name)
    return view


def log_obstacles(stream: rr.RecordingStream, scenario: Any) -> None:
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


def log_blocked_style(stream: rr.RecordingStream) -> None:
    """The blocked-move marker's style, static: every body's."""
    stream.log(
        BLOCKED,
        rr.Points2D.from_fields(
            radii=rr.Radius.ui_points(8.0), colors=palette.ARM_BLOCKED, draw_order=7.0
        ),
        static=True,
    )


def log_blocked(stream: rr.RecordingStream, steps: pd.DataFrame, places: _Floats) -> dict[str, int]:
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
