"""A strategy that ends the run, and one that records its phases: the runner, the recording
(read back with the mcap library and with rsstp_replay), ``info``, the audit summary."""

from __future__ import annotations

import json
from pathlib import Path
from typing import ClassVar

import pytest
from mcap.reader import make_reader

from rsstp_cli.replay import main as replay_main
from rsstp_cli.sim import main as sim_main
from rsstp_replay import open_recording
from rsstp_replay.audits import run_audits
from rsstp_replay.audits.loaded import load
from rsstp_sim import (
    AgentView,
    RandomStrategy,
    Runner,
    StrategyBase,
    StrategyError,
    load_scenario,
)
from rsstp_sim.recording.recorder import Recorder, record
from rsstp_sim.strategies._learner_walk import PHASES
from rsstp_sim.strategies.learner import LearnerStrategy

SCHEDULE = {1: "first", 11: "second", 31: "first"}
"""The phase :class:`Phased` enters at each step; it stops at :data:`LAST`."""
LAST = 40


class Phased(StrategyBase):
    """Turns joint 0; enters the phases of :data:`SCHEDULE`, stops after step :data:`LAST`."""

    name: ClassVar[str] = "phased"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[0]

    def refine(self, agent: AgentView) -> None:
        phase = SCHEDULE.get(agent.step)
        if phase is not None:
            agent.enter(phase)
        if agent.step == LAST:
            agent.stop("the schedule\nis over")


class StopAtOnce(StrategyBase):
    name: ClassVar[str] = "stop-at-once"

    def reset(self, agent: AgentView) -> None:
        agent.stop("nothing to do")

    def choose_action(self, agent: AgentView) -> int:  # pragma: no cover - never called
        raise AssertionError("a stopped run takes no step")


def expected_shares() -> dict[str, int]:
    """The steps 1 .. LAST per phase, counted step by step from the schedule."""
    counts: dict[str, int] = {}
    phase = None
    for step in range(1, LAST + 1):
        phase = SCHEDULE.get(step, phase)
        assert phase is not None
        counts[phase] = counts.get(phase, 0) + 1
    return counts


def test_the_runner_stops_when_the_strategy_says_so() -> None:
    runner = Runner(load_scenario("three-joint"), Phased(), seed=0)
    summary = runner.run(1000)
    assert summary.steps == runner.step_index == LAST
    assert runner.stopped == "the schedule is over"  # one line
    assert summary.budget == 1000
    assert summary.to_text().startswith(
        "stopped by the strategy at step 40 of a budget of 1,000: the schedule is over\n"
    )
    with pytest.raises(StrategyError, match="ended the run at step 40 .*no further step"):
        runner.step()
    # A strategy that never stops runs its whole budget, and says nothing of a stop.
    plain = Runner(load_scenario("three-joint"), RandomStrategy(), seed=0).run(100)
    assert (plain.steps, plain.stopped, plain.budget) == (100, None, None)
    assert "stopped" not in plain.to_text()


def test_a_recording_ends_with_the_stop_event(tmp_path: Path) -> None:
    path = tmp_path / "phased.mcap"
    result = record(path, load_scenario("three-joint"), Phased(), steps=1000, seed=0)
    assert (result.steps, result.stopped, result.budget) == (40, "the schedule is over", 1000)
    with path.open("rb") as stream:
        messages = list(make_reader(stream).iter_messages(log_time_order=False))
    steps = [json.loads(m.data)["step"] for _, c, m in messages if c.topic == "/rsstp/step"]
    assert steps == list(range(LAST + 1))
    schema, channel, last = messages[-1]
    assert channel.topic == "/rsstp/event" and last.log_time == LAST * 1_000_000
    event = json.loads(last.data)
    assert event == {
        "step": 40,
        "kind": "note",
        "text": "stopped by the strategy at step 40 of a budget of 1,000: the schedule is over",
        "data": {"stop": "the schedule is over", "budget": 1000},
    }
    phases = [
        (json.loads(m.data)["step"], json.loads(m.data)["data"]["phase"])
        for _, c, m in messages
        if c.topic == "/rsstp/event" and "phase" in json.loads(m.data)["data"]
    ]
    assert phases == sorted(SCHEDULE.items())


def test_a_strategy_may_stop_before_the_first_step(tmp_path: Path) -> None:
    path = tmp_path / "once.mcap"
    result = Recorder(path, load_scenario("thesis-roulette"), StopAtOnce(), seed=0).run(10)
    assert (result.steps, result.stopped) == (0, "nothing to do")
    with open_recording(path) as recording:
        assert recording.n_steps == 0
        assert recording.events()["text"].tolist()[-1] == (
            "stopped by the strategy at step 0 of a budget of 10: nothing to do"
        )


def test_info_and_the_audit_summary_say_how_the_run_ended(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "phased.mcap"
    record(path, load_scenario("three-joint"), Phased(), steps=1000, seed=0)
    line = "stopped by the strategy at step 40 of a budget of 1,000: the schedule is over"
    assert replay_main(["info", str(path)]) == 0
    assert f"  {line}\n" in capsys.readouterr().out
    with open_recording(path) as recording:
        summary = run_audits(load(recording)).summary
    assert summary.stop is not None and summary.stop.to_text() == line
    shares = {p.phase: (p.steps, p.share) for p in summary.phases}
    assert shares == {phase: (n, n / LAST) for phase, n in expected_shares().items()}
    text = summary.to_text()
    assert text.splitlines()[0] == line
    assert "phases: first 50.0 % (20 steps), second 50.0 % (20 steps)" in text
    found = summary.to_json()
    assert found["stopped"] == {"step": 40, "budget": 1000, "reason": "the schedule is over"}
    assert found["phases"] == {
        "first": {"steps": 20, "share": 0.5},
        "second": {"steps": 20, "share": 0.5},
    }


def test_record_cli_says_the_budget_was_not_used_up(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "learner.mcap"
    argv = ["record", "thesis-roulette", "--strategy", "learner", "--steps", "64", "-o", str(out)]
    assert sim_main([*argv, "--quiet"]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed[0].startswith("stopped by the strategy at step ")
    assert printed[0].endswith(
        " of a budget of 64: done: 4 states, every transition confirmed and tested"
    )
    used = int(printed[0].split(" at step ")[1].split(" ")[0])
    with open_recording(out) as recording:
        assert recording.n_steps == used < 64


def test_a_phase_is_one_word() -> None:
    runner = Runner(load_scenario("three-joint"), Phased(), seed=0)
    with pytest.raises(StrategyError, match="a phase is one word, got 'two words'"):
        runner.agent.enter("two words")


@pytest.mark.parametrize(
    "name", ["one-joint-10", pytest.param("thesis-algo", marks=pytest.mark.slow)]
)
def test_the_learners_phases_are_events_and_their_shares_are_its_step_counts(
    tmp_path: Path, name: str
) -> None:
    # thesis-algo starts away from its feedback pose: the run begins with a search (home).
    path = tmp_path / "learner.mcap"
    learner = LearnerStrategy()
    result = record(path, load_scenario(name), learner, steps=1_000_000, seed=0)
    assert result.stopped is not None and learner.done
    # The learner's own counters, by phase (each counter names the phase it belongs to).
    counted: dict[str, int] = {}
    for key, n in learner.stats().items():
        if key.startswith("steps_"):
            phase = PHASES[key.removeprefix("steps_")]
            counted[phase] = counted.get(phase, 0) + n
    with open_recording(path) as recording:
        events = recording.events()
        notes = events[events["kind"] == "note"]
        phased = notes[notes["data"].str.startswith('{"phase"')]
        assert set(phased["text"]) == {f"phase: {p}" for p in counted}
        assert phased["step"].is_monotonic_increasing and phased["step"].iloc[0] == 1
        summary = run_audits(load(recording)).summary
    assert {p.phase: p.steps for p in summary.phases} == counted
    assert sum(counted.values()) == result.steps
    assert set(counted) <= {"home", "explore", "identify"}
