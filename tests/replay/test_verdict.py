"""The verdict against a product search written here, in random worlds, one-way worlds included.

"Learned" means: the final model has a state that behaves as the start pose, and the state of
every step its version was in force behaves as the step's true class. The test searches the
product of a model and the minimal machine pair by pair, in plain Python, and derives the
verdict, ``learned_at_step``, the per-version ``equivalent`` column and the confinement from
that alone.
"""

from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pytest
from fakes import FakeRecording, RandomRefiner
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from rsstp_replay import open_recording
from rsstp_replay.audits import audit_truth
from rsstp_sim import load_scenario, make_strategy, parse_scenario
from rsstp_sim.recording import record
from rsstp_sim.strategies import LearnerStrategy, RandomStrategy, SplitterStrategy
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth, compute_truth
from scenarios import arm_toml
from waiting import HANG_S

OBSTACLE_SPOTS = [((0.0, 2.2), 0.3), ((-1.5, 1.5), 0.4), ((0.0, -2.2), 0.3), ((-2.5, 0.0), 0.3)]
"""Obstacles clear of the straight arm along +x (the start pose)."""


def behaves_as(
    model: TransitionSystem, labels: Mapping[int, bool], truth: GroundTruth, state: int, cls: int
) -> bool:
    """Whether no action sequence tells model state ``state`` from true class ``cls``."""
    seen: set[tuple[int, int]] = set()
    stack = [(state, cls)]
    while stack:
        pair = stack.pop()
        if pair in seen:
            continue
        seen.add(pair)
        s, c = pair
        if s not in labels or labels[s] != bool(truth.class_sensation[c]):
            return False
        for k, action in enumerate(truth.actions):
            successors = model.successors(s, action)
            if len(successors) != 1:
                return False
            stack.append((successors[0], int(truth.class_next[c][k])))
    return True


def reached(edges: Mapping[int, set[int]], start: int) -> set[int]:
    found, stack = {start}, [start]
    while stack:
        for following in edges.get(stack.pop(), set()):
            if following not in found:
                found.add(following)
                stack.append(following)
    return found


def expected_verdict(
    recording: FakeRecording, truth: GroundTruth
) -> tuple[bool, int | None, list[bool], int | None, int]:
    """(learned, learned_at_step, equivalent per version, confined_since_step,
    reachable_classes), the slow way."""
    steps = recording.steps()
    columns = list(truth.value_names)
    classes = [truth.class_of(row) for row in steps[columns].to_numpy().tolist()]
    memory = recording.memory()
    states = [int(s) for s in memory.internal_states]
    sensed = [bool(s) for s in memory.sensations]
    versions = recording.model_versions()
    starts = [v.step for v in versions]
    in_force = [sum(1 for s in starts if s <= t) - 1 for t in range(len(states))]
    equivalent = []
    for k, message in enumerate(versions):
        model = TransitionSystem.from_snapshot(message.snapshot())
        mine = [t for t in range(len(states)) if in_force[t] == k]
        last = mine[-1] if mine else message.step
        labels: dict[int, bool] = {}
        for t in range(last + 1):
            labels[states[t]] = sensed[t]
        pairs = [(states[t], classes[t]) for t in mine] or [
            (message.current, classes[message.step])
        ]
        equivalent.append(
            any(behaves_as(model, labels, truth, s, 0) for s in model.states)
            and all(behaves_as(model, labels, truth, s, c) for s, c in pairs)
        )
    learned = equivalent[-1]
    learned_at = None
    if learned:
        learned_at = 0
        for t in range(len(states)):
            if not equivalent[in_force[t]]:
                learned_at = t + 1
    forward: dict[int, set[int]] = {}
    backward: dict[int, set[int]] = {}
    for c, row in enumerate(truth.class_next.tolist()):
        for d in row:
            forward.setdefault(c, set()).add(d)
            backward.setdefault(d, set()).add(c)
    returning = reached(backward, 0)
    confined = None
    if classes[-1] not in returning:
        confined = max(t for t in range(len(classes)) if classes[t] in returning) + 1
    return learned, learned_at, equivalent, confined, len(reached(forward, classes[-1]))


@st.composite
def worlds(draw: st.DrawFn) -> str:
    joints = draw(st.integers(1, 2))
    step = draw(st.sampled_from([45, 60, 90, 120]))
    every = list(range(2 * joints))
    actions = draw(st.lists(st.sampled_from(every), min_size=1, max_size=len(every), unique=True))
    obstacles = draw(st.lists(st.sampled_from(OBSTACLE_SPOTS), max_size=2, unique=True))
    target = [draw(st.sampled_from([0, step, 360 - step])) for _ in range(joints)]
    return arm_toml(
        [2.0, 1.0][:joints],
        [0] * joints,
        step,
        obstacles,
        name="random-world",
        actions=sorted(actions),
        feedback={"target_deg": target},
    )


STRATEGIES = {
    "learner": LearnerStrategy,
    "random": RandomStrategy,
    "splitter": SplitterStrategy,
    "refiner": lambda: RandomRefiner(split=0.1, max_states=12),
}


@pytest.mark.slow
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    world=worlds(),
    strategy=st.sampled_from(sorted(STRATEGIES)),
    seed=st.integers(0, 2**16),
    steps=st.integers(1, 160),
)
def test_the_verdict_agrees_with_a_product_search(
    world: str, strategy: str, seed: int, steps: int
) -> None:
    scenario = parse_scenario(world)
    truth = compute_truth(scenario)
    recording = FakeRecording(scenario, STRATEGIES[strategy](), seed=seed, steps=steps)
    findings = audit_truth(recording, truth=truth)
    learned, learned_at, equivalent, confined, reachable = expected_verdict(recording, truth)
    verdict = findings.verdict
    event(f"learned={learned}, confined={confined is not None}")
    assert verdict.learned == learned
    assert verdict.learned_at_step == learned_at
    assert findings.versions["equivalent"].tolist() == equivalent
    assert (None if verdict.confinement is None else verdict.confinement.step) == confined
    assert verdict.reachable_classes == reachable
    if learned:
        assert verdict.line().startswith("learned:")
    else:
        assert verdict.line().startswith("not learned:")


def _one_way(actions: Sequence[int]) -> str:
    return arm_toml(
        [2.0, 1.0],
        [0, 0],
        30,
        [((0.0, 2.2), 0.3)],
        name="one-way",
        actions=list(actions),
        feedback={"target_deg": [0, 0]},
    )


def test_a_one_way_world_is_not_learned_from_where_the_arm_ended() -> None:
    """Both joints turn one way only; the obstacle traps the first joint, so the start pose is
    never reached again. A model right about the trapped part is still not learned."""
    scenario = parse_scenario(_one_way([0, 2]))
    truth = compute_truth(scenario)
    recording = FakeRecording(scenario, LearnerStrategy(), seed=0, steps=400)
    verdict = audit_truth(recording, truth=truth).verdict
    assert not verdict.learned
    assert verdict.confinement is not None and verdict.confinement.step >= 1
    returning = truth.classes_returning_to(0)
    steps = recording.steps()
    classes = truth.classes_of(steps[["angle_deg_0", "angle_deg_1"]].to_numpy())
    assert returning[classes[verdict.confinement.step - 1]]
    assert not returning[classes[verdict.confinement.step :]].any()
    assert verdict.confinement.action == int(steps["action"].iloc[verdict.confinement.step])
    assert "cannot return" in verdict.line()
    assert verdict.to_json()["confined_since_step"] == verdict.confinement.step
    assert verdict.to_json()["reachable_classes"] == int(
        np.count_nonzero(truth.classes_reached_from(int(classes[-1])))
    )


@pytest.mark.slow
def test_the_command_line_fails_a_one_way_run_and_says_why(tmp_path: Path) -> None:
    """`audit --truth --fail-on not-learned` exits 1 on the built-in one-way world, whatever
    the model knows of where the arm ended; the JSON names the confinement."""
    path = tmp_path / "one-way.mcap"
    record(path, load_scenario("one-way"), make_strategy("learner"), steps=600, seed=0)
    command = [sys.executable, "-m", "rsstp_cli.replay", "audit", "--truth", str(path)]
    gated = subprocess.run(
        [*command, "--fail-on", "not-learned"], capture_output=True, text=True, timeout=HANG_S
    )
    assert gated.returncode == 1
    assert "cannot return to where it started" in gated.stderr
    document = json.loads(
        subprocess.run(
            [*command, "--json"], capture_output=True, text=True, timeout=HANG_S, check=True
        ).stdout
    )
    verdict = document["verdict"]
    truth = compute_truth(load_scenario("one-way"))
    with open_recording(path) as recording:
        steps = recording.steps()
    classes = truth.classes_of(steps[["angle_deg_0", "angle_deg_1"]].to_numpy())
    back = truth.classes_returning_to(0)
    expected_step = int(np.flatnonzero(back[classes])[-1]) + 1
    assert verdict["learned"] is False
    assert verdict["confined_since_step"] == expected_step
    assert verdict["confining_move"] == {
        "action": int(steps["action"].iloc[expected_step]),
        "pose_before": steps[["angle_deg_0", "angle_deg_1"]].iloc[expected_step - 1].tolist(),
        "pose_after": steps[["angle_deg_0", "angle_deg_1"]].iloc[expected_step].tolist(),
    }
    assert verdict["reachable_classes"] == int(truth.classes_reached_from(int(classes[-1])).sum())
    assert verdict["reachable_classes"] < truth.n_classes
