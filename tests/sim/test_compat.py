"""Tests for the thesis-era ``robot_arm`` facade."""

from __future__ import annotations

import doctest
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rsstp_sim import compat
from rsstp_sim.compat import THESIS_GOAL_TOLERANCE, robot_arm
from rsstp_sim.errors import ActionError, MemoryRangeError, ModelError, ScenarioError
from rsstp_sim.scenario import Obstacle

LEFT, RIGHT = 0, 1  # the thesis scripts' names: 0 turns +1 degree, 1 turns -1 degree
THESIS_OBSTACLES = [[1, 2], 1, [-1, -2], 1]
FIGURE_13 = [[[0, 1], [1]], [[0], [0, 1]]]


def test_docstring_examples_run() -> None:
    result = doctest.testmod(compat)
    assert result.attempted > 0
    assert result.failed == 0


def thesis_arm(**keywords: Any) -> robot_arm:
    """The thesis demo arm: one link of 2 from 95 degrees, goal at 100 degrees."""
    return robot_arm(1, [95], [2], THESIS_OBSTACLES, 1, [(-0.35, 1.97)], [LEFT, RIGHT], **keywords)


def run_thesis_script() -> dict[str, object]:
    """A thesis-era script (demo_msrgym.py style), with only the import line changed."""
    arm = thesis_arm()
    out: dict[str, object] = {}
    for _ in range(7):
        arm.update_position(RIGHT)
    out["after_right"] = arm.get_arm_position()[0]
    for _ in range(9):
        arm.update_position(LEFT)
    out["after_left"] = arm.get_arm_position()[0]
    out["home_after_left"] = arm.is_desired_position_reached()
    for _ in range(5):
        arm.update_position(RIGHT)
    out["reset_position"] = arm.get_arm_position()[0]
    out["split"] = arm.split_node(0)
    out["delete_left"] = arm.delete_conection_between_nodes(0, 1, LEFT)
    out["delete_right"] = arm.delete_conection_between_nodes(1, 0, RIGHT)
    out["deterministic"] = arm.is_deterministic()
    states = []
    for action in [RIGHT] * 7 + [LEFT] * 9:
        arm.update_position(action)
        states.append(arm.get_current_internal_state())
    out["states"] = states
    out["home_again"] = arm.is_desired_position_reached()
    out["merged"] = arm.merge_nodes(0, 1)
    out["state_after_merge"] = arm.get_current_internal_state()
    out["memory_size"] = arm.get_memory_size()
    # thesis index 15 is the 16th move (reaching 100 degrees), 14 the 15th (99 degrees)
    out["compare_home"] = arm.compare_memory(15, 14)
    out["compare_shifted"] = arm.compare_memory(0, 1)
    out["compare_last"] = arm.compare_memory(arm.get_memory_size() - 1, 15)
    return out


def test_thesis_script_runs_with_sensible_results(capsys: pytest.CaptureFixture[str]) -> None:
    out = run_thesis_script()
    # The link touches the obstacle at (1, 2) (radius 1) at 90 degrees: 91 is as far as it goes.
    assert out["after_right"] == [91]
    assert out["after_left"] == [100]
    assert out["home_after_left"] is True
    assert out["reset_position"] == [95]
    assert out["split"] == [[[0, 1], [0, 1]], [[0, 1], [0, 1]]]
    assert out["delete_left"] == [[[0, 1], [1]], [[0, 1], [0, 1]]]
    assert out["delete_right"] == FIGURE_13
    assert out["deterministic"] is False
    states = out["states"]
    assert isinstance(states, list) and set(states) <= {0, 1}
    # Node 1 is only left by LEFT, node 0 only entered from 1 by LEFT: once RIGHT leads to
    # node 1 the arm stays there until a LEFT.
    first_one = states.index(1)
    assert first_one < 7 and all(s == 1 for s in states[first_one:7])
    assert out["home_again"] is True
    assert out["merged"] == [[[0, 1]]]
    assert out["state_after_merge"] == 0
    assert out["memory_size"] == 37
    assert out["compare_home"] == 2  # same action, same state, the sensation differs
    assert out["compare_shifted"] == 0  # the action sequences diverge first
    assert out["compare_last"] in (1, 3)  # both at 100 degrees with the goal sensed
    assert capsys.readouterr().out == ""  # nothing printed without the visualise flags


def test_thesis_script_repeats_exactly() -> None:
    assert run_thesis_script() == run_thesis_script()


def test_seed_keyword_changes_only_the_nondeterministic_choices() -> None:
    def states(seed: int) -> list[int]:
        arm = thesis_arm(seed=seed)
        arm.split_node(0)
        out = []
        for _ in range(40):
            arm.update_position(LEFT)
            out.append(arm.get_current_internal_state())
        return out

    runs = {tuple(states(seed)) for seed in range(8)}
    assert len(runs) > 1
    assert states(3) == states(3)


def test_visualise_flags_print(capsys: pytest.CaptureFixture[str]) -> None:
    arm = thesis_arm(visualise_ext=True)
    for _ in range(5):
        arm.update_position(LEFT)
    out = capsys.readouterr().out
    assert "Updated position: ([100], [(-0.35, 1.97)])" in out
    assert "Internal state after update: 0" in out
    assert "Home position reached" in out
    assert "Transition matrix" not in out

    arm = thesis_arm(visualise_int=True)
    arm.update_position(RIGHT)
    out = capsys.readouterr().out
    assert "Transition matrix: \n[[[0, 1]]]\n" in out
    assert "Transition matrix is deterministic" in out
    assert "Updated position" not in out

    arm = thesis_arm(visualise_ext=True)
    for _ in range(5):
        arm.update_position(RIGHT)
    assert "Move blocked: link 0 meets obstacle 0" in capsys.readouterr().out


def test_initial_model_is_the_universal_one() -> None:
    arm = robot_arm(2, [0, 90], [2, 1], [], 10, [(2, 0), (2, 1)], [0, 1, 2, 3])
    assert arm.get_transition_matrix() == [[[0, 1, 2, 3]]]
    assert arm.get_current_internal_state() == 0
    assert arm.is_deterministic() is True
    assert arm.get_memory_size() == 0
    assert arm.is_desired_position_reached() is True


def test_index_mapping_after_merge() -> None:
    arm = thesis_arm()
    arm.split_node(0)
    arm.split_node(0)  # ids 0, 1, 2 at indices 0, 1, 2
    arm.delete_connection_between_nodes(2, 2, LEFT)  # mark node 2 (id 2)
    arm.model.current = 2
    assert arm.get_current_internal_state() == 2
    matrix = arm.merge_nodes(0, 1)  # id 1 disappears: id 2 moves to index 1
    assert arm.model.states == (0, 2)
    assert arm.get_current_internal_state() == 1
    assert len(matrix) == 2
    assert LEFT not in matrix[1][1] and RIGHT in matrix[1][1]
    # Index 1 now addresses id 2, as the original's shifted matrix row did.
    arm.add_connection_between_nodes(1, 1, LEFT)
    assert arm.model.successors(2, LEFT) == (0, 2)
    arm.delete_conection_between_nodes(1, 0, RIGHT)
    assert arm.model.successors(2, RIGHT) == (2,)
    # merge_nodes(n, m) with n > m: the survivor ends at index n - 1 (the original's too).
    arm.split_node(1)  # ids 0, 2, 3
    merged = arm.merge_nodes(2, 0)
    assert arm.model.states == (2, 3)
    assert len(merged) == 2
    assert arm.get_current_internal_state() == 0  # id 2, now at index 0


def test_model_operations_return_the_matrix_and_validate() -> None:
    arm = thesis_arm()
    assert arm.add_connection_between_nodes(0, 0, LEFT) == [[[0, 1]]]  # exists: no change
    assert arm.delete_connection_between_nodes(0, 0, LEFT) == [[[1]]]
    assert arm.delete_connection_between_nodes(0, 0, LEFT) == [[[1]]]  # missing: no change
    with pytest.raises(ModelError, match=r"split_node: node 1 is not a matrix index 0\.\.0"):
        arm.split_node(1)
    with pytest.raises(ModelError, match="merge_nodes: cannot merge node 0 with itself"):
        arm.merge_nodes(0, 0)
    with pytest.raises(ModelError, match=r"action 2 is not one of the arm's actions \[0, 1\]"):
        arm.add_connection_between_nodes(0, 0, 2)
    with pytest.raises(ModelError, match="must be an integer"):
        arm.split_node(0.0)  # type: ignore[arg-type]
    with pytest.raises(ModelError, match="must be an integer"):
        arm.split_node(True)
    assert arm.split_node(np.int64(0)) == [[[1], [1]], [[1], [1]]]


def test_action_absent_from_model_still_moves_the_arm() -> None:
    arm = thesis_arm()
    arm.delete_connection_between_nodes(0, 0, LEFT)
    arm.update_position(LEFT)  # the original silently refused to move (defect 8)
    assert arm.get_arm_position()[0] == [96]
    assert arm.get_current_internal_state() == 0
    assert arm.get_memory_size() == 1


def test_unknown_action_raises() -> None:
    arm = robot_arm(1, 0, 1, [], 90, (1, 0), [1])
    with pytest.raises(ActionError, match="action 0 is not one of the scenario's actions"):
        arm.update_position(0)
    assert arm.get_memory_size() == 0


def test_compare_memory_codes() -> None:
    # thesis-roulette style: one joint, 90-degree steps, feedback at the start.
    arm = robot_arm(1, [0], [1], [], 90, [(1, 0)], [0, 1])
    for action in [0, 0, 0, 0, 1, 1]:
        arm.update_position(action)
    # thesis indices 0..5: 90, 180, 270, 0 (sensed), 270, 180 degrees; all in state 0
    assert arm.compare_memory(0, 4) == 0  # then actions 0 vs 1: unknown
    assert arm.compare_memory(0, 1) == 2  # 270 vs 0 degrees after two same actions
    assert arm.compare_memory(1, 5) == 3  # both at 180, nothing after: identical
    assert arm.compare_memory(np.int64(0), 4) == 0
    with pytest.raises(MemoryRangeError, match="must differ"):
        arm.compare_memory(1, 1)
    with pytest.raises(MemoryRangeError, match=r"indices must be in 0 \.\. 5"):
        arm.compare_memory(0, 6)
    with pytest.raises(MemoryRangeError, match=r"indices must be in 0 \.\. 5"):
        arm.compare_memory(-1, 0)
    with pytest.raises(MemoryRangeError, match="must be an integer"):
        arm.compare_memory(0, "1")  # type: ignore[arg-type]
    with pytest.raises(MemoryRangeError, match=r"none \(no move yet\)"):
        robot_arm(1, [0], [1], [], 90, [(1, 0)], [0, 1]).compare_memory(0, 1)


def test_compare_memory_state_difference() -> None:
    arm = robot_arm(1, [0], [1], [], 90, [(1, 0)], [0])
    arm.split_node(0)
    arm.delete_connection_between_nodes(0, 0, 0)  # 0 -> 1 only
    arm.delete_connection_between_nodes(1, 1, 0)  # 1 -> 0 only
    for _ in range(4):
        arm.update_position(0)
    # states 1, 0, 1, 0; sensations False, False, False, True
    assert arm.compare_memory(0, 1) == 1
    assert arm.compare_memory(0, 2) == 2  # same state 1, then 0 vs 0: the sensation differs
    assert arm.is_deterministic() is True


def test_obstacle_flat_form_parsed() -> None:
    arm = thesis_arm()
    assert arm.scenario.obstacles == (Obstacle((1.0, 2.0), 1.0), Obstacle((-1.0, -2.0), 1.0))
    assert arm.scenario.collision == "swept"
    assert arm.scenario.feedback_points == ((-0.35, 1.97),)
    assert arm.scenario.actions == (0, 1)
    assert arm.scenario.step_deg == 1
    assert robot_arm(1, 95, 2, None, 1, (-0.35, 1.97), [0, 1]).scenario.obstacles == ()
    arm = robot_arm(1, 95, 2, np.array([(3.0, 4.0), 0.5], dtype=object), 1, (-0.35, 1.97), [0])
    assert arm.scenario.obstacles == (Obstacle((3.0, 4.0), 0.5),)


@pytest.mark.parametrize(
    ("obstacles", "message"),
    [
        ([[1, 2], 1, [3, 3]], r"obstacles: expected the flat form .* found 3 items"),
        ([1, [1, 2]], r"obstacles\[0\] \(centre of obstacle 0\): expected a point \[x, y\]"),
        ([[1, 2, 3], 1], r"obstacles\[0\] .* expected a point \[x, y\], found \[1, 2, 3\]"),
        ([[1, 2], "big"], r"obstacles\[1\] \(radius of obstacle 0\): expected a number"),
        ([[1, 2], 1, [4, 4], -1], r"obstacles\[1\]\.radius: expected a number > 0"),
        ([["a", 2], 1], r"obstacles\[0\] \(centre of obstacle 0\)\[0\]: expected a number"),
        ("[[1, 2], 1]", "obstacles: expected the flat form"),
        ([[0, 1], 0.5], "the start pose .* is invalid"),
    ],
)
def test_bad_obstacles_raise_scenario_error(obstacles: object, message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        robot_arm(1, [95], [2], obstacles, 1, [(-0.35, 1.97)], [0, 1])  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ((0, [95], [2], [], 1, [(0, 2)], [0]), "joints_n: expected an integer >= 1"),
        ((2, [95], [2, 1], [], 1, [(0, 2), (0, 3)], [0]), "initial_position: expected 2 angles"),
        ((1, [95], [2, 1], [], 1, [(0, 2)], [0]), "arm_lengths: expected 1 lengths"),
        ((1, [95.5], [2], [], 1, [(0, 2)], [0]), r"arm\.initial_deg\[0\]: expected an integer"),
        ((1, [95], [-2], [], 1, [(0, 2)], [0]), r"arm\.lengths\[0\]: expected a number > 0"),
        ((1, [95], [2], [], 0, [(0, 2)], [0]), r"arm\.step_deg: expected an integer in 1\.\.359"),
        ((1, [95], [2], [], 1, [(0, 2), (0, 1)], [0]), "goal_position: expected 1 points"),
        ((1, [95], [2], [], 1, [(0, 2)], [0, 2]), r"arm\.actions\[1\]: expected an integer"),
        ((1, [95], [2], [], 1, [(0, 2)], "01"), "actions: expected a list of action ids"),
    ],
)
def test_bad_arguments_raise_scenario_error(arguments: tuple[object, ...], message: str) -> None:
    with pytest.raises(ScenarioError, match=message):
        robot_arm(*arguments)  # type: ignore[arg-type]


def test_goal_forms_and_tolerance() -> None:
    single = robot_arm(1, 95, 2, [], 1, (-0.35, 1.97), [0, 1])
    listed = robot_arm(1, [95], [2.0], [], 1, [(-0.35, 1.97)], [0, 1])
    assert single.scenario.feedback_points == listed.scenario.feedback_points
    assert single.scenario.tolerance * single.scenario.total_length == pytest.approx(
        THESIS_GOAL_TOLERANCE
    )
    sensed = {}
    for _ in range(10):
        single.update_position(0)
        sensed[single.get_arm_position()[0][0]] = single.is_desired_position_reached()
    assert [angle for angle, hit in sensed.items() if hit] == [100]
    strict = robot_arm(1, 95, 2, [], 1, (-0.35, 1.97), [0, 1], goal_tolerance=0.001)
    for _ in range(5):
        strict.update_position(0)
    assert strict.is_desired_position_reached() is False  # the tip is 0.0027 away


def test_two_joint_goal_points() -> None:
    # Thesis demo values: 90 and 120 degrees -> tips (0, 2) and (-0.87, 1.5), rounded.
    arm = robot_arm(2, [90, 120], [2, 1], [], 10, [(0.0, 2.0), (-0.87, 1.5)], [0, 1, 2, 3])
    assert arm.is_desired_position_reached() is True
    arm.update_position(2)
    assert arm.is_desired_position_reached() is False
    assert arm.get_arm_position()[0] == [90, 130]


def test_world_queries() -> None:
    initial = [95]
    arm = robot_arm(1, initial, [2], THESIS_OBSTACLES, 1, [(-0.35, 1.97)], [0, 1])
    angles, tips = arm.get_arm_position()
    assert angles == [95]
    assert tips[0] == pytest.approx((2 * np.cos(np.radians(95)), 2 * np.sin(np.radians(95))))
    (distances,) = arm.distance_from_obstacle()
    tip = np.array(tips[0])
    assert distances == pytest.approx(
        [np.hypot(*(tip - (1, 2))) - 1, np.hypot(*(tip - (-1, -2))) - 1]
    )
    assert 0 < arm.get_sensory_data_float() < 1
    for _ in range(5):
        arm.update_position(LEFT)
    assert arm.get_sensory_data_float() == pytest.approx(1.0, abs=1e-3)
    assert initial == [95]  # the caller's list is never changed (defect 5)
    assert arm._ext.get_sensory_data() is True  # thesis demos reached into arm._ext
    assert arm._ext.get_position() == arm.get_arm_position()


def test_each_arm_has_its_own_memory() -> None:
    first, second = thesis_arm(), thesis_arm()
    first.update_position(LEFT)
    assert first.get_memory_size() == 1
    assert second.get_memory_size() == 0
    assert len(first.memory) == 2  # entry 0 is the start; thesis index i is entry i + 1
    assert first.memory[1].action == LEFT


def test_draw_graph_from_tm(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    arm = thesis_arm()
    arm.split_node(0)
    arm.delete_conection_between_nodes(0, 1, LEFT)
    arm.delete_conection_between_nodes(1, 0, RIGHT)
    source = arm.draw_graph_from_tm()
    assert "0 -> 1 [label=1]" in source and "1 -> 0 [label=0]" in source
    assert '0 [fillcolor="#ffd54f"' in source
    assert list(tmp_path.iterdir()) == []  # nothing written without a path
    other = arm.draw_graph_from_tm(
        [[[0], [0, 1], [], []], [[0], [0], [0, 1], []], [[1], [], [], [0]], [[1], [0], [0, 1], []]]
    )
    assert "3 -> 2" in other
    out = arm.draw_graph_from_tm(path=tmp_path / "model.dot")
    assert (tmp_path / "model.dot").read_text(encoding="utf-8") == out == source
    with pytest.raises(ModelError, match="square matrix"):
        arm.draw_graph_from_tm([[[0], [1]]])
