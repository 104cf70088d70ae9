"""The truth audit: internal states against the minimal correct model."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rsstp_replay import open_recording
from rsstp_replay.audits import audit_truth, truth_table
from rsstp_sim import (
    AgentView,
    RandomStrategy,
    ScriptStrategy,
    StrategyBase,
    TransitionSystem,
    load_scenario,
)
from rsstp_sim.recording import record
from rsstp_sim.strategies import RouletteStrategy
from rsstp_sim.truth import compute_truth
from waiting import HANG_S

SRC = Path(__file__).resolve().parents[2] / "src"


class Oracle(StrategyBase):
    """Random actions with the true minimal model as the internal model (a test double)."""

    name = "oracle"

    def __init__(self, model: TransitionSystem) -> None:
        self._model = model

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        return self._model.copy()

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]


def test_the_true_model_matches_the_truth_at_every_step(tmp_path: Path) -> None:
    scenario = load_scenario("two-joint-30")
    truth = compute_truth(scenario)
    path = tmp_path / "oracle.mcap"
    record(path, scenario, Oracle(truth.minimal_model()), steps=3000, seed=2)
    with open_recording(path) as rec:
        steps = rec.steps(truth=True)
        findings = audit_truth(rec)
    assert (steps["internal_state"] == steps["true_class"]).all()
    assert findings.aliased == {} and findings.redundant == {}
    assert findings.first_mismatch_step is None
    assert findings.verdict.learned and findings.counterexample is None
    # The one version is right from the reset: learned at step 0, every figure zero.
    assert findings.learned_at_step == 0
    assert findings.to_text().startswith(
        "verdict: learned: equivalent to the minimal model (119 states) from step 0 to the end"
    )
    (row,) = findings.versions.itertuples()
    assert (row.aliased_states, row.redundant_classes, row.contradictory_states) == (0, 0, 0)
    assert row.equivalent and row.steps_in_force == 3001


def test_a_one_state_model_aliases_every_class(tmp_path: Path) -> None:
    path = tmp_path / "script.mcap"
    record(path, load_scenario("thesis-roulette"), ScriptStrategy(), steps=20, seed=0)
    with open_recording(path) as rec:
        findings = audit_truth(rec)
        true_class = rec.steps(truth=True)["true_class"].to_numpy()
    assert true_class.tolist()[:5] == [0, 1, 2, 3, 0]
    assert findings.aliased == {0: (0, 1, 2, 3)}
    assert findings.first_aliasing_step == 1
    assert findings.redundant == {}
    assert not findings.verdict.learned
    # One move already tells the 4-cycle from one state: the model stays in state 0, which it
    # labels with the sensation last seen there (true at step 20), the world senses false.
    example = findings.counterexample
    assert example is not None and example.actions == (0,)
    assert (example.from_state, example.from_step, example.true_class) == (0, 20, 0)
    assert example.model_states == (0,)
    assert example.predicted == (True,) and example.actual == (False,)
    assert example.last_changed_step is None  # the one-state model never changed
    assert findings.learned_at_step is None
    assert findings.verdict.line() == (
        "not learned: 1 state for 4 true classes after 20 steps; the model has not changed "
        "size since step 0"
    )


def test_roulette_is_redundant(tmp_path: Path) -> None:
    path = tmp_path / "roulette.mcap"
    record(path, load_scenario("thesis-roulette"), RouletteStrategy(), steps=300, seed=0)
    with open_recording(path) as rec:
        findings = audit_truth(rec)
    assert set(findings.redundant) == {0, 1, 2, 3}
    assert all(len(states) > 30 for states in findings.redundant.values())
    assert findings.verdict.final_states == 152
    report = findings.to_json()
    assert json.loads(json.dumps(report)) == report
    assert report["history"]["redundant_classes"]["0"] == list(findings.redundant[0])
    # The verdict: ever growing, 152 states at 300 steps, 76 at 150: about half a state a step.
    assert report["learned_at_step"] is None
    assert report["verdict"]["growth_per_step"] == pytest.approx((152 - 76) / 150, abs=0.02)
    assert findings.verdict.line().startswith(
        "not learned: 152 states for 4 true classes after 300 steps; the model grows by about 0.5"
    )
    # Its counterexample starts at the final state; the path's transitions changed last at
    # the final step (roulette splits at every move).
    example = report["counterexample"]
    assert example["from_step"] == 300 and example["last_changed_step"] == 300
    # Within each version nothing is redundant: roulette never revisits a state it made.
    versions = findings.versions
    assert (versions["redundant_classes"] == 0).all()
    assert versions["states"].iloc[-1] == 152 and not versions["equivalent"].any()


def test_first_steps_are_where_the_correspondence_breaks(tmp_path: Path) -> None:
    path = tmp_path / "random.mcap"
    record(path, load_scenario("thesis-algo"), RandomStrategy(), steps=500, seed=3)
    with open_recording(path) as rec:
        findings = audit_truth(rec)
        steps = rec.steps(truth=True)
    classes = steps["true_class"].to_numpy()
    # One internal state: aliasing starts at the first step whose class differs from step 0's.
    assert findings.first_aliasing_step == int(np.argmax(classes != classes[0]))
    assert findings.first_redundancy_step is None


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", *args],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin"},
        timeout=HANG_S,
    )


@pytest.mark.slow
def test_cli_truth_audit_and_gates(tmp_path: Path) -> None:
    path = tmp_path / "roulette.mcap"
    record(path, load_scenario("thesis-roulette"), RouletteStrategy(), steps=100, seed=0)
    shown = run_cli("audit", str(path), "--truth")
    assert shown.returncode == 0, shown.stderr
    assert shown.stdout.startswith("verdict: not learned: 52 states for 4 true classes")
    assert "== truth ==" in shown.stdout and "redundancy: 4 true classes" in shown.stdout
    as_json = run_cli("audit", str(path), "--truth", "--json")
    document = json.loads(as_json.stdout)
    assert document["truth"]["final_model_states"] == 52
    assert document["verdict"]["learned"] is False
    assert document["truth"]["learned_at_step"] is None
    not_learned = run_cli("audit", str(path), "--truth", "--fail-on", "not-learned")
    assert not_learned.returncode == 1
    assert "audit failed: not learned: 52 states" in not_learned.stderr
    gated = run_cli("audit", str(path), "--truth", "--fail-on", "redundancy")
    assert gated.returncode == 1
    assert "a true class was split over several states" in gated.stderr
    usage = run_cli("audit", str(path), "--fail-on", "not-equivalent")
    assert usage.returncode == 2
    assert usage.stderr.strip().endswith("--fail-on not-equivalent needs --truth")
    assert "Traceback" not in usage.stderr


@pytest.mark.parametrize("name", ["thesis-roulette", "two-joint-30"])
def test_true_class_column_is_the_truth_of_each_pose(name: str, tmp_path: Path) -> None:
    scenario = load_scenario(name)
    path = tmp_path / "run.mcap"
    record(path, scenario, RandomStrategy(), steps=200, seed=5)
    truth = compute_truth(scenario)
    with open_recording(path) as rec:
        steps = rec.steps(truth=True)
    angles = steps[[f"angle_deg_{j}" for j in range(scenario.n_joints)]].to_numpy()
    assert steps["true_class"].tolist() == [truth.class_of(list(a)) for a in angles]


LEARNER = Path(__file__).resolve().parents[2] / "recordings" / "two-joint-30-learner.mcap"


def test_a_learner_that_learned_reads_as_learned() -> None:
    """The reference learner run: learned, from the step its final version came into force;
    judged within versions, nothing is wrong at the end, though the accumulated history (state
    ids across versions) is full of aliasing."""
    with open_recording(LEARNER) as rec:
        findings = audit_truth(rec)
        versions = list(rec.model_versions())
    assert findings.verdict.learned
    learned = findings.learned_at_step
    assert learned is not None
    versions_table = findings.versions
    suffix = versions_table.loc[versions_table["step"] >= learned]
    assert suffix["equivalent"].all()
    before = versions_table.loc[versions_table["step"] < learned]
    assert not before["equivalent"].iloc[-1]  # the stretch starts right there
    assert learned == versions[len(before)].step
    final = versions_table.iloc[-1]
    assert (final.aliased_states, final.redundant_classes, final.contradictory_states) == (0, 0, 0)
    assert findings.final_aliased == {} and findings.final_redundant == {}
    assert findings.aliased  # the accumulated figure stays, and says otherwise
    assert findings.verdict.line() == (
        f"learned: equivalent to the minimal model (119 states) from step {learned:,} to the end"
    )
    assert len(versions_table) == len(versions)
    assert versions_table["version"].tolist() == [v.version for v in versions]


def test_aliasing_within_a_version_against_a_brute_force_count() -> None:
    """Per version, an aliased state is one whose steps under that version had several true
    classes: count it the slow way."""
    with open_recording(LEARNER) as rec:
        findings = audit_truth(rec)
        steps = rec.steps()
    table = steps.assign(true_class=findings.true_class)
    expected = (
        table.groupby(["model_version", "internal_state"])["true_class"]
        .nunique()
        .gt(1)
        .groupby(level=0)
        .sum()
    )
    got = findings.versions.set_index("version")["aliased_states"]
    assert got.loc[expected.index].tolist() == expected.tolist()
    aliased = table.groupby(["model_version", "internal_state"])["true_class"].transform("nunique")
    assert findings.aliased_step.tolist() == (aliased > 1).tolist()


def test_the_counterexample_names_the_step_its_path_last_changed(tmp_path: Path) -> None:
    """A strategy that learns the 4-cycle, then breaks one transition late: the counterexample
    runs through the broken transition, and names the step it was broken at."""

    class BreakLate(StrategyBase):
        name = "break-late"

        def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
            return compute_truth(load_scenario("thesis-roulette")).minimal_model()

        def choose_action(self, agent: AgentView) -> int:
            return 0

        def refine(self, agent: AgentView) -> None:
            if agent.step == 30:  # 2 -0-> 3 becomes 2 -0-> 0
                agent.model.delete(2, 3, 0)
                agent.model.add(2, 0, 0)

    path = tmp_path / "break.mcap"
    record(path, load_scenario("thesis-roulette"), BreakLate(), steps=41, seed=0)
    with open_recording(path) as rec:
        findings = audit_truth(rec)
    assert findings.learned_at_step is None
    versions = findings.versions
    assert versions["equivalent"].tolist() == [True, False]  # both changes in one message
    example = findings.counterexample
    assert example is not None
    # Step 41 ends in state 1 (class 1): actions 0, 0 reach state 0 instead of 3; the model
    # predicts the start's sensation (true) where the world senses false.
    assert example.from_state == 1 and example.actions == (0, 0)
    assert example.model_states == (2, 0)
    assert example.predicted == (False, True) and example.actual == (False, False)
    assert example.last_changed_step == 30
    text = findings.to_text()
    assert "the transitions on that path last changed at step 30" in text


def test_the_truth_table_gives_class_pose_and_aliasing_per_step() -> None:
    with open_recording(LEARNER) as rec:
        table = truth_table(rec)
        findings = audit_truth(rec)
        truth = rec.ground_truth()
    angles = table[["angle_deg_0", "angle_deg_1"]].to_numpy()
    assert (truth.angles_deg[table["pose"].to_numpy()] == angles).all()
    assert (truth.true_class[table["pose"].to_numpy()] == table["true_class"].to_numpy()).all()
    assert table["aliased"].tolist() == findings.aliased_step.tolist()
    # After the learner's last version came into force, no step is aliased.
    learned = findings.learned_at_step
    assert learned is not None
    assert not table.loc[learned:, "aliased"].any()
    assert table.loc[: learned - 1, "aliased"].any()
