"""The truth audit: internal states against the minimal correct model."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rsstp_replay import open_recording
from rsstp_replay.audits import audit_truth
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
    assert findings.final_equivalent and findings.counterexample is None
    assert "equivalent to the truth" in findings.to_text()


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
    assert not findings.final_equivalent
    assert findings.counterexample == (0,)  # one move already tells the 4-cycle from 1 state


def test_roulette_is_redundant(tmp_path: Path) -> None:
    path = tmp_path / "roulette.mcap"
    record(path, load_scenario("thesis-roulette"), RouletteStrategy(), steps=300, seed=0)
    with open_recording(path) as rec:
        findings = audit_truth(rec)
    assert set(findings.redundant) == {0, 1, 2, 3}
    assert all(len(states) > 30 for states in findings.redundant.values())
    assert findings.final_model_states == 152
    report = findings.to_json()
    assert json.loads(json.dumps(report)) == report
    assert report["redundant_classes"]["0"] == list(findings.redundant[0])


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
        [sys.executable, "-m", "rsstp_replay", *args],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin"},
        timeout=120,
    )


def test_cli_truth_audit_and_gates(tmp_path: Path) -> None:
    path = tmp_path / "roulette.mcap"
    record(path, load_scenario("thesis-roulette"), RouletteStrategy(), steps=100, seed=0)
    shown = run_cli("audit", str(path), "--truth")
    assert shown.returncode == 0, shown.stderr
    assert "== truth ==" in shown.stdout and "redundancy: 4 true classes" in shown.stdout
    as_json = run_cli("audit", str(path), "--truth", "--json")
    assert json.loads(as_json.stdout)["truth"]["final_model_states"] == 52
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
