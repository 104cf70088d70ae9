"""Tables for pandas: the steps indexed by step with typed blocked columns, the model, events
and scenario tables, and ``rsstp-replay table`` to Parquet or to CSV with its dtype sidecar,
read back by :func:`rsstp_replay.read_table` with the same index and dtypes."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from rsstp_cli.replay import main
from rsstp_replay import Recording, open_recording, read_table
from rsstp_replay.export.tables import (
    TABLES,
    changes_table,
    model_table,
    recording_table,
    scenario_table,
)
from rsstp_sim import Runner, make_strategy, parse_scenario
from rsstp_sim.arm.geometry import Blocker
from rsstp_sim.recording.recorder import record
from rsstp_sim.transition_system import TransitionSystem

REFERENCE = Path(__file__).resolve().parents[2] / "recordings"
ROULETTE = REFERENCE / "thesis-roulette-roulette.mcap"  # many model versions and events
THREE_JOINT = REFERENCE / "three-joint-random.mcap"  # blocked moves
LEARNER = REFERENCE / "two-joint-30-learner.mcap"  # splits, merges, adds and deletes
BLOCKED_COLUMNS = {
    "fold": ["blocked_joint"],
    "obstacle": ["blocked_link", "blocked_obstacle"],
    "links": ["blocked_link_i", "blocked_link_j"],
}
# A short middle link: the last link can swing onto the first; an obstacle below.
EVERY_BLOCKER = """
[arm]
lengths = [2.0, 0.5, 2.0]
initial_deg = [0, 90, 90]
step_deg = 30
[[obstacles]]
center = [0.0, -2.5]
radius = 1.0
"""
BLOCKED_STEPS = 200
BLOCKED_SEED = 1


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def blocked_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[Blocker | None]]:
    """A random walk blocked by every kind of blocker, and its blockers from a live run."""
    scenario = parse_scenario(EVERY_BLOCKER, origin="every-blocker.toml")
    path = tmp_path_factory.mktemp("tables") / "every-blocker.mcap"
    record(path, scenario, make_strategy("random"), steps=BLOCKED_STEPS, seed=BLOCKED_SEED)
    runner = Runner(scenario, make_strategy("random"), seed=BLOCKED_SEED)
    return path, [None] + [runner.step().blocker for _ in range(BLOCKED_STEPS)]


# ------------------------------------------------------------------------- the steps


def test_the_steps_are_indexed_by_step() -> None:
    with open_recording(THREE_JOINT) as recording:
        steps = recording.steps()
    assert isinstance(steps.index, pd.RangeIndex)
    assert (steps.index.name, len(steps)) == ("step", recording.n_steps + 1)
    assert "step" not in steps.columns  # groupby("step") is not ambiguous
    per_step = steps.groupby("step")["internal_state"].first()
    assert per_step.equals(steps["internal_state"])
    assert steps.loc[10:12].index.tolist() == [10, 11, 12]


def test_blocked_columns_say_what_blocked_each_kind(
    blocked_run: tuple[Path, list[Blocker | None]],
) -> None:
    path, blockers = blocked_run
    with open_recording(path) as recording:
        steps = recording.steps()
    kind = steps["blocked_kind"]
    assert kind.dtype == pd.CategoricalDtype(["fold", "obstacle", "links", "room", "wall", "door"])
    assert set(kind.dropna()) == {"fold", "obstacle", "links"}  # every kind is tested
    every = [name for names in BLOCKED_COLUMNS.values() for name in names]
    assert all(str(steps[name].dtype) == "Int64" for name in every)
    for step, blocker in enumerate(blockers):
        row = steps.loc[step]
        found = {name: None if pd.isna(row[name]) else int(row[name]) for name in every}
        if blocker is None:
            assert pd.isna(row["blocked_kind"]) and not row["blocked"], step
            assert set(found.values()) == {None}, step
            continue
        expected = dict.fromkeys(every) | dict(
            zip(BLOCKED_COLUMNS[blocker.kind], blocker.indices, strict=True)
        )
        assert (row["blocked_kind"], found) == (blocker.kind, expected), step
    # The kinds' columns select without parsing text.
    obstacle = steps.loc[steps["blocked_kind"] == "obstacle"]
    assert obstacle["blocked_obstacle"].notna().all() and obstacle["blocked_joint"].isna().all()
    links = steps.loc[steps["blocked_kind"] == "links"]
    assert (links["blocked_link_i"] < links["blocked_link_j"] - 1).all()


def test_tables_of_two_scenarios_concatenate() -> None:
    """One joint and no obstacle, three joints and two obstacles: the columns align by name,
    the shared ones keep their dtypes (the blocked kind stays categorical)."""
    with open_recording(ROULETTE) as one, open_recording(THREE_JOINT) as three:
        tables = {
            name: (recording_table(one, name), recording_table(three, name)) for name in TABLES
        }
    small, large = tables["steps"]
    assert set(small.columns) < set(large.columns)
    both = pd.concat([small, large], keys=["roulette", "three-joint"], names=["recording"])
    assert both.index.names == ["recording", "step"]
    assert both.columns.is_unique and set(both.columns) == set(large.columns)
    assert len(both) == len(small) + len(large)
    for name in small.columns:
        assert both[name].dtype == large[name].dtype, name
        assert both[name].notna().sum() == small[name].notna().sum() + large[name].notna().sum()
    assert both.loc["roulette", "angle_deg_2"].isna().all()
    assert both.loc[("three-joint", 13), "blocked_kind"] == "obstacle"
    assert both.groupby("recording")["blocked"].sum().to_dict() == {
        "roulette": 0,
        "three-joint": int(large["blocked"].sum()),
    }
    for name in ("model", "events"):
        a, b = tables[name]
        assert list(a.columns) == list(b.columns)
        joined = pd.concat([a, b], ignore_index=True)
        assert joined.dtypes.equals(b.dtypes), name
    scenarios = pd.concat(tables["scenario"], ignore_index=True)
    assert scenarios["name"].tolist() == ["thesis-roulette", "three-joint"]
    assert scenarios["n_joints"].tolist() == [1, 3]


# --------------------------------------------------------------- model and scenario


def test_the_model_table_has_every_transition_of_every_version() -> None:
    with open_recording(ROULETTE) as recording:
        versions = recording.model_versions()
        model = model_table(recording)
    assert list(model.columns) == ["version", "step", "states", "source", "action", "target"]
    assert [str(t) for t in model.dtypes] == ["int64"] * 3 + ["Int64"] * 3
    assert model["version"].unique().tolist() == [v.version for v in versions]
    for record_ in versions[:: max(1, len(versions) // 20)]:
        rows = model.loc[model["version"] == record_.version]
        triples = rows[["source", "action", "target"]].to_numpy(np.int64).tolist()
        assert triples == [list(t) for t in record_.triples()]
        assert set(rows["step"]) == {record_.step} and set(rows["states"]) == {len(record_.states)}


@pytest.mark.parametrize("path", [ROULETTE, LEARNER], ids=lambda p: p.stem)
def test_the_changes_table_replayed_from_the_first_version_gives_every_version(path: Path) -> None:
    with open_recording(path) as recording:
        versions = recording.model_versions()
        changes = changes_table(recording)
        events = recording.events()
    assert list(changes.columns) == [
        "version", "step", "kind", "changed", "source", "target", "action", "result"
    ]  # fmt: skip
    others = changes.drop(columns="kind")
    assert [str(t) for t in others.dtypes] == ["int64", "int64", "bool"] + ["Int64"] * 4
    assert pd.api.types.is_string_dtype(changes["kind"])  # (object before pandas 3)
    assert {"split"} <= set(changes["kind"]) <= {"split", "merge", "add", "delete"}
    for kind in ("split", "merge"):
        assert (changes["kind"] == kind).sum() == (events["kind"] == kind).sum()
    assert (changes["kind"] == "split").sum() > 30
    model = TransitionSystem.from_snapshot(versions[0].snapshot())
    rows = changes.groupby("version", sort=False)
    for k, record_ in enumerate(versions[1:], start=1):
        for row in rows.get_group(record_.version).itertuples():
            if row.kind == "split":
                assert model.split(row.source) == row.result
            elif row.kind == "merge":
                assert model.merge(row.source, row.target) == row.result
            else:
                done = getattr(model, str(row.kind))(row.source, row.target, row.action)
                assert done == row.changed
        if k % 25 == 0 or k == len(versions) - 1:
            assert tuple(model.transitions()) == record_.triples()
            assert model.states == tuple(record_.states)


def test_a_version_without_transitions_has_one_row() -> None:
    class Versions:
        def __init__(self, recording: Recording) -> None:
            first = recording.model_versions()[0]
            none = {"source": [], "action": [], "target": []}
            empty = type(first).from_json(first.to_json() | {"version": 1, "transitions": none})
            self.versions = [first, empty]

        def model_versions(self) -> list[object]:
            return self.versions

    with open_recording(ROULETTE) as recording:
        model = model_table(Versions(recording))  # type: ignore[arg-type]
    last = model.iloc[-1]
    assert last["version"] == 1 and pd.isna(last["source"]) and pd.isna(last["target"])
    assert model.groupby("version")["source"].count().tolist() == [len(model) - 1, 0]


def test_the_scenario_table_is_the_scenario_message_in_one_row() -> None:
    with open_recording(THREE_JOINT) as recording:
        scenario = scenario_table(recording)
        record_ = recording.scenario_record
    assert len(scenario) == 1
    row = scenario.iloc[0]
    assert (row["name"], row["n_joints"], row["seed"]) == ("three-joint", 3, 1)
    assert row["strategy_name"] == "random" and row["collision"] == "swept"
    assert json.loads(row["lengths"]) == list(record_.lengths)
    assert len(json.loads(row["obstacles"])) == 2
    assert str(scenario["n_joints"].dtype) == "int64"


# ---------------------------------------------------------------- rsstp-replay table


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
@pytest.mark.parametrize("what", TABLES)
@pytest.mark.parametrize("path", [ROULETTE, THREE_JOINT], ids=lambda p: p.stem)
def test_every_table_reads_back_with_its_types(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, path: Path, what: str, suffix: str
) -> None:
    out = tmp_path / f"{what}{suffix}"
    code, printed, err = run_cli(capsys, "table", str(path), "--what", what, "-o", str(out))
    assert (code, err) == (0, "")
    with open_recording(path) as recording:
        expected = recording_table(recording, what)
    assert printed.startswith(f"wrote {len(expected):,} rows and {len(expected.columns)} columns")
    found = read_table(out)
    assert found.equals(expected)
    assert found.dtypes.to_dict() == expected.dtypes.to_dict()
    assert (type(found.index), found.index.name) == (type(expected.index), expected.index.name)
    assert (out.with_name(out.name + ".dtypes.json").exists()) == (suffix == ".csv")


def test_the_csv_sidecar_describes_every_column(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "steps.csv"
    code, printed, _ = run_cli(capsys, "table", str(THREE_JOINT), "-o", str(out))
    assert code == 0
    sidecar = tmp_path / "steps.csv.dtypes.json"
    assert printed.endswith(f"; dtypes in {sidecar}\n")
    meta = json.loads(sidecar.read_text())
    header = out.read_text().split("\n", 1)[0].split(",")
    assert (meta["format"], meta["version"], meta["index"]) == (
        "rsstp-replay table dtypes",
        1,
        "step",
    )
    assert list(meta["dtypes"]) == header
    assert meta["dtypes"]["step"] == "int64" and meta["dtypes"]["action"] == "Int64"
    assert meta["dtypes"]["blocked_kind"] == "category"
    assert meta["categories"] == {
        "blocked_kind": ["fold", "obstacle", "links", "room", "wall", "door"]
    }


def test_the_truth_table_reads_back_from_csv(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "truth.csv"
    code, _, err = run_cli(capsys, "table", str(ROULETTE), "--truth", "-o", str(out))
    assert (code, err) == (0, "")
    with open_recording(ROULETTE) as recording:
        expected = recording_table(recording, truth=True)
    assert {"true_class", "pose", "aliased"} <= set(expected.columns)
    assert read_table(out).equals(expected)


# ------------------------------------------------------- refusals on the command line


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["--what", "model", "--truth"],
            "table: --truth adds to the steps table, not to --what model",
        ),
        (["--what", "memory"], "argument --what: invalid choice: 'memory'"),
        (["-o", "{tmp}/t.csv.dtypes.json"], "unknown table format '.json'"),
    ],
)
def test_bad_table_arguments_are_one_line(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, args: list[str], message: str
) -> None:
    if "-o" not in args:
        args = [*args, "-o", "{tmp}/t.parquet"]
    filled = [a.format(tmp=tmp_path) for a in args]
    code, printed, err = run_cli(capsys, "table", str(ROULETTE), *filled)
    assert (code, printed) == (2, "")
    assert err.count("\n") == 1 and message in err, err
    assert list(tmp_path.iterdir()) == []


def test_an_existing_sidecar_is_kept_without_force(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    out = tmp_path / "steps.csv"
    sidecar = tmp_path / "steps.csv.dtypes.json"
    sidecar.write_text("kept\n")
    code, _, err = run_cli(capsys, "table", str(ROULETTE), "-o", str(out))
    assert code == 2
    assert err == f"rsstp-replay: error: {sidecar}: already exists (use --force to overwrite)\n"
    assert sidecar.read_text() == "kept\n" and not out.exists()
    code, _, err = run_cli(capsys, "table", str(ROULETTE), "-o", str(out), "--force")
    assert (code, err) == (0, "")
    with open_recording(ROULETTE) as recording:
        assert read_table(out).equals(recording.steps())
