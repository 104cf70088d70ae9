"""Tests for the Gymnasium environment of the world alone."""

from __future__ import annotations

import doctest

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from rsstp_sim import env as env_module
from rsstp_sim import palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.env import ENV_ID, MAX_EPISODE_STEPS, ArmEnv, register_envs
from rsstp_sim.errors import ActionError, ScenarioError
from rsstp_sim.scenario import load_scenario, parse_scenario
from scenarios import arm_toml
from waiting import HANG_S

FLOAT_TWO_LINKS = arm_toml(
    [2.0, 1.0],
    [0, 90],
    10,
    [((-2.0, -2.0), 0.5)],
    name="float-two-links",
    feedback={"target_deg": [0, 90], "mode": "float"},
)
SUBSET_ACTIONS = arm_toml([2.0, 1.0], [0, 90], 10, name="subset", actions=[3, 1])

# thesis-obstacles: one link of length 2 from 95 degrees, 1-degree steps, an obstacle
# at (1, 2) of radius 1 that the link touches at 90 degrees, feedback at 100 degrees.
PLUS, MINUS = 0, 1


def float_scenario() -> Scenario:
    return parse_scenario(FLOAT_TWO_LINKS, origin="float-two-links")


def test_docstring_examples_run() -> None:
    result = doctest.testmod(env_module)
    assert result.attempted > 0
    assert result.failed == 0


@pytest.mark.parametrize(
    ("scenario", "render_mode"),
    [
        ("three-joint", None),
        ("thesis-obstacles", None),
        ("thesis-obstacles", "rgb_array"),
        ("float", None),
        ("float", "rgb_array"),
    ],
)
def test_check_env_passes(scenario: str, render_mode: str | None) -> None:
    arm_env = ArmEnv(float_scenario() if scenario == "float" else scenario, render_mode=render_mode)
    check_env(arm_env)  # filterwarnings=error: any checker warning fails the test


def test_spaces_bool_and_float() -> None:
    bool_env = ArmEnv("three-joint")
    assert bool_env.action_space == gymnasium.spaces.Discrete(6)
    assert bool_env.observation_space == gymnasium.spaces.Discrete(2)
    float_env = ArmEnv(float_scenario())
    assert float_env.observation_space == gymnasium.spaces.Box(
        0.0, 1.0, shape=(1,), dtype=np.float32
    )
    obs, _ = float_env.reset(seed=0)
    assert isinstance(obs, np.ndarray)
    assert obs.dtype == np.float32
    assert obs.tolist() == [1.0]  # the start pose is the feedback pose
    obs, *_ = float_env.step(0)
    assert isinstance(obs, np.ndarray)
    assert 0.0 < obs[0] < 1.0


def test_reset_returns_start_observation() -> None:
    arm_env = ArmEnv("thesis-algo")
    obs, info = arm_env.reset(seed=3)
    assert obs == 0  # 95 degrees, feedback at 100
    assert info["angles_deg"] == (95,)
    for _ in range(5):
        arm_env.step(PLUS)
    obs, info = arm_env.reset()
    assert obs == 0
    assert info["angles_deg"] == (95,)


def test_sensation_observed() -> None:
    arm_env = ArmEnv("thesis-algo")
    arm_env.reset(seed=0)
    observations = [arm_env.step(PLUS)[0] for _ in range(6)]
    assert observations == [0, 0, 0, 0, 1, 0]  # 96, ..., 100 (sensed), 101


def test_info_contents() -> None:
    scenario = load_scenario("three-joint")
    arm_env = ArmEnv(scenario)
    _, info = arm_env.reset(seed=0)
    assert set(info) == {
        "angles_deg",
        "joint_positions",
        "blocked",
        "blocked_by",
        "distances",
        "sensation",
        "feedback",
        "action",
        "pose_code",
    }
    assert info["angles_deg"] == (330, 3, 357)
    assert info["pose_code"] == 330 + 3 * 360 + 357 * 360**2  # angle j in base 360
    assert info["action"] is None
    assert info["blocked"] is False and info["blocked_by"] is None
    assert info["sensation"] is True and info["feedback"] == pytest.approx(1.0)
    positions = info["joint_positions"]
    assert isinstance(positions, np.ndarray)
    assert positions.shape == (4, 2) and positions.dtype == np.float64
    assert positions[0].tolist() == [0.0, 0.0]
    np.testing.assert_allclose(positions[1], [3 * np.cos(np.radians(330)), -1.5], atol=1e-12)
    distances = info["distances"]
    assert isinstance(distances, np.ndarray) and distances.shape == (3, 2)
    tip = positions[1:]
    centers = np.array([o.center for o in scenario.obstacles])
    radii = np.array([o.radius for o in scenario.obstacles])
    expected = np.hypot(*(tip[:, None, :] - centers[None, :, :]).transpose(2, 0, 1)) - radii
    np.testing.assert_allclose(distances, expected, atol=1e-12)

    _, reward, terminated, truncated, info = arm_env.step(3)
    assert (reward, terminated, truncated) == (0.0, False, False)
    assert info["action"] == 3
    assert info["angles_deg"] == (330, 358, 357)
    assert info["sensation"] is False and 0.0 < info["feedback"] < 1.0


def test_info_arrays_are_fresh() -> None:
    arm_env = ArmEnv("three-joint")
    _, first = arm_env.reset(seed=0)
    _, second = arm_env.reset(seed=0)
    assert first["joint_positions"] is not second["joint_positions"]
    first["joint_positions"][:] = 7.0  # the caller may modify its copy
    assert arm_env.world.joint_positions[1, 0] != 7.0


def test_blocked_moves_reported() -> None:
    arm_env = ArmEnv("thesis-obstacles")
    arm_env.reset(seed=0)
    steps = [arm_env.step(MINUS) for _ in range(6)]
    infos = [info for *_, info in steps]
    assert [info["angles_deg"][0] for info in infos] == [94, 93, 92, 91, 91, 91]
    assert [info["blocked"] for info in infos] == [False] * 4 + [True] * 2
    assert infos[3]["blocked_by"] is None
    assert infos[4]["blocked_by"] == "link 0 meets obstacle 0"
    assert all(not terminated and not truncated for _, _, terminated, truncated, _ in steps)
    _, _, _, _, info = arm_env.step(PLUS)
    assert info["blocked"] is False and info["angles_deg"] == (92,)


def test_action_index_maps_to_scenario_action() -> None:
    scenario = parse_scenario(SUBSET_ACTIONS, origin="subset")
    assert scenario.actions == (1, 3)
    arm_env = ArmEnv(scenario)
    assert arm_env.action_space == gymnasium.spaces.Discrete(2)
    arm_env.reset(seed=0)
    *_, info = arm_env.step(1)
    assert info["action"] == 3
    assert info["angles_deg"] == (0, 80)
    *_, info = arm_env.step(np.int64(0))
    assert info["action"] == 1
    assert info["angles_deg"] == (350, 80)


@pytest.mark.parametrize("bad", [2, -1, 1.0, "0", True, None])
def test_invalid_action_raises(bad: object) -> None:
    arm_env = ArmEnv(parse_scenario(SUBSET_ACTIONS, origin="subset"))
    arm_env.reset(seed=0)
    with pytest.raises(ActionError, match=r"0\.\.1 \(Discrete\(2\)"):
        arm_env.step(bad)  # type: ignore[arg-type]


def test_same_actions_give_same_observations() -> None:
    actions = np.random.default_rng(7).integers(0, 6, size=300)

    def run() -> tuple[list[int], list[tuple[int, ...]]]:
        arm_env = ArmEnv("three-joint")
        obs, info = arm_env.reset(seed=11)
        observations, angles = [int(obs)], [info["angles_deg"]]
        for action in actions:
            obs, _, _, _, info = arm_env.step(int(action))
            observations.append(int(obs))
            angles.append(info["angles_deg"])
        return observations, angles

    first, second = run(), run()
    assert first == second
    assert len(set(first[1])) > 10  # the arm did move around


def test_make_after_register(recwarn: pytest.WarningsRecorder) -> None:
    register_envs()
    register_envs()  # idempotent: no "Overriding environment" warning
    assert ENV_ID in gymnasium.registry
    made = gymnasium.make(ENV_ID)
    assert isinstance(made.unwrapped, ArmEnv)
    assert made.unwrapped.scenario.name == "three-joint"
    obs, info = made.reset(seed=0)
    assert obs == 1 and info["angles_deg"] == (330, 3, 357)
    made.close()
    assert not recwarn.list


def test_make_with_kwargs_and_time_limit() -> None:
    register_envs()
    made = gymnasium.make(ENV_ID, scenario="thesis-algo", max_episode_steps=3)
    made.reset(seed=0)
    truncations = [made.step(0)[3] for _ in range(3)]
    assert truncations == [False, False, True]


def test_spec_rebuilds_directly_built_env() -> None:
    arm_env = ArmEnv("thesis-algo")
    assert arm_env.spec is not None and arm_env.spec.id == ENV_ID
    rebuilt = arm_env.spec.make()
    assert isinstance(rebuilt.unwrapped, ArmEnv)
    assert rebuilt.unwrapped.scenario == arm_env.scenario
    rebuilt.close()


def test_render() -> None:
    assert ArmEnv("thesis-obstacles").render() is None
    arm_env = ArmEnv("thesis-obstacles", render_mode="rgb_array")
    arm_env.reset(seed=0)
    frame = arm_env.render()
    assert isinstance(frame, np.ndarray)
    assert frame.shape == (400, 400, 3) and frame.dtype == np.uint8
    assert (frame == 255).all(axis=2).mean() > 0.5  # mostly white background
    blue = (frame == palette.ARM).all(axis=2).sum()
    assert blue > 100  # the arm
    for _ in range(5):
        arm_env.step(MINUS)  # the last move is blocked
    blocked = arm_env.render()
    assert isinstance(blocked, np.ndarray)
    assert (blocked == palette.ARM).all(axis=2).sum() == 0
    assert (blocked == palette.ARM_BLOCKED).all(axis=2).sum() > 100


def test_bad_constructor_arguments() -> None:
    with pytest.raises(ValueError, match="render_mode must be None or one of"):
        ArmEnv("three-joint", render_mode="human")
    with pytest.raises(ScenarioError, match="no-such-scenario"):
        ArmEnv("no-such-scenario")


def test_the_sensation_reward_with_a_step_cost() -> None:
    """thesis-roulette senses its point every 4 moves: 1 - cost there, -cost elsewhere."""
    env = ArmEnv("thesis-roulette", reward="sensation", step_cost=0.25)
    env.reset(seed=0)
    rewards = [env.step(0)[1] for _ in range(8)]
    assert rewards == [-0.25, -0.25, -0.25, 0.75, -0.25, -0.25, -0.25, 0.75]
    assert [ArmEnv("thesis-roulette").step(0)[1] for _ in range(2)] == [0.0, 0.0]
    check_env(ArmEnv("thesis-algo", reward="sensation", step_cost=0.01), skip_render_check=True)
    with pytest.raises(ValueError, match="reward must be one of"):
        ArmEnv("thesis-roulette", reward="distance")


def test_make_puts_a_time_limit_on_an_episode() -> None:
    env = gymnasium.make(ENV_ID, scenario="thesis-roulette")
    env.reset(seed=0)
    truncated = [env.step(0)[3] for _ in range(MAX_EPISODE_STEPS)]
    assert truncated == [False] * (MAX_EPISODE_STEPS - 1) + [True]
    short = gymnasium.make(ENV_ID, scenario="thesis-roulette", max_episode_steps=3)
    short.reset(seed=0)
    assert [short.step(0)[3] for _ in range(3)] == [False, False, True]


def test_make_with_the_module_prefix_in_a_fresh_interpreter() -> None:
    """Gymnasium 1.x has no plugin entry points: ``rsstp_sim:`` imports us first."""
    import subprocess
    import sys

    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "import gymnasium\n"
            "env = gymnasium.make('rsstp_sim:rsstp/Arm-v0', scenario='thesis-roulette')\n"
            "print(env.reset(seed=0)[0], env.spec.max_episode_steps)",
        ],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["1", str(MAX_EPISODE_STEPS)]
