"""The default blueprint saved with a recording: how the viewer lays out its views."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import rerun.blueprint as rrb

from rsstp_replay._viewer_chunks import TIMELINE
from rsstp_sim.scenario import Scenario

__all__ = ["default_blueprint"]

_GRAPH_MARGIN = 60.0
"""Room around the outermost states in the graph view (points: label nodes stick out)."""


def default_blueprint(
    scenario: Scenario,
    *,
    first: int,
    last: int,
    positions: Mapping[int, tuple[float, float]],
) -> rrb.Blueprint:
    """The 2D world and the model graph side by side; below them the plots (sensation and
    feedback, obstacle distances, model size, their time axes linked and showing steps
    ``first .. last``) and the audit log; the ``step`` timeline selected.

    The world view frames the arm's reach and the obstacles; the graph view frames every
    state of ``positions`` (the viewer's coordinates, y down).
    """
    reach = 1.1 * scenario.total_length
    for obstacle in scenario.obstacles:
        reach = max(reach, 1.05 * (float(np.hypot(*obstacle.center)) + obstacle.radius))
    xs = [x for x, _ in positions.values()] or [0.0]
    ys = [y for _, y in positions.values()] or [0.0]
    steps = rrb.TimeRange(
        start=rrb.TimeRangeBoundary.absolute(seq=first),
        end=rrb.TimeRangeBoundary.absolute(seq=max(last, first + 1)),
    )

    def plot(name: str, origin: str) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(
            name=name,
            origin=origin,
            axis_x=rrb.TimeAxis(link="LinkToGlobal", view_range=steps),
        )

    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(
                rrb.Spatial2DView(
                    name="World",
                    origin="/",
                    contents=["+ /world/**"],
                    visual_bounds=rrb.VisualBounds2D(
                        x_range=[-reach, reach], y_range=[-reach, reach]
                    ),
                ),
                rrb.GraphView(
                    name="Model",
                    origin="/model",
                    visual_bounds=rrb.VisualBounds2D(
                        x_range=[min(xs) - _GRAPH_MARGIN, max(xs) + _GRAPH_MARGIN],
                        y_range=[min(ys) - _GRAPH_MARGIN, max(ys) + _GRAPH_MARGIN],
                    ),
                ),
            ),
            rrb.Horizontal(
                plot("Sensation and feedback", "/plots/agent"),
                plot("Obstacle distances", "/plots/distance"),
                plot("Model size", "/plots/model"),
                rrb.TextLogView(name="Audit log", origin="/log"),
                column_shares=[2, 2, 1, 3],
            ),
            row_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=TIMELINE, state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )
