"""The audits: compare, determinism, summary and the report, over hand-built model versions,
live runs (through a recording-like fake) and, end to end, a real recording."""

from __future__ import annotations

import functools
import json
from collections.abc import Callable
from pathlib import Path

import msgspec
import numpy as np
import pandas as pd
import pytest
from fakes import FakeRecording, RandomRefiner, StaticRecording
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_format import records
from rsstp_replay.audits import (
    AuditReport,
    CompareFindings,
    audit_consistency,
    audit_consistency_by_version,
    audit_determinism,
    audit_summary,
    compare,
    run_audits,
)
from rsstp_replay.reader.recording import open_recording
from rsstp_sim import Memory, RandomStrategy, load_scenario
from rsstp_sim.errors import MemoryRangeError, ModelError
from rsstp_sim.memory import CompareKind
from rsstp_sim.recording import builders
from rsstp_sim.recording.recorder import record as record_run
from rsstp_sim.transition_system import TransitionSystem

# ------------------------------------------------------------------------- helpers


def versions(
    start: TransitionSystem, changes: list[tuple[int, Callable[[TransitionSystem], object]]]
) -> list[records.ModelRecord]:
    """Model messages: ``start`` at step 0 (with its operations), then one per change."""
    model = start
    result = [builders.model_record(model, step=0, operations=model.drain_operations())]
    for step, change in changes:
        change(model)
        result.append(builders.model_record(model, step=step, operations=model.drain_operations()))
    return result


def split_then_fixed() -> list[records.ModelRecord]:
    """Deterministic but incomplete, nondeterministic after a split (step 4), deterministic
    again after two deletes (steps 7 and 10), complete at 15, incomplete again at 20."""
    model = TransitionSystem(1, actions=[0, 1])
    model.add(0, 0, 0)
    return versions(
        model,
        [
            (4, lambda m: m.split(0)),  # 0 -0-> {0, 1}, 1 -0-> {0, 1}
            (7, lambda m: m.delete(0, 1, 0)),  # (0, 0) resolved, (1, 0) not yet
            (10, lambda m: m.delete(1, 0, 0)),  # 0 -0-> 0, 1 -0-> 1
            (15, lambda m: (m.add(0, 1, 1), m.add(1, 0, 1))),  # every pair has one successor
            (20, lambda m: m.delete(1, 0, 1)),  # (1, 1) empty
        ],
    )


def small_memory(steps: int = 30) -> Memory:
    memory = Memory()
    memory.reset(0, False, 0.0)
    for t in range(1, steps + 1):
        memory.append(t % 2, 0, t % 3 == 0, 0.5)
    return memory


@functools.cache
def refiner_run() -> tuple[FakeRecording, RandomRefiner]:
    strategy = RandomRefiner()
    fake = FakeRecording(load_scenario("two-joint-30"), strategy, seed=7, steps=3000)
    return fake, strategy


@functools.cache
def random_run() -> FakeRecording:
    return FakeRecording(load_scenario("one-joint-10"), RandomStrategy(), seed=3, steps=2000)


# --------------------------------------------------------------------- determinism


def test_determinism_over_hand_built_versions() -> None:
    findings = audit_determinism(split_then_fixed())
    assert [v.step for v in findings.versions] == [0, 4, 7, 10, 15, 20]
    assert [v.version for v in findings.versions] == [1, 2, 3, 4, 6, 7]
    assert [v.deterministic for v in findings.versions] == [True, False, False, True, True, True]
    assert [v.complete for v in findings.versions] == [False, False, False, False, True, False]
    assert findings.versions[1].nondeterministic == ((0, 0, (0, 1)), (1, 0, (0, 1)))
    assert findings.versions[2].nondeterministic == ((1, 0, (0, 1)),)
    assert findings.versions[0].empty == ((0, 1),)
    assert findings.versions[3].empty == ((0, 1), (1, 1))
    assert findings.final.empty == ((1, 1),)
    assert findings.deterministic_from == 10
    assert findings.first_complete_step == 15
    assert findings.complete_from is None
    assert findings.nondeterministic_versions == 2


def test_determinism_verdicts_at_the_end() -> None:
    fixed = split_then_fixed()
    # Nondeterministic at the end: never "deterministic from".
    assert audit_determinism(fixed[:3]).deterministic_from is None
    assert audit_determinism(fixed[:3]).first_complete_step is None
    # Complete at the end: both "from" steps are the step it got there.
    assert audit_determinism(fixed[:5]).complete_from == 15
    assert audit_determinism(fixed[:5]).deterministic_from == 10
    # Deterministic from the start.
    assert audit_determinism(fixed[:1]).deterministic_from == 0
    # Broken again by a later split, then fixed again: the last fix counts.
    model = TransitionSystem.from_snapshot(fixed[-1].snapshot(), version=fixed[-1].version)
    again = (
        fixed
        + versions(
            model,
            [
                (30, lambda m: m.split(1)),  # (0, 1), (1, 0) and (2, 0) go to {1, 2}
                (40, lambda m: m.delete(1, 2, 0)),
                (45, lambda m: m.delete(2, 1, 0)),
                (50, lambda m: m.delete(0, 2, 1)),
            ],
        )[1:]
    )
    findings = audit_determinism(again)
    assert [len(v.nondeterministic) for v in findings.versions[-4:]] == [3, 2, 1, 0]
    assert findings.deterministic_from == 50
    assert findings.first_complete_step == 15
    assert findings.nondeterministic_versions == 5


def test_determinism_equals_a_rebuild_of_every_version() -> None:
    fake, _ = refiner_run()
    models = fake.model_versions()
    findings = audit_determinism(fake)
    assert len(findings.versions) == len(models) > 20
    for record, found in zip(models, findings.versions, strict=True):
        report = TransitionSystem.from_snapshot(record.snapshot()).determinism_report()
        assert found.nondeterministic == report.nondeterministic
        assert found.empty == report.empty
        assert found.deterministic == record.deterministic
        assert len(found.nondeterministic) == record.nondeterministic_pairs
        assert (found.version, found.step) == (record.version, record.step)
    assert any(found.empty for found in findings.versions)
    assert any(not found.deterministic for found in findings.versions)


def test_determinism_frame() -> None:
    frame = audit_determinism(split_then_fixed()).to_frame()
    assert list(frame.columns) == [
        "version",
        "step",
        "states",
        "transitions",
        "nondeterministic_pairs",
        "empty_pairs",
        "deterministic",
    ]
    assert frame["step"].tolist() == [0, 4, 7, 10, 15, 20]
    assert frame["nondeterministic_pairs"].tolist() == [0, 2, 1, 0, 0, 0]
    assert frame["empty_pairs"].tolist() == [1, 2, 2, 2, 0, 1]
    assert frame["states"].tolist() == [1, 2, 2, 2, 2, 2]
    assert frame["transitions"].tolist() == [1, 4, 3, 2, 4, 3]
    assert frame["deterministic"].dtype == bool
    assert frame["version"].dtype == np.int64


def test_determinism_text_and_json() -> None:
    findings = audit_determinism(split_then_fixed())
    text = findings.to_text()
    assert (
        "final model (version 7, step 20): 2 states, 3 transitions; deterministic, 1 pair with "
        "no successor" in text
    )
    assert "deterministic from step 10 to the end" in text
    assert "first deterministic and complete at step 15, not at the end" in text
    assert "pairs with no successor in the final model: 1\n  state 1 action 1" in text
    nondeterministic = audit_determinism(split_then_fixed()[:2]).to_text()
    assert "nondeterministic at the end" in nondeterministic
    assert "state 0 action 0 -> [0, 1]" in nondeterministic
    data = findings.to_json()
    assert json.loads(json.dumps(data)) == data
    assert data["deterministic_from"] == 10
    assert data["final"]["empty"] == [{"state": 1, "action": 1}]
    assert len(data["versions"]) == 6


def test_determinism_refuses_inconsistent_messages() -> None:
    models = split_then_fixed()
    with pytest.raises(ModelError, match="no model message"):
        audit_determinism([])
    skipped = [models[0], *models[2:]]  # version 3's delete needs the split of version 2
    with pytest.raises(ModelError, match=r"model version 3 \(step 7\): its operations do not"):
        audit_determinism(skipped)
    wrong = models[1]
    bad_states = msgspec.structs.replace(wrong, states=(0, 1, 2))
    with pytest.raises(ModelError, match=r"model version 2 \(step 4\): its operations give"):
        audit_determinism([models[0], bad_states])
    bad_pairs = msgspec.structs.replace(wrong, nondeterministic_pairs=0)
    with pytest.raises(ModelError, match="has 2 pairs with several successors, the message says 0"):
        audit_determinism([models[0], bad_pairs])
    bad_version = msgspec.structs.replace(wrong, version=9)
    with pytest.raises(ModelError, match="to version 2, not 9"):
        audit_determinism([models[0], bad_version])


# ------------------------------------------------------------------------- summary


def test_summary_counts_what_the_live_run_did() -> None:
    fake, strategy = refiner_run()
    runner = fake.runner
    summary = audit_summary(fake)
    assert strategy.counts["split"] > 1 and strategy.counts["merge"] > 1
    assert (summary.splits, summary.merges, summary.adds, summary.deletes) == (
        strategy.counts["split"],
        strategy.counts["merge"],
        strategy.counts["add"],
        strategy.counts["delete"],
    )
    live = runner.summary()
    assert summary.steps == live.steps == 3000
    assert summary.blocked == live.blocked > 0
    assert summary.no_transition == live.no_transition > 0
    assert summary.sensations_true == live.sensations.get(True, 0) > 0
    assert summary.sensations_false == live.sensations.get(False, 0) > 0
    assert summary.final_size.states == live.model_states
    assert summary.final_size.transitions == live.model_transitions
    assert summary.final_deterministic == live.deterministic
    consistency = audit_consistency(runner.memory)
    assert summary.contradictory_states == len(consistency.contradictions) > 0
    assert summary.first_contradiction_step == consistency.first_contradiction_step
    assert summary.last_contradiction_step == max(
        found.first_step for found in consistency.contradictions
    )
    frame = summary.to_frame()
    assert list(frame.columns) == ["version", "step", "states", "transitions"]
    assert len(frame) == len(fake.model_versions())
    assert frame["version"].tolist() == [m.version for m in fake.model_versions()]
    assert frame["version"].iloc[-1] == runner.model.version
    assert frame["step"].iloc[0] == 0  # the split at reset is recorded at step 0
    text = summary.to_text()
    assert f"steps: {live.steps:,}" in text
    assert f"blocked moves: {live.blocked}" in text
    assert f"operations: {summary.splits} splits, {summary.merges} merges" in text
    data = summary.to_json()
    assert json.loads(json.dumps(data)) == data
    assert data["operations"]["delete"] == strategy.counts["delete"]


# ---------------------------------------------------------------------- the report


def test_report_text_and_json() -> None:
    fake, _ = refiner_run()
    report = run_audits(fake)
    assert isinstance(report, AuditReport)
    count = len(report.consistency.contradictions)
    first = report.consistency.first_contradiction_step
    text = report.to_text()
    for heading in ("== summary ==", "== consistency ==", "== determinism =="):
        assert heading in text
    assert (
        f"accumulated over the whole history (state ids across versions): {count:,} "
        f"contradictory states, first at step {first}\n"
    ) in text
    for found in report.consistency.contradictions[:10]:
        assert f"  state {found.state}: contradictory from step {found.first_step};" in text
    within = report.within_versions
    assert within == audit_consistency_by_version(
        fake.runner.memory, fake.steps()["model_version"].to_numpy()
    )
    assert f"within each model version: {len(within.contradictions):,} states contradicted" in text
    assert f"steps: {fake.n_steps:,}" in text
    assert "determinism: final model (version" in text
    data = report.to_json()
    assert json.loads(json.dumps(data)) == data
    assert set(data) == {
        "has_contradiction",
        "ever_contradicted",
        "has_nondeterminism",
        "summary",
        "consistency_within_versions",
        "consistency",
        "determinism",
        "contract",
    }
    assert data["contract"] == {"holds": True, "violations": []}
    assert "contract: holds at every one of the" in text
    final = report.determinism.final.version
    in_final = any(found.version == final for found in within.contradictions)
    assert data["has_contradiction"] is report.has_contradiction is in_final
    assert data["ever_contradicted"] is report.ever_contradicted is True
    assert report.has_nondeterminism == (not fake.runner.model.is_deterministic())
    assert report.summary == audit_summary(fake)
    assert report.determinism == audit_determinism(fake)
    assert report.consistency == audit_consistency(fake.runner.memory)


def test_report_fails_on_the_final_model_only() -> None:
    memory = small_memory()
    fixed = run_audits(StaticRecording(split_then_fixed(), memory))
    assert not fixed.has_nondeterminism
    assert fixed.ever_nondeterministic
    broken = run_audits(StaticRecording(split_then_fixed()[:3], memory))
    assert broken.has_nondeterminism
    assert broken.to_json()["has_nondeterminism"] is True
    # The same one-state memory: a contradiction, or not, independently of the model.
    assert fixed.has_contradiction == (not audit_consistency(memory).consistent)


def test_report_of_a_consistent_run() -> None:
    memory = Memory()
    memory.reset(0, False, 0.0)
    for t in range(1, 11):
        memory.append(0, t, t == 10, 0.5)  # every time its own state: nothing to contradict
    model = TransitionSystem.universal([0])
    report = run_audits(StaticRecording(versions(model, []), memory))
    assert not report.has_contradiction
    assert "within each model version: no contradictory state in 10 steps" in report.to_text()
    assert "accumulated over the whole history: no contradictory state" in report.to_text()
    assert report.summary.first_contradiction_step is None
    assert report.summary.last_contradiction_step is None
    assert "contradictions: none" in report.summary.to_text()


def test_random_strategy() -> None:
    fake = random_run()
    report = run_audits(fake)
    universal = TransitionSystem.universal(fake.runner.scenario.actions)
    # The random strategy never refines: one model version, the universal model, which is
    # deterministic and complete (one self-loop per action) from step 0.
    assert len(report.determinism.versions) == 1
    assert report.determinism.deterministic_from == 0
    assert report.determinism.first_complete_step == 0
    assert report.determinism.complete_from == 0
    assert not report.has_nondeterminism and not report.ever_nondeterministic
    summary = report.summary
    assert summary.operations == 0
    assert (summary.final_size.states, summary.final_size.transitions) == (
        1,
        len(universal.transitions()),
    )
    assert summary.no_transition == 0
    assert summary.blocked == 0  # one joint, no obstacle
    # One internal state for 36 poses while the sensation varies: the memory contradicts it
    # (the walk returns to the feedback pose from both sides, and leaves it).
    sensations = fake.memory().sensations
    assert sensations.any() and not sensations.all()
    assert report.has_contradiction
    # One version: the within-versions audit is the whole-history one, each finding naming it.
    assert report.within_versions == audit_consistency_by_version(
        fake.memory(), fake.steps()["model_version"].to_numpy()
    )
    assert {found.version for found in report.within_versions.contradictions} == {
        report.determinism.final.version
    }
    (found,) = report.consistency.contradictions
    assert found.state == 0
    witness = found.witness
    actions, seen = fake.memory().actions, fake.memory().sensations
    i, j, k = witness.i, witness.j, witness.k
    assert tuple(actions[i + 1 : i + k + 1]) == tuple(actions[j + 1 : j + k + 1])
    assert seen[i + k] != seen[j + k]
    assert summary.first_contradiction_step == summary.last_contradiction_step == found.first_step


# ------------------------------------------------------------------------- compare


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_compare_equals_the_live_compare(data: st.DataObject) -> None:
    fake, _ = refiner_run()
    live = fake.runner.memory
    n = data.draw(st.integers(0, live.steps), label="n")
    m = data.draw(st.integers(0, live.steps).filter(lambda x: x != n), label="m")
    expected = live.compare(n, m)
    found = compare(fake, n, m)
    assert (found.kind, found.offset, found.length, found.n, found.m) == (
        expected.kind,
        expected.offset,
        expected.length,
        expected.n,
        expected.m,
    )
    assert compare(live, n, m) == found


def test_compare_findings() -> None:
    memory = Memory()
    memory.reset(0, False, 0.1)
    for action, sensation in [(1, True), (0, False), (1, True), (0, True), (1, True)]:
        memory.append(action, 0, sensation, 0.5)
    found = compare(memory, 2, 0)  # the thesis's Figure 11
    assert found == CompareFindings(CompareKind.DIFFERENT_SENSATION, 2, 4, 2, 0)
    assert found.decided_at == (4, 2)
    assert found.to_text() == (
        "compare(2, 0): different (sensation) at offset 2 (steps 4 and 2); "
        "sub-memories of 4 entries"
    )
    assert found.to_json() == {
        "kind": "different_sensation",
        "offset": 2,
        "length": 4,
        "n": 2,
        "m": 0,
    }
    identical = compare(memory, 5, 3)
    assert identical.kind is CompareKind.IDENTICAL and identical.decided_at is None
    assert "no difference over the 1 entry of" in identical.to_text()
    assert compare(memory, 3, 4).to_text().startswith("compare(3, 4): unknown (the actions differ)")
    with pytest.raises(MemoryRangeError, match="the starts must differ"):
        compare(memory, 3, 3)
    with pytest.raises(MemoryRangeError, match="both starts must be in"):
        compare(memory, 0, 6)


def test_fake_steps_table_matches_the_live_memory() -> None:
    fake, _ = refiner_run()
    assert fake.memory() == fake.runner.memory
    steps = fake.steps()
    assert steps["action"].dtype == pd.Int64Dtype()
    assert steps["action"].isna().tolist()[:2] == [True, False]


# ---------------------------------------------------------------------- end to end


def test_audits_of_a_real_recording_equal_those_of_the_live_run(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    record_run(path, load_scenario("two-joint-30"), RandomRefiner(), steps=3000, seed=7)
    fake, _ = refiner_run()  # the same scenario, strategy, seed and steps, observed live
    with open_recording(path) as recording:
        report = run_audits(recording)
        assert report == run_audits(fake)
        assert report.to_json() == run_audits(fake).to_json()
        live = fake.runner.memory
        rng = np.random.default_rng(0)
        for n, m in rng.integers(0, recording.n_steps + 1, size=(200, 2)):
            if n != m:
                assert compare(recording, int(n), int(m)) == compare(live, int(n), int(m))
    assert report.summary.blocked == fake.runner.blocked > 0
    assert report.summary.splits == refiner_run()[1].counts["split"]


def test_a_loaded_recording_keeps_what_the_audits_read_once(tmp_path: Path) -> None:
    """The steps table read for the audits: the recording's table less the geometry and
    the blocker's details, its angles in two bytes and its other integer columns in the
    narrowest dtype of their values, its memory columns shared with the memory (one copy),
    the values unchanged."""
    from rsstp_replay.audits.loaded import load

    path = tmp_path / "run.mcap"
    record_run(path, load_scenario("two-joint-30"), RandomRefiner(), steps=2000, seed=7)
    with open_recording(path) as recording:
        loaded = load(recording)
        table, full = loaded.steps(), recording.steps(geometry=False)
        memory = loaded.memory()
    detail = {"blocked_kind", "blocked_joint", "blocked_link", "blocked_obstacle"}
    detail |= {"blocked_link_i", "blocked_link_j"}
    assert detail <= set(full.columns)
    assert list(table.columns) == [name for name in full.columns if name not in detail]
    assert table.index.equals(full.index)

    def narrowest(column: pd.Series) -> str:
        values = [-1, *column.dropna().tolist()]  # -1: where a nullable column is missing
        dtype = next(
            t for t in ("int8", "int16", "int32", "int64")
            if np.iinfo(t).min <= min(values) and max(values) <= np.iinfo(t).max
        )  # fmt: skip
        return dtype.capitalize() if isinstance(column.dtype, pd.Int64Dtype) else dtype

    narrow = {name: narrowest(full[name]) for name in ("action", "state_before", "model_version")}
    narrow |= {name: "int16" for name in table.columns if name.startswith("angle_deg_")}
    for name in table.columns:
        assert str(table[name].dtype) == narrow.get(name, str(full[name].dtype)), name
        pd.testing.assert_series_equal(table[name], full[name], check_dtype=False)
    for name, column in (
        ("internal_state", memory.internal_states),
        ("sensation", memory.sensations),
        ("feedback", memory.feedback),
    ):
        assert np.shares_memory(table[name].to_numpy(), column)
