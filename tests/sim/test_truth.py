"""Tests for the ground truth: enumeration, minimisation, canonical numbering, equivalence."""

from __future__ import annotations

import doctest
import itertools
import json
import re
from collections import deque
from collections.abc import Mapping, Sequence

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_sim import truth as truth_module
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.table import pose_space_size
from rsstp_sim.arm.world import World
from rsstp_sim.errors import ModelError, RsstpError
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import (
    GroundTruth,
    TruthError,
    check_equivalence,
    compute_truth,
    format_truth,
)


def one_joint(step: int, *, actions: Sequence[int] = (0, 1), feedback: str = "") -> Scenario:
    return parse_scenario(
        f"name = 'one-joint-{step}'\n[arm]\nlengths = [1.0]\ninitial_deg = [0]\n"
        f"step_deg = {step}\nactions = {list(actions)}\n{feedback}"
    )


# ------------------------------------------------------------ reference code


def reference_counterexample(
    model: TransitionSystem, labels: Mapping[int, bool], truth: GroundTruth, start: int
) -> tuple[int, ...] | None:
    """Shortest, then first by action order, counterexample by a backward search.

    Distances to failure are computed over all (model state, class) pairs by a
    breadth-first search on the reversed product, then the sequence is read off
    greedily from the start: independent of the forward search under test.
    """
    classes = range(truth.n_classes)
    pairs = [(s, c) for s in model.states for c in classes]

    def wrong(s: int, c: int) -> bool:
        return labels.get(s) is None or labels[s] != bool(truth.class_sensation[c])

    def step(s: int, c: int, k: int) -> tuple[int, int] | None:
        successors = model.successors(s, truth.actions[k])
        return (successors[0], int(truth.class_next[c, k])) if len(successors) == 1 else None

    predecessors: dict[tuple[int, int], list[tuple[int, int]]] = {p: [] for p in pairs}
    fails_now = set()
    for s, c in pairs:
        for k in range(len(truth.actions)):
            target = step(s, c, k)
            if target is None:
                fails_now.add((s, c))
            else:
                predecessors[target].append((s, c))
    dist = {p: 0 for p in pairs if wrong(*p)}
    layer = list(dist)
    depth = 0
    while layer or depth == 0:
        following = [q for p in layer for q in predecessors[p] if q not in dist]
        if depth == 0:
            following += [p for p in fails_now if p not in dist]
        layer = list(dict.fromkeys(following))
        depth += 1
        for p in layer:
            dist[p] = depth
    here = (start, 0)
    if here not in dist:
        return None
    sequence: list[int] = []
    while dist[here] > 0:
        for k, action in enumerate(truth.actions):
            target = step(*here, k)
            if target is None and dist[here] == 1:
                return (*sequence, action)
            if target is not None and dist.get(target, -1) == dist[here] - 1:
                sequence.append(action)
                here = target
                break
    return tuple(sequence)


def replay_fails(
    model: TransitionSystem,
    labels: Mapping[int, bool],
    truth: GroundTruth,
    start: int,
    sequence: Sequence[int],
) -> bool:
    """Whether following ``sequence`` exposes a difference (at its end or before)."""
    state, c = start, 0
    if labels.get(state) != bool(truth.class_sensation[c]):
        return True
    for action in sequence:
        successors = model.successors(state, action)
        if len(successors) != 1:
            return True
        state, c = successors[0], int(truth.class_next[c, truth.actions.index(action)])
        if labels.get(state) != bool(truth.class_sensation[c]):
            return True
    return False


def brute_force_counterexample(
    model: TransitionSystem, labels: Mapping[int, bool], truth: GroundTruth, max_length: int
) -> tuple[int, ...] | None:
    for length in range(max_length + 1):
        for sequence in itertools.product(truth.actions, repeat=length):
            if replay_fails(model, labels, truth, model.current, sequence):
                return sequence
    return None


def plant(
    truth: GroundTruth, kind: str, c: int, k: int, other: int
) -> tuple[TransitionSystem, dict[int, bool]]:
    """The minimal model with one planted difference at class ``c`` and action index ``k``."""
    model, labels = truth.minimal_model(), truth.class_labels()
    action, target = truth.actions[k], int(truth.class_next[c, k])
    if kind == "redirect":
        model.delete(c, target, action)
        model.add(c, other, action)
    elif kind == "flip":
        labels[c] = not labels[c]
    elif kind == "delete":
        model.delete(c, target, action)
    elif kind == "nondeterministic":
        model.add(c, other if other != target else (target + 1) % truth.n_classes, action)
    return model, labels


# --------------------------------------------------------------- enumeration


def test_docstring_examples_run() -> None:
    result = doctest.testmod(truth_module)
    assert result.attempted > 0
    assert result.failed == 0


def test_roulette_is_a_minimal_four_cycle() -> None:
    truth = compute_truth(load_scenario("thesis-roulette"))
    assert (truth.n_poses, truth.n_classes, truth.n_sensed) == (4, 4, 1)
    assert truth.actions == (0,)
    assert truth.pose_codes.tolist() == [0, 90, 180, 270]
    assert truth.start_index == 0 and truth.true_class.tolist() == [0, 1, 2, 3]
    assert truth.next_pose.tolist() == [[1], [2], [3], [0]]
    assert truth.class_next.tolist() == [[1], [2], [3], [0]]
    assert truth.class_sensation.tolist() == [True, False, False, False]
    assert not truth.blocked.any()


def test_one_joint_10_has_36_classes() -> None:
    truth = compute_truth(load_scenario("one-joint-10"))
    assert (truth.n_poses, truth.n_classes, truth.n_sensed) == (36, 36, 1)
    assert truth.angles_deg[:, 0].tolist() == list(range(0, 360, 10))


def test_one_joint_90_with_both_actions_has_four_classes() -> None:
    truth = compute_truth(one_joint(90))
    assert (truth.n_poses, truth.n_classes) == (4, 4)
    # Turning -90 from 0 wraps to 270 (pose 3); +90 from 270 wraps to 0.
    assert truth.next_pose.tolist() == [[1, 3], [2, 0], [3, 1], [0, 2]]
    assert truth.class_of([0]) == 0 and truth.class_of([90]) == 1 and truth.class_of([270]) == 2


@pytest.mark.parametrize(
    "feedback",
    [
        "[feedback]\npoints = [[5.0, 5.0]]",  # never sensed
        "[feedback]\ntarget_deg = [45]",  # between two reachable poses
        "[feedback]\ntarget_deg = [0]\ntolerance = 2.5",  # always sensed
    ],
)
def test_uniform_sensation_collapses_to_one_class(feedback: str) -> None:
    truth = compute_truth(one_joint(90, feedback=feedback))
    assert truth.n_poses == 4 and truth.n_classes == 1
    assert truth.true_class.tolist() == [0, 0, 0, 0]
    assert truth.class_next.tolist() == [[0, 0]]


def test_thesis_obstacles_is_a_walled_segment_of_distinct_poses() -> None:
    # The obstacles (centres at distance sqrt(5), radius 1) block the link when its
    # direction is within atan(1/2) = 26.57 degrees of a centre's direction (63.43 and
    # 243.43 degrees): 37..90 and 217..270 are blocked (90 and 270 touch). From 95 the
    # arm sweeps 91..216. With walls at both ends and one sensed pose (100), the
    # number of -1 steps before the sensation (x >= 100) or of +1 steps (x < 100)
    # tells every pose apart.
    truth = compute_truth(load_scenario("thesis-obstacles"))
    assert truth.angles_deg[:, 0].tolist() == list(range(91, 217))
    assert truth.n_poses == truth.n_classes == 126
    assert truth.angles_deg[truth.sensation, 0].tolist() == [100]
    blocked = {
        (int(truth.angles_deg[p, 0]), truth.actions[k]) for p, k in np.argwhere(truth.blocked)
    }
    assert blocked == {(91, 1), (216, 0)}


def test_two_joint_30_builtin() -> None:
    scenario = load_scenario("two-joint-30")
    truth = compute_truth(scenario)
    assert pose_space_size(scenario) == 144
    assert (truth.n_poses, truth.n_classes, truth.n_sensed) == (119, 119, 1)
    assert truth.blocked.any() and not truth.blocked.all()
    # The second joint never reaches 180 (folding back onto the first link).
    assert 180 not in truth.angles_deg[:, 1].tolist()


@pytest.mark.parametrize("name", ["two-joint-30", "thesis-obstacles"])
def test_truth_agrees_with_the_world_on_a_random_walk(name: str) -> None:
    scenario = load_scenario(name)
    truth = compute_truth(scenario)
    world = World(scenario)
    rng = np.random.default_rng(7)
    pose = truth.start_index
    for k in rng.integers(0, len(truth.actions), 3000).tolist():
        blocker = world.move(truth.actions[k])
        assert (blocker is not None) == bool(truth.blocked[pose, k])
        pose = int(truth.next_pose[pose, k])
        assert world.pose_code == int(truth.pose_codes[pose])
        assert world.sensation == bool(truth.sensation[pose])
        assert world.angles_deg == tuple(truth.angles_deg[pose].tolist())


def test_refuses_a_pose_space_larger_than_the_limit() -> None:
    scenario = load_scenario("three-joint")
    assert pose_space_size(scenario) == 72**3
    message = (
        "three-joint: the pose space has 373,248 poses, more than the limit of "
        "200,000 (pass a larger max_poses)"
    )
    with pytest.raises(TruthError, match=f"^{re.escape(message)}$"):
        compute_truth(scenario, max_poses=200_000)
    assert issubclass(TruthError, RsstpError)


@pytest.mark.parametrize(
    ("name", "per_move"),
    [
        ("two-joint-30", False),
        ("two-joint-30", True),
        ("thesis-obstacles", False),
        ("one-way", True),
        ("rover-one-way", None),
        ("rover-two-rooms", None),
    ],
)
def test_the_truth_of_a_world_a_run_grew_is_its_bodys(name: str, per_move: bool | None) -> None:
    """A sweep's worker hands its audit the truth of the world its run was recorded in: that
    world's own table completed (grown in blocks or move by move) and its size read from it,
    the truth and the refusal a fresh table of the body gives."""
    from rsstp_sim.bodies import make_world
    from rsstp_sim.runner import Runner
    from rsstp_sim.strategies import RandomStrategy

    scenario = load_scenario(name)
    world = make_world(scenario) if per_move is None else World(scenario, per_move=per_move)
    Runner(scenario, RandomStrategy(), seed=3, world=world).run(400)
    assert compute_truth(scenario, world=world) == compute_truth(scenario)
    poses = compute_truth(scenario).n_poses
    with pytest.raises(TruthError, match=r"the pose space has [\d,]+ poses, more than the limit"):
        compute_truth(scenario, max_poses=poses - 1, world=make_world(scenario))


def test_pose_space_counts_only_turned_joints_and_the_step_lattice() -> None:
    only_first = parse_scenario(
        "[arm]\nlengths = [2.0, 1.0]\ninitial_deg = [0, 7]\nstep_deg = 40\nactions = [0, 1]"
    )
    assert pose_space_size(only_first) == 9  # gcd(40, 360) = 40: 9 angles, joint 1 fixed
    truth = compute_truth(only_first)
    assert truth.n_poses == 9 and set(truth.angles_deg[:, 1].tolist()) == {7}
    assert compute_truth(one_joint(7)).n_poses == 360  # gcd(7, 360) = 1


def test_arrays_and_consistency() -> None:
    truth = compute_truth(load_scenario("two-joint-30"))
    codes = truth.pose_codes
    assert np.all(np.diff(codes) > 0)
    assert np.array_equal(codes, truth.angles_deg @ np.array([1, 360]))
    assert truth.angles_deg[truth.start_index].tolist() == [0, 0]
    assert truth.true_class[truth.start_index] == 0
    assert np.array_equal(truth.blocked, truth.next_pose == np.arange(truth.n_poses)[:, None])
    assert np.array_equal(truth.class_next[truth.true_class], truth.true_class[truth.next_pose])
    assert np.array_equal(truth.class_sensation[truth.true_class], truth.sensation)
    for array in (truth.pose_codes, truth.next_pose, truth.true_class, truth.class_next):
        assert array.dtype == np.int64 and not array.flags.writeable


def test_classes_are_numbered_breadth_first() -> None:
    for scenario in (load_scenario("two-joint-30"), one_joint(30, actions=[1])):
        truth = compute_truth(scenario)
        order, queue = [0], deque([0])
        while queue:
            for c in truth.class_next[queue.popleft()].tolist():
                if c not in order:
                    order.append(c)
                    queue.append(c)
        assert order == list(range(truth.n_classes))


def test_minimal_model_is_deterministic_and_complete() -> None:
    truth = compute_truth(load_scenario("two-joint-30"))
    model = truth.minimal_model()
    assert model.states == tuple(range(truth.n_classes))
    assert model.current == 0 and model.actions == truth.actions
    assert model.determinism_report().complete
    assert model.transitions() == [
        (c, a, int(truth.class_next[c, k]))
        for c in range(truth.n_classes)
        for k, a in enumerate(truth.actions)
    ]
    assert model.drain_operations() == []


def test_class_of_and_pose_index() -> None:
    truth = compute_truth(load_scenario("thesis-obstacles"))
    assert truth.class_of([95]) == 0 and truth.class_of([95 + 360]) == 0
    assert truth.pose_index([100]) == 9
    with pytest.raises(TruthError, match=r"^thesis-obstacles: the pose \[60\] is not reachable"):
        truth.class_of([60])
    with pytest.raises(TruthError, match=r"expected 1 values \(angle_deg_0\), found 2"):
        truth.class_of([95, 0])
    with pytest.raises(TruthError, match="must be integers"):
        truth.class_of([95.0])  # type: ignore[list-item]


def test_equality_ignores_seconds_and_reports() -> None:
    scenario = load_scenario("two-joint-30")
    first, second = compute_truth(scenario), compute_truth(scenario)
    assert first == second and first.seconds > 0
    assert first != compute_truth(load_scenario("thesis-roulette"))
    summary = first.to_json()
    assert json.loads(json.dumps(summary)) == summary
    assert {k: v for k, v in summary.items() if k != "seconds"} == {
        "scenario": "two-joint-30",
        "actions": [0, 1, 2, 3],
        "reachable_poses": 119,
        "sensed_poses": 1,
        "minimal_model_states": 119,
    }
    lines = format_truth(first).splitlines()
    assert lines[0] == "scenario: two-joint-30"
    assert "reachable poses: 119" in lines and "minimal model: 119 states" in lines
    assert "sensed poses: 1" in lines and lines[-1].startswith("seconds: ")


# -------------------------------------------------------------- minimisation


# --------------------------------------------------------------- equivalence


def test_the_minimal_model_and_the_pose_machine_are_equivalent() -> None:
    truth = compute_truth(load_scenario("two-joint-30"))
    assert check_equivalence(truth.minimal_model(), truth.class_labels(), truth) is None
    poses = TransitionSystem(truth.n_poses, actions=truth.actions)
    for p, row in enumerate(truth.next_pose.tolist()):
        for action, q in zip(truth.actions, row, strict=True):
            poses.add(p, q, action)
    labels = dict(enumerate(truth.sensation.tolist()))
    assert check_equivalence(poses, labels, truth, start_state=truth.start_index) is None
    poses.current = truth.start_index
    assert check_equivalence(poses, labels, truth) is None
    assert truth.start_index == 0 and not truth.sensation[1]
    assert check_equivalence(poses, labels, truth, start_state=1) == ()


def test_universal_model_fails_at_once_or_after_one_step() -> None:
    truth = compute_truth(load_scenario("thesis-roulette"))
    universal = TransitionSystem.universal([0])
    assert check_equivalence(universal, {0: True}, truth) == (0,)
    assert check_equivalence(universal, {0: False}, truth) == ()
    assert check_equivalence(universal, {}, truth) == ()
    assert check_equivalence(TransitionSystem(1), {0: True}, truth) == (0,)
    with pytest.raises(ModelError, match="unknown start state 5"):
        check_equivalence(universal, {0: True}, truth, start_state=5)


@pytest.mark.parametrize("kind", ["redirect", "flip", "delete", "nondeterministic"])
@pytest.mark.parametrize("name", ["two-joint-30", "thesis-obstacles"])
def test_planted_differences_give_the_shortest_counterexample(kind: str, name: str) -> None:
    truth = compute_truth(load_scenario(name))
    rng = np.random.default_rng(11)
    for _ in range(5):
        c = int(rng.integers(truth.n_classes))
        k = int(rng.integers(len(truth.actions)))
        other = int(rng.integers(truth.n_classes))
        if kind == "redirect" and other == truth.class_next[c, k]:
            continue
        model, labels = plant(truth, kind, c, k, other)
        found = check_equivalence(model, labels, truth)
        assert found is not None
        assert replay_fails(model, labels, truth, 0, found)
        assert not replay_fails(model, labels, truth, 0, found[:-1]) if found else True
        assert found == reference_counterexample(model, labels, truth, 0)


def test_counterexample_matches_brute_force_on_a_small_case() -> None:
    truth = compute_truth(one_joint(60, feedback="[feedback]\ntarget_deg = [120]"))
    for kind, c, k, other in [
        ("redirect", 3, 0, 0),
        ("flip", 4, 0, 0),
        ("delete", 2, 1, 0),
        ("nondeterministic", 5, 1, 1),
    ]:
        model, labels = plant(truth, kind, c, k, other)
        found = check_equivalence(model, labels, truth)
        assert found == brute_force_counterexample(model, labels, truth, 8)
        assert found is not None


@settings(max_examples=60, deadline=None)
@given(
    step=st.sampled_from([30, 45, 60, 90, 120]),
    target=st.integers(0, 359),
    actions=st.sampled_from([(0,), (1,), (0, 1)]),
    kind=st.sampled_from(["redirect", "flip", "delete", "nondeterministic"]),
    data=st.data(),
)
def test_random_cycles(
    step: int, target: int, actions: tuple[int, ...], kind: str, data: st.DataObject
) -> None:
    truth = compute_truth(
        one_joint(step, actions=actions, feedback=f"[feedback]\ntarget_deg = [{target}]")
    )
    assert truth.n_poses == 360 // step
    assert truth.n_classes == (truth.n_poses if target % step == 0 else 1)
    c = data.draw(st.integers(0, truth.n_classes - 1))
    k = data.draw(st.integers(0, len(actions) - 1))
    other = data.draw(st.integers(0, truth.n_classes - 1))
    model, labels = plant(truth, kind, c, k, other)
    found = check_equivalence(model, labels, truth)
    assert found == reference_counterexample(model, labels, truth, 0)
    if found is None:  # only a redirect, or no change at all when there is one class
        assert kind == "redirect" or (kind == "nondeterministic" and truth.n_classes == 1)
    else:
        assert replay_fails(model, labels, truth, 0, found)
        if len(found) <= 10:
            assert found == brute_force_counterexample(model, labels, truth, len(found))
