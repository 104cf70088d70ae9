"""The step records agree with the model messages at every step, for every strategy.

The property: for every step ``t`` of a recording, its internal state is the current state of
``model_at(t)`` (the version in force at the end of the step) and a state of it, step ``t + 1``
starts there, and the step names that version. Checked at every step (no sampling) over
strategies (the built-ins, a random refiner that splits, merges, adds and deletes, and one that
re-localises by setting ``model.current``), scenarios and seeds.
"""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from fakes import RandomRefiner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rsstp_format.records import ModelRecord
from rsstp_replay import open_recording
from rsstp_replay.audits.contract import check_contract
from rsstp_sim import AgentView, load_scenario, make_strategy
from rsstp_sim.recording import record
from rsstp_sim.runner import Runner
from rsstp_sim.strategies import Strategy
from waiting import HANG_S

REFERENCE = Path(__file__).resolve().parents[2] / "recordings"


class Relocator(RandomRefiner):
    """A random refiner that also re-localises: now and then it decides it is elsewhere."""

    name: ClassVar[str] = "relocator"

    def refine(self, agent: AgentView) -> None:
        super().refine(agent)
        if float(agent.rng.random()) < 0.2:
            states = agent.model.states
            agent.model.current = states[int(agent.rng.integers(len(states)))]


def _strategy(name: str) -> Strategy:
    if name == "refiner":
        return RandomRefiner(split=0.1, max_states=8)
    if name == "relocator":
        return Relocator(split=0.1, max_states=8)
    return make_strategy(name)


STRATEGIES = ["random", "roulette", "splitter", "learner", "refiner", "relocator"]
SCENARIOS = ["thesis-roulette", "one-joint-10", "two-joint-30", "thesis-obstacles"]


@pytest.mark.slow
@settings(
    max_examples=24,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    strategy=st.sampled_from(STRATEGIES),
    scenario=st.sampled_from(SCENARIOS),
    seed=st.integers(0, 2**16),
    steps=st.integers(1, 160),
)
def test_every_step_is_in_the_current_state_of_its_model_version(
    strategy: str, scenario: str, seed: int, steps: int
) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.mcap"
        record(path, load_scenario(scenario), _strategy(strategy), steps=steps, seed=seed)
        with open_recording(path) as recording:
            assert check_contract(recording).holds, check_contract(recording).to_text()
            table = recording.steps()
            states = table["internal_state"].to_numpy(np.int64)
            versions = table["model_version"].to_numpy(np.int64)
            before = table["state_before"].to_numpy(np.int64, na_value=-1)
            for t in range(recording.n_steps + 1):
                model = recording.model_at(t)
                assert model.current == states[t], f"step {t}"
                assert model.version == versions[t], f"step {t}"
                if t:
                    assert before[t] == states[t - 1], f"step {t}"


def test_the_live_memory_ends_each_step_where_the_model_is() -> None:
    """A re-localising strategy: the memory entry of a step is the model's current state at
    the end of the step, not the successor the transition led to."""
    runner = Runner(load_scenario("one-joint-10"), Relocator(split=0.2, max_states=8), seed=3)
    relocated = 0
    for _ in range(300):
        outcome = runner.step()
        assert runner.memory.last_state == runner.model.current == outcome.state_after
        relocated += outcome.followed != outcome.state_after
    assert relocated > 10


@pytest.mark.parametrize("path", sorted(REFERENCE.glob("*.mcap")), ids=lambda p: p.name)
def test_reference_recordings_keep_the_contract(path: Path) -> None:
    with open_recording(path) as recording:
        assert check_contract(recording).holds


@pytest.mark.parametrize("block", [None, 1, 7, 20])
def test_a_broken_chain_is_found_at_its_first_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, block: int | None
) -> None:
    """The check reads the columns, not the live run: feed it a step that starts elsewhere,
    a step in a state its version lacks, and a step naming the wrong version (each twice:
    the first and the count are found whatever the blocks of steps checked together)."""
    import rsstp_replay.audits.contract as contract

    if block is not None:
        monkeypatch.setattr(contract, "_BLOCK", block)
    path = tmp_path / "run.mcap"
    record(path, load_scenario("thesis-roulette"), make_strategy("roulette"), steps=40, seed=0)
    with open_recording(path) as recording:
        table, versions = recording.steps(), list(recording.model_versions())
        times, events = recording.step_log_times(), recording.events()

    edited = table.copy()
    edited.loc[[20, 27], "state_before"] = 999
    edited.loc[[30, 39], "internal_state"] = 998
    edited.loc[[35, 21], "model_version"] = 997
    found = check_contract(_Edited(edited, versions, times, events))  # type: ignore[arg-type]
    rules = {v.rule: (v.step, v.count) for v in found.violations}
    # A step in another state breaks the chain at the step after it too (31, 40: 4 in all).
    assert rules == {
        "state-chain": (20, 4),
        "state-in-model": (30, 2),
        "model-version": (21, 2),
    }
    assert "step 30 is in internal state 998" in found.to_text()
    assert "step 21 names model version 997" in found.to_text()


@pytest.mark.slow
def test_check_and_audit_gate_on_the_contract(tmp_path: Path) -> None:
    """`rsstp-replay check` exits 0 on a recording that keeps the contract and 1 on one that
    breaks it (a step edited to start in another state), naming the rule and the step; `audit
    --fail-on contract` exits 1 on the same."""
    import json
    import subprocess
    import sys

    from test_corrupt import edit_json, rewrite

    good = tmp_path / "good.mcap"
    record(good, load_scenario("thesis-roulette"), make_strategy("roulette"), steps=40, seed=0)

    def elsewhere(step: dict[str, object]) -> None:
        agent = step["agent"]
        assert isinstance(agent, dict)
        agent["state_before"] = agent["internal_state"] = 0  # roulette has moved on from 0

    bad = rewrite(good, tmp_path / "bad.mcap", message=edit_json("/rsstp/step", 25, elsewhere))

    def cli(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [sys.executable, "-m", "rsstp_cli.replay", *args],
            capture_output=True,
            text=True,
            timeout=HANG_S,
        )

    ok = cli("check", str(good))
    assert ok.returncode == 0, ok.stderr
    assert "contract: holds at every one of the 41 steps" in ok.stdout
    broken = cli("check", str(bad))
    assert broken.returncode == 1
    assert "state-chain: from step 25 (2 step(s)): step 25 starts in state 0" in broken.stdout
    as_json = json.loads(cli("check", "--json", str(bad)).stdout)
    assert {v["rule"] for v in as_json["violations"]} == {"state-chain"}  # 0 is still a state
    gated = cli("audit", str(bad), "--fail-on", "contract")
    assert gated.returncode == 1
    assert "the steps break the recording contract" in gated.stderr
    assert cli("audit", str(good), "--fail-on", "contract").returncode == 0


def test_log_times_and_event_steps_are_checked(tmp_path: Path) -> None:
    """A step logged off its step x 1,000,000 ns, and an event naming a step the recording
    does not have (its log time agreeing, so the reader takes it), are contract findings."""
    import json

    from test_corrupt import rewrite

    good = tmp_path / "good.mcap"
    record(good, load_scenario("thesis-roulette"), make_strategy("roulette"), steps=40, seed=0)

    def late(topic: str, log_time: int) -> int:
        return log_time + 500_000 if topic == "/rsstp/step" and log_time >= 30_000_000 else log_time

    retimed = rewrite(good, tmp_path / "retimed.mcap", retime=late)
    with open_recording(retimed) as recording:
        found = check_contract(recording)
    assert [(v.rule, v.step, v.count) for v in found.violations] == [("log-time", 30, 11)]
    assert "step 30 is logged at 30,500,000 ns, not 30,000,000" in found.to_text()

    def far(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/event" or log_time != 40_000_000:
            return data
        event = json.loads(data)
        event["step"] = 1_000_000
        return json.dumps(event).encode()

    def far_time(topic: str, log_time: int) -> int:
        return (
            1_000_000 * 1_000_000
            if topic == "/rsstp/event" and log_time == 40_000_000
            else log_time
        )

    with open_recording(good) as recording:
        assert (recording.events()["step"] == 40).any()  # roulette notes its last step
    moved = rewrite(good, tmp_path / "moved.mcap", message=far, retime=far_time)
    with open_recording(moved) as recording:
        found = check_contract(recording)
    assert [v.rule for v in found.violations] == ["event-in-range"]
    assert "names step 1,000,000, outside the recording's steps 0 to 40" in found.to_text()


def test_a_model_message_whose_current_state_is_not_its_steps_is_found(tmp_path: Path) -> None:
    """The one place a recording says the current state twice: the last model message of a
    step names it, and so does the step record. Rewrite one message's current state to another
    state of its version: `model-current`, at that message's step, and nothing else."""
    import msgspec

    path = tmp_path / "run.mcap"
    record(path, load_scenario("thesis-roulette"), make_strategy("learner"), steps=60, seed=0)
    with open_recording(path) as recording:
        table, versions = recording.steps(), list(recording.model_versions())
        times, events = recording.step_log_times(), recording.events()
    assert check_contract(_Edited(table, versions, times, events)).holds
    k = next(i for i, v in enumerate(versions) if v.step > 0 and len(v.states) > 1)
    other = next(s for s in versions[k].states if s != versions[k].current)
    changed = [*versions]
    changed[k] = msgspec.structs.replace(versions[k], current=other)
    found = check_contract(_Edited(table, changed, times, events))
    assert [(v.rule, v.step, v.count) for v in found.violations] == [
        ("model-current", versions[k].step, 1)
    ]
    assert f"says the current state is {other}" in found.to_text()


class _Edited:
    """A recording's columns, some of them edited, as the contract check reads them."""

    def __init__(self, table: object, versions: list[ModelRecord], times: object, events: object):
        self.table, self.versions, self.times, self.event_table = table, versions, times, events

    def steps(self, *, geometry: bool = True) -> object:
        return self.table

    def model_versions(self) -> list[ModelRecord]:
        return self.versions

    def step_log_times(self) -> object:
        return self.times

    def events(self) -> object:
        return self.event_table
