"""One regression test per defect of the original platform (docs/world.md).

Each test fails on the original behaviour it is named after.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import shapely

from conftest import THIN_OBSTACLE_TOML
from rsstp_sim.arm import geometry
from rsstp_sim.arm.geometry import ArmGeometry, Blocker
from rsstp_sim.arm.world import World
from rsstp_sim.errors import ScenarioError
from rsstp_sim.memory import Memory, MemoryEntry
from rsstp_sim.runner import Event, Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies import RandomStrategy, ScriptStrategy
from rsstp_sim.transition_system import TransitionSystem
from scenarios import arm_toml


def test_defect_01_link_inside_obstacle_is_a_collision() -> None:
    # The link from (0, 0) to (1, 0) lies inside the disk: it never meets the circle.
    disk = shapely.Point(0.5, 0.0).buffer(1.0, quad_segs=64)
    assert not shapely.LineString([(0, 0), (1, 0)]).intersects(disk.exterior)
    text = arm_toml([1.0], [0], 10, [((0.5, 0.0), 1.0)])
    with pytest.raises(
        ScenarioError, match=r"start pose \[0\] is invalid \(link 0 meets obstacle 0\)"
    ):
        parse_scenario(text)
    # A two-link arm wholly inside a large disk collides, whichever way it points.
    geo = ArmGeometry(
        lengths=np.array([1.0, 1.0]),
        centers=np.array([[0.5, 0.5]]),
        radii=np.array([3.0]),
        swept=True,
        eps=0.0,
    )
    poses = [[a, b] for a in range(0, 360, 30) for b in range(0, 360, 30) if b != 180]
    codes = geometry.pose_blockers(geo, poses)
    assert {geo.decode(int(c)) for c in codes} == {Blocker("obstacle", (0, 0))}


def test_defect_02_large_step_cannot_pass_through_an_obstacle() -> None:
    # One link of length 2 turning 90 degrees from 0; a thin disk sits on the diagonal.
    text = THIN_OBSTACLE_TOML
    swept = parse_scenario(text.format(mode="swept"))
    assert geometry.pose_blocker(swept, [90]) is None  # the end pose alone is fine
    world = World(swept)
    assert world.move(0) == Blocker("obstacle", (0, 0))
    assert world.angles_deg == (0,)
    # The thesis behaviour is still available, on request.
    endpoint = World(parse_scenario(text.format(mode="endpoint")))
    assert endpoint.move(0) is None
    assert endpoint.angles_deg == (90,)


@pytest.mark.parametrize("mode", ["swept", "endpoint"])
def test_defect_03_base_joint_can_be_at_and_pass_180(mode: str) -> None:
    at_180 = parse_scenario(
        f"[arm]\nlengths = [1.0]\ninitial_deg = [180]\nstep_deg = 5\n"
        f'[motion]\ncollision = "{mode}"\n'
    )
    assert at_180.initial_deg == (180,)
    world = World(dataclasses.replace(at_180, initial_deg=(170,)))
    visited = []
    for _ in range(4):
        assert world.move(0) is None
        visited.append(world.angles_deg[0])
    assert visited == [175, 180, 185, 190]
    for _ in range(4):
        assert world.move(1) is None
    assert world.angles_deg == (170,)
    # The base of a longer arm too; only the later joints fold.
    two = World(
        parse_scenario(
            f"[arm]\nlengths = [1.0, 1.0]\ninitial_deg = [175, 90]\n"
            f'step_deg = 5\n[motion]\ncollision = "{mode}"\n'
        )
    )
    assert two.move(0) is None
    assert two.angles_deg == (180, 90)


def _float_tips(angles_deg: list[int], lengths: list[float]) -> list[list[float]]:
    """Link tips by plain float trigonometry, independent of the simulator's tables."""
    phi = np.deg2rad(np.cumsum(angles_deg))
    steps = np.asarray(lengths)[:, None] * np.stack([np.cos(phi), np.sin(phi)], axis=1)
    return np.cumsum(steps, axis=0).tolist()


def test_defect_04_feedback_matches_poses_with_unround_coordinates() -> None:
    # The three-joint start pose, with feedback points given as plain coordinates.
    points = _float_tips([330, 3, 357], [3.0, 2.0, 1.0])
    assert any(round(v, 2) != v for point in points for v in point)  # not round numbers
    text = f"""
    [arm]
    lengths = [3.0, 2.0, 1.0]
    initial_deg = [330, 3, 357]
    step_deg = 5
    [feedback]
    points = {points!r}
    """
    scenario = parse_scenario(text)
    world = World(scenario)
    assert world.sensation is True
    for action in scenario.actions:  # one step away: no match
        world.reset()
        assert world.move(action) is None
        assert world.sensation is False, action
    world.reset()
    world.move(4)
    world.move(5)  # away and back
    assert world.angles_deg == scenario.initial_deg
    assert world.sensation is True
    # Any target pose matches when the arm is exactly there (not only a lucky two thirds).
    lengths = [3.0, 2.0, 1.0]
    rng = np.random.default_rng(4)
    for target in rng.integers(0, 360, size=(60, 3)).tolist():
        target[1:] = [a if a != 180 else 181 for a in target[1:]]
        aimed = parse_scenario(
            f"[arm]\nlengths = {lengths}\ninitial_deg = [0, 0, 0]\nstep_deg = 1\n"
            f"[feedback]\npoints = {_float_tips(target, lengths)!r}\n"
        )
        if geometry.pose_blocker(aimed, target) is not None:
            continue  # links crossing: no world starts there (its table refuses the pose)
        assert World(dataclasses.replace(aimed, initial_deg=tuple(target))).sensation, target


def test_defect_05_world_neither_keeps_nor_changes_the_callers_angles() -> None:
    scenario = load_scenario("three-joint")
    angles = [330, 3, 357]
    world = World(dataclasses.replace(scenario, initial_deg=angles))  # type: ignore[arg-type]
    world.move(0)
    world.move(2)
    assert world.angles_deg == (335, 8, 357)
    assert angles == [330, 3, 357]
    angles[0] = 0  # the caller changing its list afterwards changes nothing in the world
    assert world.angles_deg == (335, 8, 357)
    world.reset()
    assert world.angles_deg == (330, 3, 357)
    # The geometry functions leave their inputs alone too.
    batch = np.array([[330, 3, 357]])
    geometry.move_blockers(world.geometry, batch, [0], [5])
    assert batch.tolist() == [[330, 3, 357]]


def test_defect_06_memory_belongs_to_one_agent() -> None:
    scenario = load_scenario("one-joint-10")
    first = Runner(scenario, RandomStrategy(), seed=1)
    second = Runner(scenario, RandomStrategy(), seed=1)
    first.run(10)
    assert len(first.memory) == 11
    assert len(second.memory) == 1
    second.run(3)
    assert (len(first.memory), len(second.memory)) == (11, 4)
    a, b = Memory(), Memory()
    a.reset(0, True, 1.0)
    assert (len(a), len(b)) == (1, 0)


def test_defect_07_blocked_move_is_ground_truth_not_memory() -> None:
    # One link from 95 degrees turning clockwise (action 1) into the disk at (1, 2).
    runner = Runner(load_scenario("thesis-obstacles"), ScriptStrategy([1]), seed=0)
    outcomes = [runner.step() for _ in range(8)]
    free = [o for o in outcomes if o.blocker is None]
    blocked = [o for o in outcomes if o.blocker is not None]
    assert outcomes == free + blocked and free and blocked  # free until the obstacle
    assert all(o.blocker == Blocker("obstacle", (0, 0)) for o in blocked)
    assert runner.blocked == len(blocked) == runner.summary().blocked
    assert runner.world.angles_deg == (95 - len(free),)
    # The agent's memory entry for a blocked move is just what it sensed.
    before = runner.memory[len(free)]
    for o in blocked:
        assert runner.memory[o.step] == MemoryEntry(1, 0, before.sensation, before.feedback)


class _PartialModelScript(ScriptStrategy):
    """Plays its script with a model that knows only action 0."""

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        model = TransitionSystem(1, actions=actions)
        model.add(0, 0, 0)
        return model


def test_defect_08_action_missing_from_the_model_still_moves_the_arm() -> None:
    events: list[Event] = []
    runner = Runner(
        load_scenario("one-joint-10"), _PartialModelScript([1]), seed=0, on_event=events.append
    )
    outcome = runner.step()
    assert runner.world.angles_deg == (350,)  # the world executed the action
    assert outcome.blocker is None
    assert outcome.no_transition is True
    assert outcome.state_before == outcome.state_after == runner.model.current == 0
    assert runner.no_transition == 1
    assert [(e.step, e.kind) for e in events] == [(1, "no_transition")]
    assert "action 1" in events[0].text
    assert runner.memory[1].action == 1 and runner.memory[1].internal_state == 0


def test_defect_09_merge_moves_the_current_state_to_the_survivor() -> None:
    model = TransitionSystem.universal([0, 1])
    first = model.split(0)
    second = model.split(0)
    model.current = second
    assert model.merge(first, second) == first
    assert model.current == first
    assert model.current in model.states
    assert model.index_of(model.current) < len(model.to_matrix())
    assert model.successors(model.current, 0)  # usable right away


def test_defect_10_duplicated_label_in_one_cell_is_not_nondeterminism() -> None:
    model = TransitionSystem.from_matrix([[[0, 0]]])
    assert model.is_deterministic()
    assert model.determinism_report().nondeterministic == ()
    assert model.transitions() == [(0, 0, 0)]
    assert model.to_matrix() == [[[0]]]


class _NondeterministicScript(ScriptStrategy):
    """Plays its script with a model in which every action may lead to either of two states."""

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        return TransitionSystem.from_matrix([[list(actions), list(actions)]] * 2)


def test_defect_11_same_seed_same_run() -> None:
    scenario = load_scenario("one-joint-10")

    def run(seed: int) -> Runner:
        runner = Runner(scenario, _NondeterministicScript([0, 0, 1]), seed=seed)
        runner.run(200)
        return runner

    first, again, other = run(7), run(7), run(8)
    assert not first.model.is_deterministic()
    assert first.memory == again.memory
    assert np.array_equal(first.memory.actions, other.memory.actions)  # same script
    assert not np.array_equal(first.memory.internal_states, other.memory.internal_states)
    # A reset replays the same run.
    memory = first.memory
    first.reset()
    first.run(200)
    assert first.memory == memory
