"""A strategy as the policy of a Gymnasium episode (StrategyPolicy): the episode is the run the
strategy makes with the same seed, and it terminates where the strategy stops the run."""

from __future__ import annotations

import doctest
from pathlib import Path
from typing import Any

import gymnasium
import pytest

from rsstp_replay import open_recording
from rsstp_sim import RandomStrategy, Runner, env_strategy, load_scenario
from rsstp_sim.env_strategy import StrategyPolicy
from rsstp_sim.errors import EnvError
from rsstp_sim.recording.env_wrapper import RecordMcap
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.strategies import LearnerStrategy

ENV_ID = "rsstp_sim:rsstp/Arm-v0"


def play(env: gymnasium.Env[Any, Any], seed: int) -> tuple[list[int], bool, dict[str, Any]]:
    """An episode with the strategy's actions: the action ids taken, whether it terminated,
    the last info."""
    assert isinstance(env, StrategyPolicy) or isinstance(env.env, StrategyPolicy)
    policy = env if isinstance(env, StrategyPolicy) else env.env
    assert isinstance(policy, StrategyPolicy)
    _, info = env.reset(seed=seed)
    taken: list[int] = []
    terminated = truncated = False
    while not (terminated or truncated):
        assert info["strategy_action"] == policy.action
        _, _, terminated, truncated, info = env.step(policy.action)
        taken.append(int(info["action"]))
    return taken, terminated, info


def test_the_docstring_example_runs() -> None:
    failures, tried = doctest.testmod(env_strategy, raise_on_error=False)
    assert tried > 0 and failures == 0


@pytest.mark.parametrize(
    "scenario", ["one-joint-10", pytest.param("two-joint-30", marks=pytest.mark.slow)]
)
def test_the_episode_terminates_where_the_learner_stops_its_run(scenario: str) -> None:
    env = StrategyPolicy(
        gymnasium.make(ENV_ID, scenario=scenario, max_episode_steps=20_000), LearnerStrategy()
    )
    taken, terminated, info = play(env, seed=3)
    runner = Runner(load_scenario(scenario), LearnerStrategy(), seed=3)
    runner.run(20_000)
    assert runner.stopped is not None and runner.stopped.startswith("done: ")
    assert taken == runner.memory.actions[1:].tolist()  # the same run, step for step
    assert terminated and len(taken) == runner.step_index < 20_000
    assert info["stopped"] == runner.stopped
    assert info["stop"] == f"stopped by the strategy at step {len(taken):,} of a budget of 20,000"
    assert info["strategy_action"] is None and env.action is None
    assert env.agent.model.to_matrix() == runner.model.to_matrix()
    with pytest.raises(EnvError, match=r"ended the episode at step [\d,]+ \(done: .*call reset"):
        env.step(0)
    # A new episode starts the strategy afresh.
    again, terminated, _ = play(env, seed=3)
    assert terminated and again == taken


def test_a_strategy_that_never_stops_runs_to_the_time_limit() -> None:
    env = StrategyPolicy(
        gymnasium.make(ENV_ID, scenario="three-joint", max_episode_steps=300), RandomStrategy()
    )
    taken, terminated, info = play(env, seed=5)
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=5)
    runner.run(300)
    assert not terminated and "stopped" not in info
    assert taken == runner.memory.actions[1:].tolist()


def test_float_feedback_reaches_the_strategy() -> None:
    scenario = load_scenario("two-joint-30")
    twin = scenario.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    assert twin != scenario.source
    env = StrategyPolicy(
        gymnasium.make(ENV_ID, scenario=parse_scenario(twin), max_episode_steps=50_000),
        LearnerStrategy(),
    )
    env.reset(seed=0)
    assert env.agent.float_feedback


def test_a_recorded_episode_ends_with_the_stop_event(tmp_path: Path) -> None:
    env = RecordMcap(
        StrategyPolicy(
            gymnasium.make(ENV_ID, scenario="thesis-roulette", max_episode_steps=100),
            LearnerStrategy(),
        ),
        tmp_path,
    )
    taken, terminated, info = play(env, seed=0)
    env.close()
    assert terminated
    with open_recording(env.recordings[0]) as recording:
        assert recording.n_steps == len(taken)
        assert recording.steps()["action"].tolist()[1:] == taken
        assert recording.events()["text"].tolist()[-1] == (
            f"stopped by the strategy at step {len(taken)}: {info['stopped']}"
        )


def test_refusals_are_one_line() -> None:
    env = StrategyPolicy(gymnasium.make(ENV_ID, scenario="two-joint-30"), LearnerStrategy())
    with pytest.raises(EnvError, match=r"call reset\(\) before step\(\)"):
        env.step(0)
    env.reset(seed=0)
    assert env.action is not None
    other = (env.action + 1) % int(env.action_space.n)
    with pytest.raises(EnvError, match=rf"chose action index {env.action}, step\(\) was given"):
        env.step(other)
    with pytest.raises(EnvError, match="not CartPoleEnv"):
        StrategyPolicy(gymnasium.make("CartPole-v1"), LearnerStrategy())
    with pytest.raises(EnvError, match="needs a strategy, got int"):
        StrategyPolicy(gymnasium.make(ENV_ID), 3)  # type: ignore[arg-type]
