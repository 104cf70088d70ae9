"""Recording a Gymnasium-driven run (RecordMcap): one recording per episode, in the format of
``rsstp-sim record``, with no model channel when the agent keeps no model; every replay
command reads such a file."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import gymnasium
import numpy as np
import pytest
from mcap.reader import make_reader

from rsstp_replay import open_recording
from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.errors import EnvError
from rsstp_sim.recording import record
from rsstp_sim.recording.env_wrapper import RecordMcap
from rsstp_sim.transition_system import TransitionSystem
from waiting import HANG_S

ENV_ID = "rsstp_sim:rsstp/Arm-v0"


def topics(path: Path) -> dict[str, int]:
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    return {channel.topic: counts[i] for i, channel in summary.channels.items()}


def random_episodes(folder: Path, episodes: int, steps: int, **kwargs: object) -> RecordMcap:
    env = RecordMcap(
        gymnasium.make(ENV_ID, scenario="three-joint", max_episode_steps=steps), folder, **kwargs
    )
    rng = np.random.default_rng(0)
    for episode in range(episodes):
        env.reset(seed=10 + episode)
        truncated = False
        while not truncated:
            _, _, _, truncated, _ = env.step(int(rng.integers(env.action_space.n)))
    env.close()
    return env


def test_each_episode_is_a_recording_without_a_model_channel(tmp_path: Path) -> None:
    env = random_episodes(tmp_path, episodes=2, steps=300)
    assert [p.name for p in env.recordings] == ["episode-0000.mcap", "episode-0001.mcap"]
    for path in env.recordings:
        found = topics(path)
        assert "/rsstp/model" not in found
        assert found["/rsstp/step"] == 301 and found["/rsstp/scenario"] == 1
        with open_recording(path) as recording:
            assert recording.finished and recording.n_steps == 300
            assert not recording.has_model
            steps = recording.steps()
            assert (steps["internal_state"] == 0).all() and (steps["model_version"] == 0).all()
            assert recording.strategy == "gymnasium"
            assert recording.seed in (10, 11)


def test_the_recording_is_what_the_environment_did(tmp_path: Path) -> None:
    """The agent's actions, and the truth the environment reported, step by step."""
    arm = gymnasium.make(ENV_ID, scenario="three-joint", max_episode_steps=200)
    env = RecordMcap(arm, tmp_path)
    env.reset(seed=3)
    rng = np.random.default_rng(5)
    seen = []
    for _ in range(200):
        _, _, _, _, info = env.step(int(rng.integers(6)))
        seen.append((info["action"], info["angles_deg"], info["sensation"], info["blocked"]))
    env.close()
    with open_recording(env.recordings[0]) as recording:
        steps = recording.steps()
    rows = steps.iloc[1:]
    assert rows["action"].tolist() == [a for a, _, _, _ in seen]
    angles = rows[["angle_deg_0", "angle_deg_1", "angle_deg_2"]].to_numpy()
    assert [tuple(map(int, row)) for row in angles] == [tuple(a) for _, a, _, _ in seen]
    assert rows["sensation"].tolist() == [s for _, _, s, _ in seen]
    assert rows["blocked"].tolist() == [b for _, _, _, b in seen]
    assert any(b for _, _, _, b in seen)  # blocked moves are part of the truth


def test_the_recorder_reads_the_environments_own_world(tmp_path: Path) -> None:
    """No second world beside the environment's: the recorder is handed each step, and a move
    made behind the wrapper's back is in the next step's truth (the physics check would name
    it), not silently mirrored."""
    env = RecordMcap(gymnasium.make(ENV_ID, scenario="three-joint"), tmp_path)
    env.reset(seed=1)
    recorder = env._recorder
    assert recorder is not None and recorder.runner.world is env.unwrapped.world
    env.step(0)
    env.unwrapped.world.move(2)  # behind the wrapper's back
    env.step(0)
    env.close()
    with open_recording(env.recordings[0]) as recording:
        angles = recording.steps()[["angle_deg_0", "angle_deg_1"]].to_numpy()
    start = np.array(load_scenario("three-joint").initial_deg[:2])
    step_deg = load_scenario("three-joint").step_deg
    assert angles[2].tolist() == ((start + [2 * step_deg, step_deg]) % 360).tolist()


def test_the_same_episode_gives_the_same_bytes(tmp_path: Path) -> None:
    runs = []
    for name in ("one", "two"):
        (tmp_path / name).mkdir()
        runs.append(random_episodes(tmp_path / name, 1, 150).recordings[0].read_bytes())
    assert runs[0] == runs[1]


def test_an_agent_with_a_model_is_recorded_with_it(tmp_path: Path) -> None:
    arm = gymnasium.make(ENV_ID, scenario="thesis-roulette")
    env = RecordMcap(arm, tmp_path, name_prefix="learner", model=TransitionSystem.universal)
    env.reset(seed=0)
    for step in range(1, 9):
        env.step(0)
        if step == 2:
            assert env.model is not None
            env.model.split(env.model.current)
    env.close()
    path = env.recordings[0]
    assert topics(path)["/rsstp/model"] == 2
    with open_recording(path) as recording:
        assert recording.has_model
        assert [m.version for m in recording.model_versions()] == [0, 1]
        assert recording.model_versions()[1].step == 3  # made between steps 2 and 3
        assert len(recording.model_at(8)) == 2


@pytest.mark.parametrize(
    "command",
    [
        ["info", "{file}"],
        ["check", "{file}"],
        ["audit", "{file}"],
        ["audit", "--truth", "{file}"],
        ["compare", "{file}", "10", "20"],
        ["table", "{file}", "-o", "{out}.parquet"],
        ["view", "{file}", "--save", "{out}.rrd"],
        ["graph", "{file}", "--step", "60", "-o", "{out}.svg"],
        ["export", "--foxglove", "{file}", "-o", "{out}.scene.mcap"],
    ],
    ids=lambda c: "-".join(w for w in c if not w.startswith("{"))[:30],
)
def test_every_replay_command_reads_a_recording_without_a_model(
    tmp_path: Path, command: list[str]
) -> None:
    env = random_episodes(tmp_path, episodes=1, steps=120)
    words = [w.format(file=env.recordings[0], out=tmp_path / "out") for w in command]
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", *words],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert done.returncode == 0, done.stderr
    assert "Traceback" not in done.stderr
    if command[0] in ("info", "audit"):
        assert "model: none recorded (the agent kept no model; read as the one-state model)" in (
            done.stdout
        )


def test_a_recording_with_a_model_channel_is_unchanged(tmp_path: Path) -> None:
    """The wrapper does not change what rsstp-sim record writes."""
    result = record(
        tmp_path / "run.mcap",
        load_scenario("thesis-roulette"),
        make_strategy("roulette"),
        steps=20,
        seed=0,
    )
    assert "/rsstp/model" in topics(result.path)


def test_refusals_are_one_line(tmp_path: Path) -> None:
    with pytest.raises(EnvError, match=r"records rsstp/Arm-v0 environments, not CartPoleEnv"):
        RecordMcap(gymnasium.make("CartPole-v1"), tmp_path)
    with pytest.raises(EnvError, match=r"no such directory"):
        RecordMcap(gymnasium.make(ENV_ID), tmp_path / "missing")
    env = RecordMcap(gymnasium.make(ENV_ID), tmp_path)
    with pytest.raises(EnvError, match=r"call reset\(\) before step\(\)"):
        env.step(0)
    env.reset(seed=0)
    env.close()
    again = RecordMcap(gymnasium.make(ENV_ID), tmp_path)
    with pytest.raises(Exception, match=r"episode-0000\.mcap.*exists"):
        again.reset(seed=0)
    assert env.recordings[0].stat().st_size > 0  # the first recording is untouched
