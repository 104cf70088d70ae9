"""Reading recordings: real MCAP files written by the recorder, checked against live runs.

The steps table and the events are checked against the messages read back independently (the
``mcap`` reader and the record types); the memory and the model at every step against a live
run with the same scenario, strategy and seed; unfinished files (cut bytes, a killed writer)
are read up to their last complete chunk, with a warning.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest
from fakes import RandomRefiner, count_chunk_reads
from mcap.reader import make_reader

from rsstp_format import records
from rsstp_replay import EVENT_KINDS, open_recording
from rsstp_replay.errors import (
    ReplayError,
    StepOutOfRange,
    TableError,
    UnfinishedRecordingWarning,
)
from rsstp_replay.reader._models import ModelHistory
from rsstp_sim import AgentView, Memory, Runner, StrategyBase, load_scenario, make_strategy
from rsstp_sim.recording.recorder import record
from rsstp_sim.transition_system import TransitionSystem
from waiting import wait_until

SRC = Path(__file__).resolve().parents[2] / "src"
STEPS = 2000
SEED = 7
CHUNK_SIZE = 16 * 1024  # about 20 steps per chunk: many chunks in a small file
BLOCKED_INDEX_COLUMNS = [
    "blocked_joint",
    "blocked_link",
    "blocked_obstacle",
    "blocked_link_i",
    "blocked_link_j",
]


class Refiner(StrategyBase):
    """Random actions, and a model that changes: splits, adds, deletes, one merge, notes and
    re-localisations (setting the current state, which no operation logs)."""

    name: ClassVar[str] = "test-refiner"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]

    def refine(self, agent: AgentView) -> None:
        model, t = agent.model, agent.step
        if t % 97 == 0 and len(model) < 8:
            model.split(model.current)
        if t % 13 == 0:
            for a in agent.actions:
                successors = model.successors(model.current, a)
                if len(successors) > 1:
                    model.delete(model.current, successors[-1], a)
                    break
        if t % 29 == 0:
            target = model.states[int(agent.rng.integers(len(model)))]
            model.add(model.current, target, agent.actions[t % len(agent.actions)])
        if t == 600 and len(model) > 2:
            model.merge(model.states[0], model.states[-1])
        if t % 31 == 0:
            model.current = model.states[t % len(model)]
        if t % 250 == 0:
            agent.note(f"step {t}: {len(model)} states")


def steps_of(path: Path) -> list[records.StepRecord]:
    """The step messages, read independently with the ``mcap`` reader and the record types."""
    return [
        record for record in _decoded(path, "/rsstp/step") if isinstance(record, records.StepRecord)
    ]


def _decoded(path: Path, topic: str) -> Iterator[records.MessageRecord]:
    with open(path, "rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(topics=[topic]):
            yield records.decode(_SCHEMAS[channel.topic], message.data)


_SCHEMAS = {
    "/rsstp/scenario": "rsstp.Scenario",
    "/rsstp/step": "rsstp.Step",
    "/rsstp/model": "rsstp.Model",
    "/rsstp/event": "rsstp.Event",
}


@pytest.fixture(scope="module")
def random_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Any]:
    """A recording of the random strategy, and what the recorder said it wrote."""
    path = tmp_path_factory.mktemp("random") / "run.mcap"
    result = record(
        path,
        load_scenario("three-joint"),
        make_strategy("random"),
        steps=STEPS,
        seed=SEED,
        chunk_size=CHUNK_SIZE,
    )
    return path, result


@dataclass(frozen=True)
class LiveRun:
    """A recording, and the live run it was made from: its memory, its model after every
    step (0 = the reset)."""

    path: Path
    memory: Memory
    models: list[TransitionSystem]


@pytest.fixture(scope="module")
def refined_run(tmp_path_factory: pytest.TempPathFactory) -> LiveRun:
    """A recording of :class:`Refiner`, and its live run."""
    path = tmp_path_factory.mktemp("refined") / "run.mcap"
    scenario = load_scenario("three-joint")
    record(path, scenario, Refiner(), steps=STEPS, seed=SEED, chunk_size=CHUNK_SIZE)
    runner = Runner(scenario, Refiner(), seed=SEED)
    models = [runner.model.copy()]
    for _ in range(STEPS):
        runner.step()
        models.append(runner.model.copy())
    return LiveRun(path, runner.memory, models)


# ----------------------------------------------------------------------------- opening


def test_open_reads_the_scenario_metadata_and_counts(random_run: tuple[Path, Any]) -> None:
    path, result = random_run
    with open_recording(path) as recording:
        assert recording.path == path
        assert recording.finished
        assert recording.recovered_steps is None
        assert recording.n_steps == STEPS
        assert recording.topic_counts == result.messages
        assert recording.seed == SEED
        assert recording.strategy == "random"
        assert recording.strategy_params == {}
        assert recording.scenario == load_scenario("three-joint")
        assert recording.scenario_record.name == "three-joint"
        assert recording.metadata["seed"] == str(SEED)
        assert recording.metadata["scenario_sha256"] == recording.scenario.sha256
        assert recording.schema_versions == {
            "rsstp.Scenario": "3.0",
            "rsstp.Step": "3.0",
            "rsstp.Model": "3.0",
            "rsstp.Event": "3.0",
        }
        assert "steps=0..2000" in repr(recording)


def test_a_closed_recording_refuses_to_read(random_run: tuple[Path, Any]) -> None:
    path, _ = random_run
    with open_recording(path) as recording:
        pass
    with pytest.raises(ReplayError, match=r"run\.mcap: the recording is closed"):
        recording.memory()
    with pytest.raises(ReplayError, match="closed"):
        recording.model_at(0)


# -------------------------------------------------------------------------- the tables


def test_steps_table_has_flat_typed_columns(random_run: tuple[Path, Any]) -> None:
    path, _ = random_run
    table = open_recording(path).steps()
    assert len(table) == STEPS + 1
    assert isinstance(table.index, pd.RangeIndex)
    assert (table.index.name, table.index.start, table.index.stop) == ("step", 0, STEPS + 1)
    dtypes = {name: str(dtype) for name, dtype in table.dtypes.items()}
    assert dtypes == {
        "action": "Int64",
        "state_before": "Int64",
        "internal_state": "int64",
        "sensation": "bool",
        "feedback": "float64",
        "model_version": "int64",
        "no_transition": "bool",
        "blocked": "bool",
        "blocked_kind": "category",
        **dict.fromkeys(BLOCKED_INDEX_COLUMNS, "Int64"),
        **{f"angle_deg_{j}": "int64" for j in range(3)},
        **{f"joint{k}_{axis}": "float64" for k in range(4) for axis in "xy"},
        **{f"dist_{k}_{j}": "float64" for k in range(3) for j in range(2)},
    }
    assert table["action"].isna().tolist() == [True] + [False] * STEPS
    assert table["state_before"].isna().sum() == 1
    assert table["blocked"].any()  # the random walk meets the obstacles
    assert list(table["blocked_kind"].cat.categories) == [
        "fold",
        "obstacle",
        "links",
        "room",
        "wall",
        "door",
    ]
    assert table.groupby("step")["action"].first().equals(table["action"])  # no ambiguity


def test_steps_table_equals_the_step_messages(random_run: tuple[Path, Any]) -> None:
    path, _ = random_run
    table = open_recording(path).steps()
    messages = steps_of(path)
    assert len(messages) == len(table)
    for row, message in zip(table.itertuples(), messages, strict=True):
        agent, truth = message.agent, message.truth
        assert row.Index == message.step
        assert (None if pd.isna(row.action) else row.action) == agent.action
        assert (None if pd.isna(row.state_before) else row.state_before) == agent.state_before
        assert (row.internal_state, row.sensation, row.feedback) == (
            agent.internal_state,
            agent.sensation,
            agent.feedback,
        )
        assert (row.model_version, row.no_transition) == (agent.model_version, agent.no_transition)
        assert row.blocked == truth.blocked
        values = row._asdict()
        by = truth.blocked_by
        expected: dict[str, Any] = dict.fromkeys(BLOCKED_INDEX_COLUMNS)
        if by is not None:
            names = {
                "fold": ["blocked_joint"],
                "obstacle": ["blocked_link", "blocked_obstacle"],
                "links": ["blocked_link_i", "blocked_link_j"],
            }[by.kind]
            expected |= dict(zip(names, by.indices, strict=True))
        assert (None if pd.isna(row.blocked_kind) else row.blocked_kind) == (by and by.kind)
        assert {name: None if pd.isna(values[name]) else values[name] for name in expected} == (
            expected
        )
        assert [values[f"angle_deg_{j}"] for j in range(3)] == list(truth.angles_deg)
        for k, point in enumerate(truth.joint_positions):
            assert (values[f"joint{k}_x"], values[f"joint{k}_y"]) == (point.x, point.y)  # exactly
        for k, tip in enumerate(truth.distances):
            assert [values[f"dist_{k}_{j}"] for j in range(2)] == list(tip.obstacles)


def test_events_table_equals_the_event_messages(refined_run: LiveRun) -> None:
    path = refined_run.path
    events = open_recording(path).events()
    messages = list(_decoded(path, "/rsstp/event"))
    text = str(pd.Series([], dtype="str").dtype)  # pandas 3: "str"; pandas 2: "object"
    assert {str(name): str(dtype) for name, dtype in events.dtypes.items()} == {
        "step": "int64",
        "kind": "category",
        "text": text,
        "data": text,
    }
    assert list(events["kind"].cat.categories) == list(EVENT_KINDS)
    assert len(events) == len(messages) > 0
    for row, message in zip(events.itertuples(index=False), messages, strict=True):
        assert isinstance(message, records.EventRecord)
        assert (row.step, row.kind, row.text) == (message.step, message.kind, message.text)
        assert json.loads(row.data) == message.data
    assert {"split", "merge", "add", "delete", "note", "blocked"} <= set(events["kind"])


@pytest.mark.parametrize("cut", [False, True])
def test_steps_and_events_read_in_one_pass_equal_them_read_apart(
    refined_run: LiveRun, tmp_path: Path, cut: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What an audit reads: both tables from one read of every chunk, the same as each
    alone (a finished file through its message indexes, a cut one by walking its chunks)."""
    path = refined_run.path
    if cut:
        offsets = _chunk_offsets(path)
        path = tmp_path / "cut.mcap"
        path.write_bytes(refined_run.path.read_bytes()[: offsets[len(offsets) // 2] + 200])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnfinishedRecordingWarning)
        apart, together = open_recording(path), open_recording(path)
    reads = count_chunk_reads(monkeypatch)
    steps, events = apart.steps(), apart.events()
    read_apart, reads[:] = set(reads), []
    both_steps, both_events = together.steps_and_events()
    assert len(set(reads)) == len(reads)  # each chunk read once,
    assert set(reads) == read_apart  # every chunk that either table reads
    pd.testing.assert_frame_equal(both_steps, steps)
    pd.testing.assert_frame_equal(both_events, events)
    assert len(events) > 0 and events["step"].max() <= together.n_steps
    pd.testing.assert_frame_equal(together.events(), events)  # kept: not read again
    assert len(reads) == len(read_apart)


@pytest.mark.parametrize("rows", [7, STEPS, STEPS + 1, 10 * STEPS])
def test_step_parts_make_the_steps_table(random_run: tuple[Path, Any], rows: int) -> None:
    with open_recording(random_run[0]) as recording:
        parts = list(recording.step_parts(rows))
        whole = recording.steps()
    sizes = [rows] * ((STEPS + 1) // rows) + ([(STEPS + 1) % rows] if (STEPS + 1) % rows else [])
    assert [len(part) for part in parts] == sizes
    assert [part.index[0] for part in parts] == list(range(0, STEPS + 1, rows))
    pd.testing.assert_frame_equal(pd.concat(parts), whole)


def test_step_parts_of_no_rows_are_refused(random_run: tuple[Path, Any]) -> None:
    with open_recording(random_run[0]) as recording:
        with pytest.raises(TableError, match="at least one row, not 0"):
            next(recording.step_parts(0))


# ------------------------------------------------------------------ memory and the model


def test_memory_equals_the_live_run(random_run: tuple[Path, Any]) -> None:
    path, _ = random_run
    runner = Runner(load_scenario("three-joint"), make_strategy("random"), seed=SEED)
    runner.run(STEPS)
    memory = open_recording(path).memory()
    assert memory == runner.memory
    for t in (0, 1, STEPS // 2, STEPS):
        assert memory[t] == runner.memory[t]


def test_memory_of_a_refining_strategy_equals_the_live_run(refined_run: LiveRun) -> None:
    assert open_recording(refined_run.path).memory() == refined_run.memory


def _same_model(replayed: TransitionSystem, live: TransitionSystem) -> bool:
    return (
        replayed == live
        and replayed.version == live.version
        and replayed.next_id == live.next_id
        and replayed.states == live.states
    )


def test_model_at_every_step_equals_the_live_model(refined_run: LiveRun) -> None:
    live = refined_run.models
    recording = open_recording(refined_run.path)
    versions = recording.model_versions()
    assert len(versions) > 20  # the model changed many times
    assert {op.kind for v in versions for op in v.operations} == {"split", "merge", "add", "delete"}
    assert versions[-1].version == live[-1].version
    for step in range(STEPS + 1):  # chunk by chunk, before the whole memory is read
        assert _same_model(recording.model_at(step), live[step]), f"step {step}"
    recording.memory()  # now from the cached columns
    for step in (0, 1, 600, 601, STEPS - 1, STEPS):
        assert _same_model(recording.model_at(step), live[step]), f"step {step}"


LEARNER = Path(__file__).resolve().parents[2] / "recordings" / "two-joint-30-learner.mcap"


def _versions_from_the_messages(path: Path) -> list[tuple[int, TransitionSystem]]:
    """Each model version and its step, rebuilt here from the messages read with the ``mcap``
    reader and the record types: the first message's snapshot, then every message's
    operations applied in turn."""
    found: list[tuple[int, TransitionSystem]] = []
    model: TransitionSystem | None = None
    for message in _decoded(path, "/rsstp/model"):
        assert isinstance(message, records.ModelRecord)
        if model is None:
            model = TransitionSystem.from_snapshot(message.snapshot(), version=message.version)
        for operation in message.operations if found else ():
            model.apply(operation.to_operation())
        model.drain_operations()
        found.append((message.step, model.copy()))
    return found


def test_model_at_next_to_each_kept_model_and_keyframe(refined_run: LiveRun) -> None:
    """The model at the step of the first and the last version, and of the versions just
    before, at and after each whole model the reader keeps and each keyframe of the file,
    asked for newest first (no version rebuilt from the one asked before it), is the version
    rebuilt from version 0 with every change, its current state the step's."""
    for path in (LEARNER, refined_run.path):
        expected = _versions_from_the_messages(path)
        internal = [step.agent.internal_state for step in steps_of(path)]
        with open_recording(path) as recording:
            versions = recording.model_versions()
            assert isinstance(versions, ModelHistory)
            heads = versions.heads
            keyframes = [k for k, head in enumerate(heads) if head.keyframe]
            kept = versions._kept  # (the whole models the reader keeps)
            assert 1 < len(keyframes) < len(kept) < len(heads)
            near = {k + d for k in [0, len(heads) - 1, *keyframes, *kept] for d in (-1, 0, 1)}
            for k in sorted(near & set(range(len(heads))), reverse=True):
                step, model = expected[k]
                model.current = internal[step]
                rebuilt = recording.model_at(step)
                assert _same_model(rebuilt, model), f"version {k}"
                assert rebuilt.nondeterministic_pairs == model.nondeterministic_pairs


def test_model_at_refuses_steps_out_of_range(random_run: tuple[Path, Any]) -> None:
    path, _ = random_run
    recording = open_recording(path)
    with pytest.raises(StepOutOfRange, match=r"run\.mcap: step 2001 is out of range: .* 0 to 2000"):
        recording.model_at(STEPS + 1)
    with pytest.raises(StepOutOfRange, match="step -1 is out of range"):
        recording.model_at(-1)
    with pytest.raises(StepOutOfRange, match="must be an integer, got 2.5"):
        recording.model_at(2.5)  # type: ignore[arg-type]
    assert recording.model_at(np.int64(STEPS)).current == 0


def test_a_recording_of_the_reset_alone(tmp_path: Path) -> None:
    path = tmp_path / "reset.mcap"
    record(path, load_scenario("one-joint-10"), make_strategy("random"), steps=0, seed=0)
    recording = open_recording(path)
    assert recording.n_steps == 0
    assert len(recording.steps()) == 1
    assert len(recording.memory()) == 1
    assert recording.model_at(0) == TransitionSystem.universal(recording.scenario.actions)
    assert len(recording.events()) == 0


# ---------------------------------------------------------------- unfinished recordings


def _chunk_offsets(path: Path) -> list[int]:
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return sorted(index.chunk_start_offset for index in summary.chunk_indexes)


@pytest.mark.parametrize("where", ["mid-chunk", "chunk-boundary"])
def test_a_truncated_recording_is_read_up_to_its_last_complete_chunk(
    refined_run: LiveRun, tmp_path: Path, where: str
) -> None:
    path, live = refined_run.path, refined_run.models
    offsets = _chunk_offsets(path)
    cut_at = offsets[len(offsets) // 2] + (200 if where == "mid-chunk" else 0)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(path.read_bytes()[:cut_at])
    with pytest.warns(
        UnfinishedRecordingWarning,
        match=r"cut\.mcap: the file was not finished; recovered \d+ steps from its complete chunks",
    ):
        recording = open_recording(cut)
    assert not recording.finished
    n = recording.n_steps
    assert recording.recovered_steps == n
    assert STEPS // 4 < n < STEPS
    assert recording.memory() == refined_run.memory.until(n)
    table = recording.steps()
    assert table.index.tolist() == list(range(n + 1))
    for step in (0, n // 2, n - 1, n):
        assert _same_model(recording.model_at(step), live[step]), f"step {step}"
    assert recording.events()["step"].max() <= n
    full = open_recording(path)
    assert recording.topic_counts["/rsstp/step"] == n + 1
    assert recording.topic_counts["/rsstp/model"] == sum(
        1 for m in full.model_versions() if m.step <= n
    )


def test_a_killed_writer_leaves_a_readable_recording(tmp_path: Path) -> None:
    path = tmp_path / "killed.mcap"
    side = tmp_path / "killed.mcap.partial"  # where it is written until it is finished
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    command = [sys.executable, "-m", "rsstp_cli.sim", "record", "three-joint"]
    command += ["--steps", "10000000", "--seed", "3", "--chunk-size", "4096", "-o", str(path)]
    process = subprocess.Popen(command, env=env, stderr=subprocess.DEVNULL)
    try:
        wait_until(
            lambda: side.exists() and side.stat().st_size >= 60_000,
            f"{side} growing to 60,000 bytes",
            process=process,
        )
    finally:
        process.send_signal(signal.SIGKILL)
        process.wait()
    assert process.returncode == -signal.SIGKILL
    assert not path.exists()
    with pytest.warns(UnfinishedRecordingWarning, match="killed.mcap.partial: the file was not"):
        recording = open_recording(side)
    n = recording.n_steps
    assert n > 0
    runner = Runner(load_scenario("three-joint"), make_strategy("random"), seed=3)
    runner.run(n)
    assert recording.memory() == runner.memory
    assert recording.model_at(n) == runner.model


# ------------------------------------------------------------ schema 3.0 and the 2.x files

SCHEMA_2 = Path(__file__).parent / "data" / "schema-2.3-two-joint-30-learner.mcap"
"""``recordings/two-joint-30-learner.mcap`` as schema 2.3 wrote it (every model message a
whole snapshot), kept when the reference recordings were re-recorded for schema 3.0."""

SCHEMA_3 = Path(__file__).parent / "data" / "schema-3.0-two-joint-30-learner.mcap"
"""The same run re-recorded for schema 3.0 (keyframes and changes), kept when the learner's
own run changed (2026-11-29): ``rsstp-sim record two-joint-30 --strategy learner --steps
12000 --seed 0`` as commit 8ad507e made it."""


def test_a_schema_2_recording_reads_as_its_schema_3_re_recording() -> None:
    """The same run in both schemas: 2.3's snapshot in every model message, 3.0's keyframes
    and changes; the reader gives the same model at every version, and the same steps."""
    with open_recording(SCHEMA_2) as old_file, open_recording(SCHEMA_3) as new_file:
        assert set(old_file.schema_versions.values()) == {"2.3"}
        assert set(new_file.schema_versions.values()) == {"3.0"}
        old, fresh = old_file.model_versions(), new_file.model_versions()
        assert len(old) == len(fresh) > 400
        for was, now in zip(old, fresh, strict=True):
            assert (was.version, was.step, was.current) == (now.version, now.step, now.current)
            assert tuple(was.states) == tuple(now.states)
            assert was.triples() == now.triples()
        assert all(m.keyframe for m in old)
        assert fresh[0].keyframe and sum(m.keyframe for m in fresh) < len(fresh) / 10
        for step in (0, 4_000, old_file.n_steps):
            assert old_file.model_at(step).snapshot() == new_file.model_at(step).snapshot()
        pd.testing.assert_frame_equal(old_file.steps(), new_file.steps())


def test_a_change_rebuilt_from_its_keyframe_is_what_the_run_had(tmp_path: Path) -> None:
    """Every version the reader gives, keyframe or change, is the live model of the run at
    that version (a strategy that splits, merges, adds and deletes)."""
    path = tmp_path / "run.mcap"
    scenario = load_scenario("three-joint")
    record(path, scenario, RandomRefiner(split=0.05, max_states=5), steps=3_000, seed=2)
    live: dict[int, dict[str, object]] = {}
    runner = Runner(scenario, RandomRefiner(split=0.05, max_states=5), seed=2)
    live[runner.model.version] = runner.model.snapshot()
    for _ in range(3_000):
        runner.step()
        live[runner.model.version] = runner.model.snapshot()
    with open_recording(path) as recording:
        versions = recording.model_versions()
        assert not all(m.keyframe for m in versions)
        for record_ in versions:
            snapshot = dict(record_.snapshot())
            expected = dict(live[record_.version])
            snapshot.pop("current"), expected.pop("current")
            assert snapshot == expected


def test_narrow_steps_and_events_hold_the_same_values(random_run: tuple[Path, Any]) -> None:
    """``narrow=True``: the integer columns in the narrowest dtype that holds their values,
    the events' text and data categorical; every value the documented table's."""
    with open_recording(random_run[0]) as recording:
        steps, events = recording.steps_and_events(geometry=False)
    with open_recording(random_run[0]) as recording:
        narrow_steps, narrow_events = recording.steps_and_events(geometry=False, narrow=True)
        again = recording.events()
    for name in steps.columns:
        values = steps[name].dropna().to_numpy()
        if name.startswith("angle_deg_"):  # 0 .. 359: always two bytes
            assert narrow_steps[name].dtype == np.int16
        if name in ("action", "state_before", "internal_state", "model_version"):
            low, high = min(-1, int(values.min())), int(values.max())  # -1: a missing value
            fits = [t for t in ("int8", "int16", "int32", "int64") if np.iinfo(t).min <= low]
            fits = [t for t in fits if high <= np.iinfo(t).max]
            assert narrow_steps[name].dtype.itemsize == np.dtype(fits[0]).itemsize, name
        pd.testing.assert_series_equal(narrow_steps[name], steps[name], check_dtype=False)
    assert isinstance(narrow_events["text"].dtype, pd.CategoricalDtype)
    assert isinstance(narrow_events["data"].dtype, pd.CategoricalDtype)
    assert narrow_events["text"].tolist() == events["text"].tolist()
    assert narrow_events["data"].tolist() == events["data"].tolist()
    pd.testing.assert_frame_equal(again, events)  # the documented table, from the kept one


def test_an_integer_column_widens_as_its_values_need() -> None:
    from rsstp_replay.reader._decode import _IntColumn

    column = _IntColumn(6)
    batches = [[1, 2], [300], [-5, 2**40, 7]]
    widths = []
    start = 0
    for batch in batches:
        column.put(slice(start, start + len(batch)), batch)
        start += len(batch)
        widths.append(column.values.dtype.itemsize)
    assert widths == [1, 2, 8]  # int8 holds 1 and 2; 300 needs int16; 2**40 int64
    assert column.values.tolist() == [1, 2, 300, -5, 2**40, 7]
