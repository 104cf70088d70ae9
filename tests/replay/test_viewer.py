"""Streaming recordings to Rerun, tested without a viewer: save to ``.rrd``, read the file back
with Rerun's own reader (``rerun.chunk``), and check paths, rows and values."""

from __future__ import annotations

import ctypes
import json
import re
import shutil
import subprocess
import sys
from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import rerun as rr
from fakes import RandomRefiner
from rerun.chunk import Chunk, RrdReader

from rsstp_replay import viewer
from rsstp_replay.audits.consistency import audit_consistency, audit_consistency_by_version
from rsstp_replay.audits.contract import version_index
from rsstp_replay.audits.truth import audit_truth
from rsstp_replay.errors import ReplayError, StepOutOfRange
from rsstp_replay.reader.recording import Recording, open_recording
from rsstp_replay.viewer import ViewerWarning, graph_positions, render_graph, view
from rsstp_replay.viewer import _layout as _viewer_layout
from rsstp_replay.viewer._model import (
    ACTION_COLORS,
    LABEL_ROOM,
    LOOP_LENGTH,
    POSE_LINES,
    state_places,
)
from rsstp_sim import palette
from rsstp_sim.recording import record
from rsstp_sim.scenario import load_scenario
from rsstp_sim.truth import compute_truth
from waiting import HANG_S

REFERENCE = Path(__file__).parents[2] / "recordings" / "three-joint-random.mcap"
LEARNER = Path(__file__).parents[2] / "recordings" / "two-joint-30-learner.mcap"


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

    def at(self, path: str, component: str, step: int, default: Any = None) -> Any:
        """The value of ``component`` at ``path`` in force at ``step`` (latest at or before;
        ``default`` when there is none)."""
        rows = [value for at, value in self.column(path, component) if at <= step]
        return rows[-1] if rows else default

    def cleared_at(self, path: str) -> list[int]:
        """The steps of the ``Clear`` rows logged at ``path``."""
        return [step for step, _ in self.column(path, "Clear:is_recursive")]


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


def _changes(values: np.ndarray) -> list[int]:
    """The rows where a value differs from the row before, with the first and the last."""
    values = values.reshape(len(values), -1)
    differs = np.r_[True, (values[1:] != values[:-1]).any(axis=1)]
    differs[-1] = True
    return np.flatnonzero(differs).tolist()


def test_entity_paths_and_rows_match_the_recording(reference: tuple[Recording, Rrd]) -> None:
    """Rows only where something changed: the arm when it moved or its blocked flag changed,
    each series when its value changed (and at the first and last step), the one state of
    the random strategy's model once, the current state once (the joint-space map: its own
    tests, test_viewer_map.py)."""
    recording, rrd = reference
    table = recording.steps()
    assert {path for path in rrd.temporal if not path.startswith("map/")} == {
        "world/arm",
        "world/sensor",
        "world/blocked",
        "world/model/current",
        "world/model/state/0",
        "plots/agent/sensation",
        "plots/agent/feedback",
        "plots/distance",
        "plots/model/states",
        "plots/model/transitions",
        "log/audit",
    }
    assert {"world", "world/obstacles", "world/feedback_points"} <= set(rrd.static)
    positions = table[[f"joint{k}_{a}" for k in range(4) for a in "xy"]].to_numpy()
    blocked = table["blocked"].to_numpy()
    moved = np.r_[True, (positions[1:] != positions[:-1]).any(axis=1)]
    arm = np.flatnonzero(moved | np.r_[True, blocked[1:] != blocked[:-1]]).tolist()
    assert [step for step, _ in rrd.column("world/arm", "LineStrips2D:strips")] == arm
    assert len(arm) < len(table)  # blocked moves do not move the arm
    for path, columns in (
        ("plots/agent/sensation", ["sensation"]),
        ("plots/agent/feedback", ["feedback"]),
        ("plots/distance", [f"dist_{k}_{j}" for k in range(3) for j in range(2)]),
    ):
        expected = _changes(table[columns].to_numpy(np.float64))
        assert [step for step, _ in rrd.column(path, "Scalars:scalars")] == expected, path
    assert [step for step, _ in rrd.column("world/model/current", "Points2D:positions")] == [0]
    assert [step for step, _ in rrd.column("world/model/state/0", "Points2D:positions")] == [0]


def test_a_series_of_too_many_changes_keeps_each_curves_extremes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Over its row budget, a series keeps (besides its first and last row) the steps where
    each curve has its least and greatest value in each equal run of steps, every one with
    its value; below the budget nothing is thinned."""
    monkeypatch.setattr(viewer.plots_part, "SERIES_MAX_ROWS", 240)
    out = tmp_path / "thin.rrd"
    with open_recording(REFERENCE) as recording:
        result = view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        table = recording.steps()
    rrd = Rrd(out)
    assert "plots/distance" in result.summary.thinned
    columns = [f"dist_{k}_{j}" for k in range(3) for j in range(2)]
    values = table[columns].to_numpy(np.float64)
    changes = _changes(values)
    buckets = 240 // (2 * len(columns))
    span = changes[-1] - changes[0] + 1
    width = -(-span // buckets)
    expected = {changes[0], changes[-1]}
    for begin in range(changes[0], changes[-1] + 1, width):
        inside = [t for t in changes if begin <= t < begin + width]
        for c in range(len(columns)):
            # the earliest step of the least value, the latest of the greatest
            low = min(inside, key=lambda t: (values[t, c], t))
            high = max(inside, key=lambda t: (values[t, c], t))
            expected |= {low, high}
    rows = rrd.column("plots/distance", "Scalars:scalars")
    assert [step for step, _ in rows] == sorted(expected)
    for step, scalars in rows:
        np.testing.assert_array_equal(scalars, values[step])
    # The sensation changes fewer times than the budget: every change is kept.
    expected_sensation = _changes(table[["sensation"]].to_numpy(np.float64))
    assert len(expected_sensation) <= 240
    sensation = [step for step, _ in rrd.column("plots/agent/sensation", "Scalars:scalars")]
    assert sensation == expected_sensation
    assert "plots/agent/sensation" not in result.summary.thinned


def test_a_long_window_is_an_overview_of_every_kth_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Over OVERVIEW_MAX_STEPS steps shown, the arm and the current state are shown at steps
    0, k, 2k, ... and the last (rows where they changed between those), the sensor is left
    out, and the log says so at the first step; the series keep every change."""
    monkeypatch.setattr(viewer, "OVERVIEW_MAX_STEPS", 2_000)
    out = tmp_path / "overview.rrd"
    with open_recording(REFERENCE) as recording:
        result = view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        table = recording.steps()
    rrd = Rrd(out)
    k = 6  # 10,001 steps in at most 2,000 rows each
    assert result.summary.every == k
    shown = sorted({*range(0, len(table), k), len(table) - 1})
    positions = table[[f"joint{j}_{a}" for j in range(4) for a in "xy"]].to_numpy()[shown]
    blocked = table["blocked"].to_numpy()[shown]
    changed = [
        shown[i]
        for i in range(len(shown))
        if i == 0 or (positions[i] != positions[i - 1]).any() or blocked[i] != blocked[i - 1]
    ]
    assert [step for step, _ in rrd.column("world/arm", "LineStrips2D:strips")] == changed
    assert "world/sensor" not in rrd.temporal
    [(step, text)] = [
        (step, text)
        for step, [text] in rrd.column("log/audit", "TextLog:text")
        if "overview" in text
    ]
    assert step == 0 and "one step in 6" in text
    assert "one step in 6" in result.to_text()
    feedback = [step for step, _ in rrd.column("plots/agent/feedback", "Scalars:scalars")]
    assert feedback == _changes(table[["feedback"]].to_numpy(np.float64))


def test_the_sensation_is_a_step_plot_that_never_averages(
    reference: tuple[Recording, Rrd],
) -> None:
    _, rrd = reference
    batch = rrd.static["plots/agent/sensation"][0].to_record_batch()
    step_after = rr.components.InterpolationMode.StepAfter.value
    min_max = rr.components.AggregationPolicy.MinMax.value
    assert batch.column("SeriesLines:interpolation_mode").to_pylist() == [[step_after]]
    assert batch.column("SeriesLines:aggregation_policy").to_pylist() == [[min_max]]
    distances = rrd.static["plots/distance"][0].to_record_batch()
    assert distances.column("SeriesLines:names").to_pylist()[0] == [
        f"tip of link {k} to obstacle {j}" for k in range(3) for j in range(2)
    ]


def test_model_versions_each_have_a_size_row(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    versions = recording.model_versions()
    assert len(versions) > 50
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
        joints = rrd.at("world/arm", "Points2D:positions", step)
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
    red = None
    for step in blocked[:20].tolist():
        kind = table.at[step, "blocked_kind"]
        label = {
            "fold": "fold joint {blocked_joint}",
            "obstacle": "obstacle {blocked_obstacle} link {blocked_link}",
            "links": "links {blocked_link_i} {blocked_link_j}",
        }[kind].format(**table.loc[step].to_dict())
        assert rrd.at("world/blocked", "Points2D:labels", step) == [f"blocked: {label}"]
        np.testing.assert_allclose(
            rrd.at("world/blocked", "Points2D:positions", step),
            [[table.at[step, "joint3_x"], table.at[step, "joint3_y"]]],
            rtol=1e-6,
        )
        color = rrd.at("world/arm", "LineStrips2D:colors", step)
        assert red is None or color == red
        red = color
    for step in free[:20].tolist():
        assert rrd.at("world/blocked", "Points2D:positions", step, default=[]) == []
        assert rrd.at("world/arm", "LineStrips2D:colors", step) != red


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


def test_states_sit_where_the_arm_was_in_the_last_version_in_them(
    refined: tuple[Recording, Rrd],
) -> None:
    """A state's place: the mean tip position over the steps it was current in the last
    version that was in it; it never moves."""
    recording, rrd = refined
    table = recording.steps()
    versions = recording.model_versions()
    in_force = version_index(versions, table.index.to_numpy())
    tips = table[["joint3_x", "joint3_y"]].to_numpy()
    states = table["internal_state"].to_numpy()
    checked = 0
    for state in sorted(set(states.tolist())):
        latest = max(in_force[states == state])
        mine = (states == state) & (in_force == latest)
        rows = rrd.column(f"world/model/state/{state}", "Points2D:positions")
        assert rows, state
        for _, place in rows:
            np.testing.assert_allclose(place, [tips[mine].mean(axis=0)], rtol=1e-5, atol=1e-5)
        checked += 1
    assert checked >= 3


def _outs(record: Any) -> dict[int, list[tuple[int, int]]]:
    outs: dict[int, list[tuple[int, int]]] = {s: [] for s in record.states}
    for s, a, t in sorted(record.triples()):
        outs[s].append((a, t))
    return outs


def _brute_force_roles(recording: Recording) -> dict[tuple[int, int], str]:
    """The role of every (version, state) pair seen at a step, with sets."""
    table = recording.steps()
    truth = compute_truth(recording.scenario)
    angles = table[[f"angle_deg_{j}" for j in range(recording.scenario.n_joints)]].to_numpy()
    classes: dict[tuple[int, int], set[int]] = defaultdict(set)
    for version, state, pose in zip(
        table["model_version"].tolist(), table["internal_state"].tolist(), angles, strict=True
    ):
        classes[version, state].add(truth.class_of(pose.tolist()))
    roles = {}
    for (version, state), mine in classes.items():
        if len(mine) > 1:
            roles[version, state] = "aliased"
        else:
            shared = any(
                v == version and s != state and mine <= other for (v, s), other in classes.items()
            )
            roles[version, state] = "redundant" if shared else "exact"
    # The final version: each state the model reaches walking beside the truth from where
    # the run ended, by the classes it meets there (visited in that version or not).
    model = recording.model_at(recording.n_steps)
    start = (model.current, truth.class_of(angles[-1].tolist()))
    pairs, todo = {start}, [start]
    while todo:
        state, cls = todo.pop()
        for k, action in enumerate(truth.actions):
            successors = model.successors(state, action)
            if len(successors) == 1:
                pair = (successors[0], int(truth.class_next[cls, k]))
                if pair not in pairs:
                    pairs.add(pair)
                    todo.append(pair)
    final = int(table["model_version"].iloc[-1])
    for state in {s for s, _ in pairs}:
        mine = {c for s, c in pairs if s == state}
        shared = any(s != state and c in mine for s, c in pairs)
        roles[final, state] = "aliased" if len(mine) > 1 else "redundant" if shared else "exact"
    return roles


def test_a_state_has_a_row_where_it_changed_and_a_clear_where_it_went(
    refined: tuple[Recording, Rrd],
) -> None:
    """Rows against a brute force over the versions: a state gets a row at the step of every
    version in which it appears, its transitions out differ from the version before or its
    role does (the true classes it stood for over the steps of the last version that was in
    it; unvisited until one was), and a clear at the step of the version that deletes it."""
    recording, rrd = refined
    versions = recording.model_versions()
    expected_rows: dict[int, list[int]] = defaultdict(list)
    expected_clears: dict[int, list[int]] = defaultdict(list)
    previous: dict[int, list[tuple[int, int]]] = {}
    previous_roles: dict[int, str] = {}
    roles = _brute_force_roles(recording)
    last_seen: dict[int, str] = {}
    for version in versions:
        now = _outs(version)
        for state in now:
            if (version.version, state) in roles:
                last_seen[state] = roles[version.version, state]
        now_roles = {s: last_seen.get(s, "unvisited") for s in now}
        for state, outs in now.items():
            if previous.get(state) != outs or previous_roles.get(state) != now_roles[state]:
                expected_rows[state].append(version.step)
        previous_roles = now_roles
        for state in set(previous) - set(now):
            expected_clears[state].append(version.step)
        previous = now
    assert sum(map(len, expected_clears.values())) > 0  # the refiner merges states away
    for state in set(expected_rows) | set(expected_clears):
        path = f"world/model/state/{state}"
        steps = sorted({step for step, _ in rrd.column(path, "Points2D:positions")})
        assert steps == sorted(set(expected_rows[state])), state
        assert rrd.cleared_at(path) == expected_clears[state], state


def test_arrows_are_coloured_by_action_and_self_loops_are_stubs(
    refined: tuple[Recording, Rrd],
) -> None:
    """Each state's one entity: an arrow per transition, in the model's order, coloured by
    action; one to another state points towards it, a self-loop is a stub of LOOP_LENGTH
    drawing scales from the state in its action's direction on the colour wheel."""
    recording, rrd = refined
    final = recording.model_versions()[-1]
    step = recording.n_steps
    placed = state_places(
        recording.steps(),
        recording.model_versions(),
        columns=("joint3_x", "joint3_y"),
        pose_columns=[f"angle_deg_{j}" for j in range(3)],
        reach=6.0,
    )
    places, scale = placed.places, placed.scale
    loops_seen = 0
    for state, outs in _outs(final).items():
        path = f"world/model/state/{state}"
        colors = rrd.at(path, "Arrows2D:colors", step, default=[])
        vectors = rrd.at(path, "Arrows2D:vectors", step, default=[])
        origins = rrd.at(path, "Arrows2D:origins", step, default=[])
        assert len(colors) == len(vectors) == len(origins) == len(outs)
        for (a, t), color, vector, origin in zip(outs, colors, vectors, origins, strict=True):
            assert _rgb(color) == ACTION_COLORS[a % len(ACTION_COLORS)]
            if t == state:
                angle = 2 * np.pi * (a % len(ACTION_COLORS)) / len(ACTION_COLORS)
                np.testing.assert_allclose(origin, places[state], atol=1e-5)
                np.testing.assert_allclose(
                    vector, LOOP_LENGTH * scale * np.array([np.cos(angle), np.sin(angle)]),
                    atol=1e-5,
                )  # fmt: skip
                loops_seen += 1
                continue
            towards = np.subtract(places[t], places[state])
            if np.hypot(*towards) > 0:  # points from the state towards its target
                assert np.dot(vector, towards) > 0
    assert loops_seen > 0
    assert not any(path.endswith("/loops") for path in rrd.temporal)


def _rgb(packed: int) -> tuple[int, int, int]:
    return (packed >> 24 & 255, packed >> 16 & 255, packed >> 8 & 255)


def test_current_state_at_every_step(refined: tuple[Recording, Rrd]) -> None:
    recording, rrd = refined
    states = recording.steps()["internal_state"].tolist()
    changes = [0] + [t for t in range(1, len(states)) if states[t] != states[t - 1]]
    classes = rrd.column("world/model/current", "Points2D:class_ids")
    assert [step for step, _ in classes] == changes
    # The label of a class id comes from the static annotation context.
    [[context]] = [
        batch.column("AnnotationContext:context").to_pylist()[0]
        for batch in (chunk.to_record_batch() for chunk in rrd.static["world/model/current"])
        if "AnnotationContext:context" in batch.schema.names
    ]
    label = {item["class_id"]: item["class_description"]["info"]["label"] for item in context}
    for step in range(0, len(states), 37):
        [class_id] = rrd.at("world/model/current", "Points2D:class_ids", step)
        assert label[class_id] == f"now: {states[step]}"


def test_an_aliased_state_has_lines_to_its_poses(reference: tuple[Recording, Rrd]) -> None:
    """The random strategy's one state stands for every pose the arm visited: thin lines to
    the tips of the most visited of them."""
    recording, rrd = reference
    table = recording.steps()
    (_, strips), *_ = rrd.column("world/model/state/0", "LineStrips2D:strips")
    assert len(strips) == POSE_LINES
    tips = {(round(x, 4), round(y, 4)) for x, y in table[["joint3_x", "joint3_y"]].to_numpy()}
    place = np.array(strips[0][0])
    np.testing.assert_allclose(place, table[["joint3_x", "joint3_y"]].mean(), rtol=1e-5)
    for start, end in strips:
        np.testing.assert_allclose(start, place, rtol=1e-6)
        assert (round(end[0], 4), round(end[1], 4)) in tips


def test_a_learned_model_looks_like_the_world() -> None:
    """The learner's final model: every state of it sits on the pose of its true class (the
    model is minimal, so one pose each), with no line to any other pose."""
    with open_recording(LEARNER) as recording:
        table = recording.steps(truth=True)
        versions = recording.model_versions()
        places = state_places(
            table,
            versions,
            columns=("joint2_x", "joint2_y"),
            pose_columns=[f"angle_deg_{j}" for j in range(2)],
            reach=3.0,
        )
    final = versions[-1]
    last_steps = table.loc[final.step :]
    for state in final.states:
        seen = last_steps.loc[last_steps["internal_state"] == state]
        if len(seen):
            tip = seen[["joint2_x", "joint2_y"]].to_numpy()
            np.testing.assert_allclose(places.places[state], tip[0], atol=1e-9)
            assert state not in places.poses


# ------------------------------------------------------------------ plots and the audit log


def test_series_values(reference: tuple[Recording, Rrd]) -> None:
    recording, rrd = reference
    table = recording.steps()
    for step in (0, 17, 999, recording.n_steps):
        assert rrd.at("plots/agent/feedback", "Scalars:scalars", step) == [
            table.at[step, "feedback"]
        ]
        assert rrd.at("plots/distance", "Scalars:scalars", step) == [
            table.at[step, f"dist_{k}_{j}"] for k in range(3) for j in range(2)
        ]
        assert rrd.at("plots/agent/sensation", "Scalars:scalars", step) == [
            float(table.at[step, "sensation"])
        ]


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


def test_the_blueprint_is_made_active_so_a_viewer_lays_out_its_views(
    reference: tuple[Recording, Rrd],
) -> None:
    """Rerun's own ``rrd print`` finds the command that makes the saved blueprint the active
    and default one: without it the web viewer opened the file in its own grid of views (a
    screenshot in headless Chromium showed it)."""
    _, rrd = reference
    rerun = Path(sys.executable).with_name("rerun")
    printed = subprocess.run(
        [str(rerun), "rrd", "print", str(rrd.path)], capture_output=True, text=True, check=True
    ).stdout
    commands = [line for line in printed.splitlines() if "BlueprintActivationCommand" in line]
    assert len(commands) == 1
    assert "make_active: true" in commands[0] and "make_default: true" in commands[0]


def test_a_step_range(refined: tuple[Recording, Rrd], tmp_path: Path) -> None:
    recording, _ = refined
    out = tmp_path / "range.rrd"
    result = view(recording, save=out, spawn=False, serve_web=False, start=100, end=250)
    assert (result.summary.first_step, result.summary.last_step) == (100, 250)
    rrd = Rrd(out)
    arm = [s for s, _ in rrd.column("world/arm", "LineStrips2D:strips")]
    assert arm[0] == 100 and arm[-1] <= 250
    in_force = [r for r in recording.model_versions() if r.step <= 100][-1]
    first_rows = {
        path.rsplit("/", 1)[1]: min(step for step, _ in rrd.column(path, "Points2D:positions"))
        for path in rrd.temporal
        if path.startswith("world/model/state/") and path.count("/") == 3
    }
    assert {int(s) for s, step in first_rows.items() if step == 100} == set(in_force.states)
    assert all(100 <= step <= 250 for step in first_rows.values())
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


RERUN = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")


@pytest.mark.skipif(RERUN is None, reason="the rerun program (from rerun-sdk) is not installed")
def test_rerun_verifies_the_files(
    reference: tuple[Recording, Rrd], refined: tuple[Recording, Rrd]
) -> None:
    assert RERUN is not None
    for _, rrd in (reference, refined):
        done = subprocess.run(
            [RERUN, "rrd", "verify", str(rrd.path)],
            capture_output=True,
            text=True,
            timeout=HANG_S,
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


ROULETTE = Path(__file__).parents[2] / "recordings" / "thesis-roulette-roulette.mcap"
_PLACES = """
import json, sys
from rsstp_replay import open_recording
from rsstp_replay.viewer import graph_positions
with open_recording(sys.argv[1]) as recording:
    print(json.dumps(graph_positions(recording.model_versions())))
"""


@pytest.mark.parametrize(("path", "engine"), [(ROULETTE, "dot"), (LEARNER, "sfdp")])
def test_the_union_layout_is_deterministic_and_keeps_states_apart(
    path: Path, engine: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``dot`` within its work limits up to DOT_MAX_PAIRS state pairs (the roulette's union:
    152 states, 151 pairs), ``sfdp`` past them (the learner's: 119 states, 763 pairs) with its
    overlaps removed by a method the wheel's Graphviz has: no two states closer than a state's
    width (36 points); the same places as in a fresh process, whatever drew from the C
    library's ``rand()`` before (sfdp draws from it and never seeds it)."""
    engines: list[str] = []
    run = _viewer_layout.run_graphviz

    def spy(engine: str, source: str, output_format: str, *, what: str) -> bytes:
        engines.append(engine)
        return run(engine, source, output_format, what=what)

    monkeypatch.setattr(_viewer_layout, "run_graphviz", spy)
    with open_recording(path) as recording:
        versions = recording.model_versions()
    for _ in range(7):
        ctypes.CDLL(None).rand()
    positions = graph_positions(versions)
    assert engines == [engine]
    assert set(positions) == {s for r in versions for s in r.states}
    fresh = subprocess.run(
        [sys.executable, "-c", _PLACES, str(path)], capture_output=True, text=True, check=True
    )
    assert {int(s): tuple(xy) for s, xy in json.loads(fresh.stdout).items()} == positions
    assert graph_positions(versions) == positions
    places = np.array(list(positions.values()))
    gaps = np.hypot(*(places[:, None, :] - places[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= 36.0


def test_render_graph_thesis_layout_and_on_the_world(
    refined: tuple[Recording, Rrd], tmp_path: Path
) -> None:
    recording, _ = refined
    step = 200
    model = recording.model_at(step)

    def pinned(source: str) -> dict[int, tuple[float, float]]:
        return {
            int(m[1]): (float(m[2]), float(m[3]))
            for m in re.finditer(r'\t(\d+) \[.*?pos="([-\d.]+),([-\d.]+)!"', source)
        }

    layout = graph_positions(recording.model_versions())
    places = pinned(render_graph(recording, step, tmp_path / "model.dot").read_text())
    assert set(places) == set(model.states)
    for state, place in places.items():
        assert place == pytest.approx(layout[state], abs=0.01)
    world = state_places(
        recording.steps(),
        recording.model_versions(),
        columns=("joint3_x", "joint3_y"),
        pose_columns=[f"angle_deg_{j}" for j in range(3)],
        reach=6.0,
    )
    on_world = pinned(
        render_graph(recording, step, tmp_path / "world.dot", on_world=True).read_text()
    )
    for state, (x, y) in on_world.items():
        assert (x, y) == pytest.approx(
            (200 * world.places[state][0], 200 * world.places[state][1]), abs=0.01
        )
    svg = render_graph(recording, step, tmp_path / "model.svg")
    assert svg.read_text().startswith("<?xml")
    with pytest.raises(StepOutOfRange):
        render_graph(recording, 401, tmp_path / "late.svg")


def test_entity_paths_are_documented() -> None:
    documented = (Path(__file__).parents[2] / "docs" / "viewer.md").read_text()
    for path in viewer.ENTITY_PATHS:
        assert f"`{path}`" in documented


# ------------------------------------------------- the truth: log levels, colours, labels


@pytest.fixture(scope="module")
def learner(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Recording, Rrd]]:
    """The learner's reference recording (it stops at step 8,400, equivalent from 8,217),
    viewed."""
    out = tmp_path_factory.mktemp("viewer") / "learner.rrd"
    with open_recording(LEARNER) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        yield recording, Rrd(out)


def _log(rrd: Rrd) -> list[tuple[int, str, str]]:
    texts = rrd.column("log/audit", "TextLog:text")
    levels = rrd.column("log/audit", "TextLog:level")
    return [(step, level, text) for (step, [text]), (_, [level]) in zip(texts, levels, strict=True)]


def test_per_version_findings_warn_and_history_ones_are_left_out(
    learner: tuple[Recording, Rrd],
) -> None:
    """Within-version contradictions are WARN where their version was in force (or replaced
    at that step), INFO after; the whole-history ones are not shown; no WARN after the step
    from which the run learned (the truth audit's verdict)."""
    recording, rrd = learner
    lines = _log(rrd)
    findings = audit_truth(recording)
    learned = findings.learned_at_step
    assert learned is not None
    assert [line for line in lines if line[1] == "WARN" and line[0] > learned] == []
    versions = recording.model_versions()
    replaced = {a.version: b.step for a, b in zip(versions[:-1], versions[1:], strict=True)}
    within = audit_consistency_by_version(
        recording.memory(), recording.steps()["model_version"].to_numpy()
    )
    expected = sorted(
        (
            found.first_step,
            "WARN" if found.first_step <= replaced.get(found.version, found.first_step) else "INFO",
        )
        for found in within.contradictions
    )
    shown = sorted(
        (step, level)
        for step, level, text in lines
        if text.startswith("contradiction:") and "model version" in text
    )
    assert shown == expected and "WARN" in {level for _, level in shown}
    # The whole history's findings (state ids across versions) are more, and none is shown.
    history = audit_consistency(recording.memory()).contradictions
    assert len(history) > len(within.contradictions)
    assert len([text for _, _, text in lines if text.startswith("contradiction:")]) == len(shown)


def test_states_are_coloured_by_what_they_stood_for(learner: tuple[Recording, Rrd]) -> None:
    """A state's colour is its role in the last version that was in it (unvisited until
    one was), by a brute force over the steps."""
    recording, rrd = learner
    roles = _brute_force_roles(recording)
    colors = {
        "exact": palette.STATE_EXACT,
        "redundant": palette.STATE_REDUNDANT,
        "aliased": palette.STATE_ALIASED,
        "unvisited": palette.STATE_UNVISITED,
    }
    versions = recording.model_versions()
    seen = set()
    for index in (len(versions) // 2, len(versions) - 1):
        version = versions[index]
        at = version.step if index == len(versions) - 1 else versions[index + 1].step - 1
        for state in version.states:
            # the role of the last version up to this one that was in the state
            role = next(
                (
                    roles[earlier.version, state]
                    for earlier in reversed(versions[: index + 1])
                    if (earlier.version, state) in roles
                ),
                "unvisited",
            )
            [color] = rrd.at(f"world/model/state/{state}", "Points2D:colors", at)
            assert _rgb(color) == colors[role], (version.version, state)
            seen.add(role)
    assert {"exact", "aliased"} <= seen
    legend = rrd.static["world/model/legend"][0].to_record_batch()
    assert legend.column("Points2D:labels").to_pylist()[0] == [
        "exact state",
        "redundant state",
        "aliased state",
        "unvisited state",
    ]


def test_labels_only_where_they_fit(refined: tuple[Recording, Rrd]) -> None:
    """A state is labelled iff no other state is within the label's room of it."""
    recording, rrd = refined
    places = state_places(
        recording.steps(),
        recording.model_versions(),
        columns=("joint3_x", "joint3_y"),
        pose_columns=[f"angle_deg_{j}" for j in range(3)],
        reach=6.0,
    )
    room = LABEL_ROOM * 6.0
    labelled = 0
    for state, (x, y) in places.places.items():
        rows = rrd.column(f"world/model/state/{state}", "Points2D:labels")
        fits = all(
            abs(x - u) >= room or abs(y - v) >= room / 2
            for other, (u, v) in places.places.items()
            if other != state
        )
        positions = rrd.column(f"world/model/state/{state}", "Points2D:positions")
        if not positions:
            continue
        if fits:
            assert [labels for _, labels in rows] == [[str(state)]] * len(positions)
            labelled += 1
        else:
            assert rows == []
    assert 0 < labelled < len(places.places)


def test_without_the_truth_the_states_are_not_coloured(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(viewer, "TRUTH_MAX_POSES", 10)
    out = tmp_path / "plain.rrd"
    with open_recording(REFERENCE) as recording:
        with pytest.warns(ViewerWarning, match="states not coloured by the truth audit: .*poses"):
            view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
    rrd = Rrd(out)
    assert "world/model/legend" not in rrd.static
    [(_, [color])] = rrd.column("world/model/state/0", "Points2D:colors")
    assert _rgb(color) == palette.STATE


# ------------------------------------------------------------------------------ the rover

ROVER = Path(__file__).parents[2] / "recordings" / "rover-one-way-random.mcap"


@pytest.fixture(scope="module")
def rover(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Recording, Rrd]]:
    """The rover's reference recording (a random walk through its one-way door), viewed."""
    out = tmp_path_factory.mktemp("viewer") / "rover.rrd"
    with open_recording(ROVER) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        yield recording, Rrd(out)


def test_the_rover_is_drawn_where_it_is_facing_where_it_faces(
    rover: tuple[Recording, Rrd],
) -> None:
    recording, rrd = rover
    table = recording.steps()
    for step in (0, 777, 2500, recording.n_steps):
        x, y = float(table.at[step, "cell_x"]) + 0.5, float(table.at[step, "cell_y"]) + 0.5
        assert rrd.at("world/robot", "Points2D:positions", step) == [[x, y]]
        heading = np.radians(float(table.at[step, "heading_deg"]))
        np.testing.assert_allclose(
            rrd.at("world/robot", "Arrows2D:vectors", step),
            [[0.45 * np.cos(heading), 0.45 * np.sin(heading)]],
            atol=1e-6,
        )
    blocked = np.flatnonzero(table["blocked"].to_numpy())
    kinds = set(table["blocked_kind"].iloc[blocked])
    assert {"room", "wall", "door", "obstacle"} <= kinds
    for step in blocked[:30].tolist():
        kind = table.at[step, "blocked_kind"]
        label = {
            "room": "room edge {blocked_edge}",
            "obstacle": "obstacle {blocked_obstacle} link {blocked_link}",
            "wall": "wall {blocked_wall}",
            "door": "door {blocked_door}",
        }[kind].format(**table.loc[step].to_dict())
        assert rrd.at("world/blocked", "Points2D:labels", step) == [f"blocked: {label}"]


def test_the_rovers_room_and_the_model_on_it(rover: tuple[Recording, Rrd]) -> None:
    recording, rrd = rover
    scenario = recording.scenario
    batch = rrd.static["world/room"][0].to_record_batch()
    strips = batch.column("LineStrips2D:strips").to_pylist()[0]
    width, height = scenario.room  # type: ignore[union-attr]
    assert strips[0] == [[0, 0], [width, 0], [width, height], [0, height], [0, 0]]
    assert len(strips) == 1 + len(scenario.walls)  # type: ignore[union-attr]
    doors = rrd.static["world/room/doors"][0].to_record_batch()
    assert len(doors.column("LineStrips2D:strips").to_pylist()[0]) == 1
    # A random walk's model is one state, placed where the robot was on average.
    table = recording.steps()
    place = rrd.at("world/model/state/0", "Points2D:positions", recording.n_steps)
    np.testing.assert_allclose(place, [[table["x"].mean(), table["y"].mean()]], rtol=1e-5)
