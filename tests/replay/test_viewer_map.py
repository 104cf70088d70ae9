"""The model map of the joint space and the neighbourhood arrows of a large model: read back
from the ``.rrd`` with Rerun's own reader and checked against computations written here."""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
from fakes import RandomRefiner
from rerun.chunk import RrdReader
from test_viewer import LEARNER, Rrd, _rgb

from rsstp_replay.audits.state_roles import ALIASED, EXACT, REDUNDANT, UNVISITED
from rsstp_replay.reader.recording import Recording, open_recording
from rsstp_replay.viewer import _large, view
from rsstp_replay.viewer._map import NO_POSE, TILE_GAP, joint_grid
from rsstp_replay.viewer._model import ACTION_COLORS
from rsstp_sim import palette
from rsstp_sim.recording import record
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.truth import check_equivalence, compute_truth

ROLE_RGB = {
    UNVISITED: palette.STATE_UNVISITED,
    EXACT: palette.STATE_EXACT,
    REDUNDANT: palette.STATE_REDUNDANT,
    ALIASED: palette.STATE_ALIASED,
}


# ------------------------------------------------------------------ the grid's colours


def _expected_roles(recording: Recording) -> dict[int, dict[int, int]]:
    """Per version number, every true class's role (a class keeps its last one; a brute
    force with sets over the steps, written apart from the viewer's numpy)."""
    truth = compute_truth(recording.scenario)
    table = recording.steps()
    angles = table[list(truth.value_names)].to_numpy().tolist()
    states_of: dict[tuple[int, int], set[int]] = defaultdict(set)
    classes_of: dict[tuple[int, int], set[int]] = defaultdict(set)
    for version, state, pose in zip(
        table["model_version"].tolist(), table["internal_state"].tolist(), angles, strict=True
    ):
        c = truth.class_of(pose)
        states_of[version, c].add(state)
        classes_of[version, state].add(c)
    known = dict.fromkeys(range(truth.n_classes), UNVISITED)
    by_version: dict[int, dict[int, int]] = {}
    for version in recording.model_versions():
        v = version.version
        for c in range(truth.n_classes):
            states = states_of.get((v, c))
            if not states:
                continue
            if any(len(classes_of[v, s]) > 1 for s in states):
                known[c] = ALIASED
            elif len(states) > 1:
                known[c] = REDUNDANT
            else:
                known[c] = EXACT
        by_version[v] = dict(known)
    # The final version: a model equivalent to the truth from where the run ended (and with a
    # state per class) stands for every class exactly, visited in it or not.
    model = recording.model_at(recording.n_steps)
    labels = {s: bool(x) for s, x in zip(table["internal_state"], table["sensation"], strict=True)}
    last = truth.class_of(angles[-1])
    if (
        len(model) == truth.n_classes
        and check_equivalence(model, labels, truth, start_state=model.current, start_class=last)
        is None
    ):
        by_version[recording.model_versions()[-1].version] = dict.fromkeys(known, EXACT)
    return by_version


@pytest.fixture(scope="module")
def learner(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Recording, Rrd]]:
    out = tmp_path_factory.mktemp("map") / "learner.rrd"
    with open_recording(LEARNER) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
        yield recording, Rrd(out)


def _cells(rrd: Rrd) -> dict[str, list[tuple[float, float]]]:
    """Each block's cell centres (static)."""
    found = {}
    for path, chunks in rrd.static.items():
        if path.startswith("map/cells/"):
            batch = chunks[0].to_record_batch()
            [centers] = batch.column("Boxes2D:centers").to_pylist()
            found[path] = [tuple(c) for c in centers]
    return found


def test_every_cell_has_the_colour_of_its_class_role_at_every_version(
    learner: tuple[Recording, Rrd],
) -> None:
    """The learner's two-joint world at 30 degrees: one cell per reachable pose, at its joint
    angle indexes; at each version's step, its colour is its true class's role by the brute
    force above."""
    recording, rrd = learner
    truth = compute_truth(recording.scenario)
    scenario = recording.scenario
    cells = _cells(rrd)
    places = {place: path for path, centers in cells.items() for place in centers}
    assert len(places) == truth.n_poses == sum(map(len, cells.values()))
    index_of = {}
    for p, angles in enumerate(truth.pose_values.tolist()):
        index = tuple(
            ((a - i) % 360) // scenario.step_deg
            for a, i in zip(angles, scenario.initial_deg, strict=True)
        )
        index_of[p] = index
        assert (float(index[0]), float(index[1])) in places  # x: joint 0, y: joint 1
    expected = _expected_roles(recording)
    checked = 0
    for version in recording.model_versions():
        roles = expected[version.version]
        colours = {path: rrd.at(path, "Boxes2D:colors", version.step) for path in cells}
        for p, (i, j) in index_of.items():
            path = places[float(i), float(j)]
            colour = colours[path][cells[path].index((float(i), float(j)))]
            assert _rgb(colour) == ROLE_RGB[roles[int(truth.true_class[p])]], (version.version, p)
            checked += 1
    assert checked > 10_000
    seen = {role for roles in expected.values() for role in roles.values()}
    assert seen == {UNVISITED, EXACT, REDUNDANT, ALIASED}  # every colour was checked


def test_a_block_has_a_row_only_where_a_cell_of_it_changed(
    learner: tuple[Recording, Rrd],
) -> None:
    """The colours grow with the changes: no two consecutive rows of a block alike, and
    fewer rows in all than versions times blocks."""
    recording, rrd = learner
    cells = _cells(rrd)
    total = 0
    for path in cells:
        rows = rrd.column(path, "Boxes2D:colors")
        total += len(rows)
        assert rows[0][0] == 0
        for (_, before), (_, after) in zip(rows, rows[1:], strict=False):
            assert before != after
    assert total < len(recording.model_versions()) * len(cells) / 4


def test_the_current_pose_ring_follows_the_arm(learner: tuple[Recording, Rrd]) -> None:
    recording, rrd = learner
    table = recording.steps()
    scenario = recording.scenario
    for step in (0, 17, 5000, recording.n_steps):
        angles = table.loc[step, ["angle_deg_0", "angle_deg_1"]].tolist()
        index = [
            ((a - i) % 360) // scenario.step_deg
            for a, i in zip(angles, scenario.initial_deg, strict=True)
        ]
        assert rrd.at("map/pose", "Boxes2D:centers", step) == [[float(index[0]), float(index[1])]]


def test_the_map_is_a_view_of_the_blueprint(learner: tuple[Recording, Rrd]) -> None:
    """The saved blueprint has a 2D view named for the map, whose contents are the map."""
    _, rrd = learner
    chunks = RrdReader(rrd.path).stream(store=rrd.blueprints[0]).to_chunks()
    values = [
        str(value)
        for chunk in chunks
        for batch in [chunk.to_record_batch()]
        for name in batch.schema.names
        if name in ("ViewBlueprint:display_name", "ViewContents:query")
        for value in batch.column(name).to_pylist()
    ]
    assert any("Model map (joint space)" in value for value in values)
    assert any("/map/**" in value for value in values)


# ------------------------------------------------------------------ three joints: tiles


def test_three_joints_tile_the_slices_of_the_first_two() -> None:
    """Three joints at 90 degrees: 4 x 4 cells a tile, one tile per angle of joint 2, in two
    rows of two tiles; every pose's cell at its tile's origin plus its two first indexes."""
    scenario = parse_scenario(
        'name = "three-90"\n[arm]\nlengths = [1.0, 1.0, 1.0]\ninitial_deg = [0, 0, 0]\n'
        "step_deg = 90\n[feedback]\ntarget_deg = [0, 0, 0]\n"
    )
    grid = joint_grid(scenario)
    assert grid is not None
    assert grid.sizes == (4, 4, 4) and grid.columns == 2 and grid.tile_rows == 2
    angles = np.array(
        [[a, b, c] for a in range(0, 360, 90) for b in range(0, 360, 90) for c in range(0, 360, 90)]
    )
    places = grid.places(angles)
    tile = angles[:, 2] // 90
    step = 4 + TILE_GAP
    np.testing.assert_array_equal(places[:, 0], (tile % 2) * step + angles[:, 0] // 90)
    np.testing.assert_array_equal(places[:, 1], -(tile // 2) * step + angles[:, 1] // 90)
    assert len({tuple(p) for p in places.tolist()}) == 64  # no two poses share a cell


def test_three_joint_map_in_the_rrd(tmp_path: Path) -> None:
    """The three-joint world (5 degrees): 72 tiles, each pose a cell, the tiles labelled with
    joint 2's angle, at most MAX_BLOCKS cell entities."""
    scenario = load_scenario("three-joint")
    record(tmp_path / "r.mcap", scenario, RandomRefiner(split=0.0), steps=200, seed=3)
    with open_recording(tmp_path / "r.mcap") as recording:
        view(recording, save=tmp_path / "r.rrd", spawn=False, serve_web=False, start=None, end=None)
    rrd = Rrd(tmp_path / "r.rrd")
    cells = _cells(rrd)
    assert sum(map(len, cells.values())) == compute_truth(scenario).n_poses
    assert len(cells) <= 128
    [labels] = rrd.static[NO_POSE][0].to_record_batch().column("Boxes2D:labels").to_pylist()
    assert len(labels) == 72 and labels[1] == f"joint 2: {(scenario.initial_deg[2] + 5) % 360}°"


def test_no_map_for_one_joint(tmp_path: Path) -> None:
    scenario = load_scenario("one-joint-10")
    record(tmp_path / "r.mcap", scenario, RandomRefiner(split=0.0), steps=50, seed=3)
    with open_recording(tmp_path / "r.mcap") as recording:
        view(recording, save=tmp_path / "r.rrd", spawn=False, serve_web=False, start=None, end=None)
    rrd = Rrd(tmp_path / "r.rrd")
    assert not any(path.startswith("map") for path in [*rrd.temporal, *rrd.static])


# ------------------------------------------------------------------ neighbourhood arrows


def _bfs(model: object, state: int, depth: int) -> list[tuple[int, int, int]]:
    """The transitions out of ``state`` and of what it reaches in fewer than ``depth`` steps."""
    found, frontier, seen = [], [state], {state}
    for _ in range(depth):
        following = []
        for s in frontier:
            for a, t in sorted(model.transitions_from(s)):  # type: ignore[attr-defined]
                found.append((s, a, t))
                if t not in seen:
                    seen.add(t)
                    following.append(t)
        frontier = following
    return found


@pytest.fixture(scope="module")
def large(
    tmp_path_factory: pytest.TempPathFactory,
) -> Iterator[tuple[Recording, Rrd, Rrd]]:
    """A random refiner's run viewed twice: as a large model (the threshold patched to 2
    states) and as a small one (an entity per state, tested in test_viewer.py)."""
    folder = tmp_path_factory.mktemp("large")
    record(
        folder / "r.mcap",
        load_scenario("three-joint"),
        RandomRefiner(split=0.05, max_states=6),
        steps=300,
        seed=7,
    )
    with open_recording(folder / "r.mcap") as recording:
        view(
            recording, save=folder / "small.rrd", spawn=False, serve_web=False, start=None, end=None
        )
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(_large, "ALL_ARROWS_MAX_STATES", 2)
            view(
                recording,
                save=folder / "large.rrd",
                spawn=False,
                serve_web=False,
                start=None,
                end=None,
            )
        yield recording, Rrd(folder / "large.rrd"), Rrd(folder / "small.rrd")


def test_a_large_model_draws_only_the_current_states_neighbourhood(
    large: tuple[Recording, Rrd, Rrd],
) -> None:
    """Over ALL_ARROWS_MAX_STATES states, no entity per state; ``world/model/near`` has, at
    each of its rows, one arrow per transition out of the current state (and out of the
    states it reaches in fewer than NEAR_STEPS steps), coloured by action, and a row wherever
    the current state changed."""
    recording, rrd, _ = large
    assert not any(path.startswith("world/model/state/") for path in rrd.temporal)
    rows = rrd.column(_large.NEAR, "Arrows2D:colors")
    states = recording.steps()["internal_state"].to_numpy()
    changed = np.flatnonzero(np.r_[True, states[1:] != states[:-1]]).tolist()
    assert set(changed) <= {step for step, _ in rows}
    checked = 0
    for step, colours in rows[:: max(1, len(rows) // 40)]:
        expected = _bfs(recording.model_at(step), int(states[step]), _large.NEAR_STEPS)
        assert sorted(_rgb(c) for c in colours) == sorted(
            ACTION_COLORS[a % len(ACTION_COLORS)] for _, a, _ in expected
        ), step
        checked += 1
    assert checked >= 20


def test_a_large_models_states_in_blocks_look_as_on_a_small_model(
    large: tuple[Recording, Rrd, Rrd],
) -> None:
    """Each block: its states' places (static) and, at every step where a state of the small
    model's view has a row or a clear, the same colour (transparent where the small view has
    none) and the label of a labelled state as its class id."""
    recording, rrd, small = large
    blocks = sorted(p for p in rrd.static if p.startswith(_large.STATE_BLOCKS + "/"))
    assert blocks
    ids = sorted(
        int(p.rsplit("/", 1)[1]) for p in small.temporal if p.startswith("world/model/state/")
    )
    size = _large.block_size(len(ids))
    steps = sorted(
        {s for p in small.temporal if p.startswith("world/model/state/")
         for s, _ in small.column(p, "Points2D:colors")}
        | {s for p in small.temporal for s in small.cleared_at(p)}
    )  # fmt: skip
    checked = 0
    for k, state in enumerate(ids):
        path = f"{_large.STATE_BLOCKS}/{k // size}"
        [places] = rrd.static[path][0].to_record_batch().column("Points2D:positions").to_pylist()
        [small_place] = small.column(f"world/model/state/{state}", "Points2D:positions")[0][1]
        np.testing.assert_allclose(places[k % size], small_place, atol=1e-6)
        for step in steps:
            cleared = [s for s in small.cleared_at(f"world/model/state/{state}") if s <= step]
            rows = [
                (s, c) for s, c in small.column(f"world/model/state/{state}", "Points2D:colors")
                if s <= step
            ]  # fmt: skip
            alive = rows and (not cleared or rows[-1][0] > cleared[-1])
            colour = rrd.at(path, "Points2D:colors", step)[k % size]
            radius = rrd.at(path, "Points2D:radii", step)[k % size]
            assert colour == (rows[-1][1][0] if alive else 0), (state, step)
            assert (radius != 0) == bool(alive), (state, step)
            checked += 1
    assert checked > 100
    assert recording.n_steps > 0


def test_a_small_model_keeps_every_arrow(learner: tuple[Recording, Rrd]) -> None:
    """The learner's 119 states: every state its arrows, no neighbourhood entity."""
    _, rrd = learner
    assert _large.NEAR not in rrd.temporal
    assert not any(path.startswith(_large.STATE_BLOCKS) for path in rrd.temporal)
    assert rrd.column("world/model/state/0", "Arrows2D:vectors")
