"""Streaming recordings to Rerun, tested without a viewer: save to ``.rrd``, read the file back
with Rerun's own reader (``rerun.chunk``), and check paths, rows and values."""

from __future__ import annotations

import re
import shutil
import subprocess
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rerun as rr
from fakes import RandomRefiner
from rerun.chunk import Chunk, RrdReader

from rsstp_replay import _viewer_layout, viewer
from rsstp_replay._viewer_model import graph_columns, graph_frame
from rsstp_replay.errors import ReplayError, StepOutOfRange
from rsstp_replay.recording import Recording, open_recording
from rsstp_replay.viewer import ViewerWarning, graph_positions, render_graph, view
from rsstp_sim.recording import record
from rsstp_sim.scenario import load_scenario

REFERENCE = Path(__file__).parents[2] / "recordings" / "three-joint-random.mcap"
PER_STEP = (
    "world/arm",
    "world/joints",
    "world/sensor",
    "world/blocked",
    "model/state",
    "plots/agent/sensation",
    "plots/agent/feedback",
    *(f"plots/distance/link{k}/obstacle{j}" for k in range(3) for j in range(2)),
)


class Rrd:
    """An ``.rrd`` file read back: the recording's chunks by entity path (no leading slash)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        reader = RrdReader(path)
        self.blueprints = reader.blueprints()
        self.temporal: dict[str, list[Chunk]] = defaultdict(list)
        self.static: dict[str, list[Chunk]] = defaultdict(list)
        for chunk in reader.stream().to_chunks():
            where = self.static if chunk.is_static else self.temporal
            where[chunk.entity_path.lstrip("/")].append(chunk)

    def column(self, path: str, component: str) -> list[tuple[int, Any]]:
        """``(step, value)`` of every row holding ``component`` at ``path``, by step."""
        found: list[tuple[int, Any]] = []
        for chunk in self.temporal[path]:
            batch = chunk.to_record_batch()
            if component in batch.schema.names:
                steps = batch.column("step").to_pylist()
                found += zip(steps, batch.column(component).to_pylist(), strict=True)
        return sorted(found, key=lambda row: row[0])

    def at(self, path: str, component: str, step: int) -> Any:
        """The value of ``component`` at ``path`` in force at ``step`` (latest at or before)."""
        rows = [value for at, value in self.column(path, component) if at <= step]
        return rows[-1]


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Recording, Rrd]]:
    """The 10,000-step reference recording (random actions among two obstacles), viewed."""
    out = tmp_path_factory.mktemp("viewer") / "reference.rrd"
    with open_recording(REFERENCE) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        yield recording, Rrd(out)


@pytest.fixture(scope="module")
def refined(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Recording, Rrd]]:
    """400 steps of a strategy that splits, merges, adds and deletes: many model versions."""
    folder = tmp_path_factory.mktemp("viewer")
    record(
        folder / "refined.mcap",
        load_scenario("three-joint"),
        RandomRefiner(split=0.05, max_states=5),
        steps=400,
        seed=7,
    )
    with open_recording(folder / "refined.mcap") as recording:
        view(
            recording,
            save=folder / "refined.rrd",
            spawn=False,
            serve_web=False,
            start=None,
            end=None,
        )
        yield recording, Rrd(folder / "refined.rrd")


# ------------------------------------------------------------------ paths and row counts


def test_entity_paths_and_rows_match_the_recording(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    n = recording.n_steps + 1
    assert set(rrd.temporal) == {
        *PER_STEP,
        "model/graph",
        "plots/model/states",
        "plots/model/transitions",
        "log/audit",
    }
    assert {"world", "world/obstacles", "world/feedback_points"} <= set(rrd.static)
    first = {
        "world/arm": "LineStrips2D:strips",
        "world/joints": "Points2D:positions",
        "world/sensor": "LineStrips2D:strips",
        "world/blocked": "Points2D:positions",
        "model/state": "GraphNodes:node_ids",
    }
    for path in PER_STEP:
        component = first.get(path, "Scalars:scalars")
        steps = [step for step, _ in rrd.column(path, component)]
        assert steps == list(range(n)), path
    versions = recording.model_versions()
    assert len(rrd.column("model/graph", "GraphNodes:node_ids")) == len(versions)


def test_model_versions_each_have_a_row(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    versions = recording.model_versions()
    assert len(versions) > 50
    nodes = rrd.column("model/graph", "GraphNodes:node_ids")
    edges = rrd.column("model/graph", "GraphEdges:edges")
    assert [step for step, _ in nodes] == [record.step for record in versions]
    assert [step for step, _ in edges] == [record.step for record in versions]
    sizes = rrd.column("plots/model/states", "Scalars:scalars")
    assert [step for step, _ in sizes][:-1] == [record.step for record in versions]
    assert sizes[-1] == (recording.n_steps, [float(len(versions[-1].states))])


# ---------------------------------------------------------------------------- the world


def test_joint_positions_at_a_step(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    table = recording.steps()
    for step in (0, 1234, recording.n_steps):
        expected = [
            [table.at[step, f"joint{k}_x"], table.at[step, f"joint{k}_y"]] for k in range(4)
        ]
        strip = rrd.at("world/arm", "LineStrips2D:strips", step)
        np.testing.assert_allclose(strip, [expected], rtol=1e-6, atol=1e-6)  # float32 in Rerun
        joints = rrd.at("world/joints", "Points2D:positions", step)
        np.testing.assert_allclose(joints, expected, rtol=1e-6, atol=1e-6)


def test_sensor_segments_run_from_each_tip_to_the_nearest_point(
    reference: tuple[Recording, Rrd],
) -> None:
    recording, rrd = reference
    table = recording.steps()
    obstacles = recording.scenario.obstacles
    for step in (5, 4321):
        segments = np.array(rrd.at("world/sensor", "LineStrips2D:strips", step))
        assert segments.shape == (3 * 2, 2, 2)
        for k in range(3):
            tip = [table.at[step, f"joint{k + 1}_x"], table.at[step, f"joint{k + 1}_y"]]
            for j, obstacle in enumerate(obstacles):
                start, end = segments[k * len(obstacles) + j]
                np.testing.assert_allclose(start, tip, rtol=1e-6, atol=1e-6)
                on_circle = np.hypot(*(end - np.array(obstacle.center)))
                assert on_circle == pytest.approx(obstacle.radius, rel=1e-5)
                assert np.hypot(*(end - start)) == pytest.approx(
                    table.at[step, f"dist_{k}_{j}"], rel=1e-5, abs=1e-5
                )


def test_blocked_moves_are_marked(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    table = recording.steps()
    blocked = np.flatnonzero(table["blocked"].to_numpy())
    free = np.flatnonzero(~table["blocked"].to_numpy())
    assert len(blocked) > 100
    labels = dict(rrd.column("world/blocked", "Points2D:labels"))
    points = dict(rrd.column("world/blocked", "Points2D:positions"))
    colors = dict(rrd.column("world/arm", "LineStrips2D:colors"))
    red = colors[int(blocked[0])]
    for step in blocked[:20].tolist():
        assert labels[step] == [f"blocked: {table.at[step, 'blocked_by']}"]
        np.testing.assert_allclose(
            points[step], [[table.at[step, "joint3_x"], table.at[step, "joint3_y"]]], rtol=1e-6
        )
        assert colors[step] == red
    for step in free[:20].tolist():
        assert points[step] == []
        assert colors[step] != red


def test_obstacles_and_feedback_points_are_static(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    batch = rrd.static["world/obstacles"][0].to_record_batch()
    centers = batch.column("Ellipses2D:centers").to_pylist()[0]
    np.testing.assert_allclose(centers, [o.center for o in recording.scenario.obstacles])
    batch = rrd.static["world/feedback_points"][0].to_record_batch()
    np.testing.assert_allclose(
        batch.column("Points2D:positions").to_pylist()[0], recording.scenario.feedback_points
    )


# ---------------------------------------------------------------------------- the model


def test_graph_nodes_at_a_version_are_its_states_and_cells(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    versions = recording.model_versions()
    nodes = rrd.column("model/graph", "GraphNodes:node_ids")
    labels = rrd.column("model/graph", "GraphNodes:labels")
    edges = rrd.column("model/graph", "GraphEdges:edges")
    for index in (0, len(versions) // 2, len(versions) - 1):
        record_ = versions[index]
        ids = nodes[index][1]
        assert [node for node in ids if ">" not in node] == [str(s) for s in record_.states]
        cells: dict[str, list[int]] = defaultdict(list)
        for s, a, t in record_.transitions:
            cells[f"{s}>{t}"].append(a)
        shown = dict(zip(ids, labels[index][1], strict=True))
        assert {node for node in ids if ">" in node} == set(cells)
        for node, actions in cells.items():
            assert shown[node] == ",".join(map(str, sorted(actions)))
        expected_edges = set()
        for node in cells:
            s, t = node.split(">")
            expected_edges |= {(s, node), (node, t)}
        assert {(e["first"], e["second"]) for e in edges[index][1]} == expected_edges


def test_state_positions_never_move(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    layout = graph_positions(recording.model_versions())
    seen: dict[str, list[float]] = {}
    for (_, ids), (_, places) in zip(
        rrd.column("model/graph", "GraphNodes:node_ids"),
        rrd.column("model/graph", "GraphNodes:positions"),
        strict=True,
    ):
        for node, place in zip(ids, places, strict=True):
            assert seen.setdefault(node, place) == place
            if ">" not in node:  # the viewer's frame is Graphviz's with y down
                x, y = layout[int(node)]
                assert place == pytest.approx([x, -y], abs=1e-3)


def test_current_state_at_every_step(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    states = recording.steps()["internal_state"].tolist()
    current = rrd.column("model/state", "GraphNodes:node_ids")
    assert [ids for _, ids in current] == [[str(s)] for s in states]


def test_vectorised_graph_matches_the_per_version_definition(
    refined: tuple[Recording, Rrd],
) -> None:
    recording, _ = refined
    versions = recording.model_versions()
    positions = {s: (x, -y) for s, (x, y) in graph_positions(versions).items()}
    columns = graph_columns(versions, positions)
    node_end, edge_end = np.cumsum(columns.node_counts), np.cumsum(columns.edge_counts)
    for index, record_ in enumerate(versions):
        frame = graph_frame(record_.states, record_.transitions, positions)
        nodes = slice(node_end[index] - columns.node_counts[index], node_end[index])
        edges = slice(edge_end[index] - columns.edge_counts[index], edge_end[index])
        assert columns.node_ids[nodes].tolist() == frame.node_ids
        assert columns.labels[nodes].tolist() == frame.labels
        assert columns.positions[nodes].tolist() == [list(p) for p in frame.positions]
        assert [tuple(edge) for edge in columns.edges[edges].tolist()] == frame.edges


# ------------------------------------------------------------------ plots and the audit log


def test_series_values(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    table = recording.steps()
    feedback = rrd.column("plots/agent/feedback", "Scalars:scalars")
    assert [value[0] for _, value in feedback] == table["feedback"].tolist()
    distance = rrd.column("plots/distance/link2/obstacle1", "Scalars:scalars")
    assert [value[0] for _, value in distance] == table["dist_2_1"].tolist()


def test_audit_log_lines_at_their_steps(
    reference: tuple[Recording, Rrd], refined: tuple[Recording, Rrd]
) -> None:
    recording, rrd = reference
    lines = [(step, text) for step, [text] in rrd.column("log/audit", "TextLog:text")]
    levels = [level for _, [level] in rrd.column("log/audit", "TextLog:level")]
    contradictions = [
        (line, level)
        for line, level in zip(lines, levels, strict=True)
        if line[1].startswith("contradiction")
    ]
    assert contradictions and {level for _, level in contradictions} == {"WARN"}
    first_line = contradictions[0][0][1]
    assert re.match(
        r"contradiction: state 0: after steps \d+ and \d+ \(both in state 0\)", first_line
    )
    assert (0, lines[0][1]) == lines[0] and lines[0][1].startswith("deterministic")

    recording, rrd = refined
    logged = {
        (step, text.split(" (")[0]) for step, [text] in rrd.column("log/audit", "TextLog:text")
    }
    for record_ in recording.model_versions():
        for operation in record_.operations:
            if operation.kind == "split" and operation.changed:
                line = f"split: state {operation.args[0]} -> new state {operation.result}"
                assert (record_.step, line) in logged
            if operation.kind == "merge" and operation.changed:
                line = f"merge: state {operation.args[1]} into state {operation.args[0]}"
                assert (record_.step, line) in logged


# ---------------------------------------------------------------- blueprint, range, file


def test_the_blueprint_is_saved_with_the_step_timeline(reference: tuple[Recording, Rrd]) -> None:
    _, rrd = reference
    assert len(rrd.blueprints) == 1
    chunks = RrdReader(rrd.path).stream(store=rrd.blueprints[0]).to_chunks()
    panel = [c for c in chunks if c.entity_path == "/time_panel"]
    values = [
        value
        for c in panel
        for column in c.to_record_batch().columns
        for value in column.to_pylist()
    ]
    assert ["step"] in values


def test_a_step_range(refined: tuple[Recording, Rrd], tmp_path: Path) -> None:
    recording, _ = refined
    out = tmp_path / "range.rrd"
    result = view(recording, save=out, spawn=False, serve_web=False, start=100, end=250)
    assert (result.summary.first_step, result.summary.last_step) == (100, 250)
    rrd = Rrd(out)
    assert [s for s, _ in rrd.column("world/arm", "LineStrips2D:strips")] == list(range(100, 251))
    graph = rrd.column("model/graph", "GraphNodes:node_ids")
    versions = [r for r in recording.model_versions() if r.step <= 250]
    in_force = [r for r in versions if r.step <= 100][-1]
    assert graph[0][0] == 100
    assert [n for n in graph[0][1] if ">" not in n] == [str(s) for s in in_force.states]
    assert [s for s, _ in graph[1:]] == [r.step for r in versions if r.step > 100]
    assert all(100 <= step <= 250 for step, _ in rrd.column("log/audit", "TextLog:text"))
    assert "steps 100..250" in result.to_text()


def test_bad_arguments_raise(refined: tuple[Recording, Rrd], tmp_path: Path) -> None:
    recording, _ = refined
    with pytest.raises(StepOutOfRange, match="the end step 401 is out of range: the recording"):
        view(recording, save=tmp_path / "x.rrd", spawn=False, serve_web=False, start=0, end=401)
    with pytest.raises(StepOutOfRange, match="no step from 9 to 3: the start is after the end"):
        view(recording, save=tmp_path / "x.rrd", spawn=False, serve_web=False, start=9, end=3)
    with pytest.raises(ReplayError, match="the folder .*missing does not exist"):
        view(
            recording,
            save=tmp_path / "missing" / "x.rrd",
            spawn=False,
            serve_web=False,
            start=None,
            end=None,
        )
    assert not (tmp_path / "x.rrd").exists()


@pytest.mark.skipif(shutil.which("rerun") is None, reason="the rerun CLI is not installed")
def test_rerun_verifies_the_files(
    reference: tuple[Recording, Rrd], refined: tuple[Recording, Rrd]
) -> None:
    for _, rrd in (reference, refined):
        done = subprocess.run(
            ["rerun", "rrd", "verify", str(rrd.path)],
            capture_output=True,
            text=True,
            timeout=120,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        assert "1 file verified without error" in done.stdout + done.stderr


# -------------------------------------------------------------- leniency and the picture


def test_a_viewer_that_cannot_be_spawned_is_a_warning(
    refined: tuple[Recording, Rrd], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    recording, _ = refined

    def no_viewer(self: rr.RecordingStream, **_: object) -> None:
        raise RuntimeError("no display")

    monkeypatch.setattr(rr.RecordingStream, "spawn", no_viewer)
    with pytest.warns(ViewerWarning, match="could not spawn a Rerun viewer: no display"):
        result = view(
            recording, save=tmp_path / "s.rrd", spawn=True, serve_web=False, start=0, end=10
        )
    assert not result.spawned and result.saved == tmp_path / "s.rrd"
    assert len(Rrd(tmp_path / "s.rrd").column("world/arm", "LineStrips2D:strips")) == 11


def test_without_graphviz_the_states_go_on_a_circle(
    refined: tuple[Recording, Rrd], monkeypatch: pytest.MonkeyPatch
) -> None:
    recording, _ = refined
    monkeypatch.setattr(_viewer_layout.shutil, "which", lambda _: None)
    with pytest.warns(ViewerWarning, match="'dot' not found"):
        positions = graph_positions(recording.model_versions())
    states = {s for r in recording.model_versions() for s in r.states}
    assert set(positions) == states
    radii = {round(float(np.hypot(*p)), 1) for p in positions.values()}
    assert len(radii) == 1


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz is not installed")
def test_render_graph_uses_the_viewer_positions(
    refined: tuple[Recording, Rrd], tmp_path: Path
) -> None:
    recording, rrd = refined
    step = 200
    model = recording.model_at(step)
    source = render_graph(recording, step, tmp_path / "model.dot").read_text()
    places = {
        int(m[1]): (float(m[2]), float(m[3]))
        for m in re.finditer(r'\t(\d+) \[.*?pos="([-\d.]+),([-\d.]+)!"', source)
    }
    assert set(places) == set(model.states)
    nodes = rrd.at("model/graph", "GraphNodes:node_ids", step)
    shown = rrd.at("model/graph", "GraphNodes:positions", step)
    for node, (x, y) in zip(nodes, shown, strict=True):
        if ">" not in node:
            assert places[int(node)] == pytest.approx((x, -y), abs=0.01)
    svg = render_graph(recording, step, tmp_path / "model.svg")
    assert svg.read_text().startswith("<?xml")
    with pytest.raises(StepOutOfRange):
        render_graph(recording, 401, tmp_path / "late.svg")


def test_entity_paths_are_documented() -> None:
    documented = (Path(__file__).parents[2] / "docs" / "viewer.md").read_text()
    for path in viewer.ENTITY_PATHS:
        assert f"`{path}`" in documented
