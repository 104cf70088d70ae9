"""The default blueprint saved with a recording: how the viewer lays out its views."""

from __future__ import annotations

import rerun.blueprint as rrb

from rsstp_replay.viewer._chunks import TIMELINE
from rsstp_replay.viewer._map import joint_grid, map_bounds
from rsstp_replay.viewer._world import ViewFrame, body_view
from rsstp_sim.scenario import AnyScenario

__all__ = ["ViewFrame", "default_blueprint", "view_frame", "view_reach"]


def view_reach(scenario: AnyScenario) -> float:
    """Half the side of the square both 2D views frame (:func:`view_frame`)."""
    return view_frame(scenario).half


def view_frame(scenario: AnyScenario) -> ViewFrame:
    """The square both 2D views frame, as the scenario's body frames it."""
    return body_view(scenario.body).frame(scenario)


def default_blueprint(
    scenario: AnyScenario, *, first: int, last: int, with_map: bool = False
) -> rrb.Blueprint:
    """Two 2D views side by side, both framing the arm's reach and the obstacles: the world
    (the arm, obstacles, feedback points, sensor, blocked moves) and the model drawn on the
    world (its states where the arm was, its transitions, the current state, over the
    obstacles); ``with_map``, a third: the model map of the joint space
    (:mod:`~rsstp_replay.viewer._map`); below them the plots (sensation and feedback,
    obstacle distances, model size, their time axes linked and showing steps ``first ..
    last``) and the audit log; the ``step`` timeline selected."""
    (cx, cy), half, _ = view_frame(scenario)
    # The world's entity mirrors y (Rerun draws y downwards): the bounds are the mirror's.
    bounds = rrb.VisualBounds2D(x_range=[cx - half, cx + half], y_range=[-cy - half, -cy + half])
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

    views: list[rrb.View] = [
        rrb.Spatial2DView(
            name="World",
            origin="/",
            contents=["+ /world/**", "- /world/model/**"],
            visual_bounds=bounds,
        ),
        rrb.Spatial2DView(
            name="Model on the world",
            origin="/",
            contents=[
                "+ /world",
                "+ /world/obstacles",
                "+ /world/feedback_points",
                "+ /world/model/**",
            ],
            visual_bounds=bounds,
        ),
    ]
    grid = joint_grid(scenario)
    if with_map and grid is not None:
        # Origin "/": the map's own y-up transform applies (a view's origin is its frame).
        x0, x1, y0, y1 = map_bounds(grid)
        views.append(
            rrb.Spatial2DView(
                name="Model map (joint space)",
                origin="/",
                contents=["+ /map/**"],
                visual_bounds=rrb.VisualBounds2D(x_range=[x0, x1], y_range=[-y1, -y0]),
            )
        )
    return rrb.Blueprint(
        rrb.Vertical(
            rrb.Horizontal(*views),
            rrb.Horizontal(
                plot("Sensation and feedback", "/plots/agent"),
                plot("Obstacle distances", "/plots/distance"),
                plot("Model size", "/plots/model"),
                plot("Strategy phase", "/plots/strategy"),
                rrb.TextLogView(name="Audit log", origin="/log"),
                column_shares=[2, 2, 1, 1, 3],
            ),
            row_shares=[3, 2],
        ),
        rrb.TimePanel(timeline=TIMELINE, state="collapsed"),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
    )
