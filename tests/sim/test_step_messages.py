"""Step and blocked-event messages from templates: the bytes of the record types' encoder.

Each run here is played live, without a recorder; every step's message from
:class:`StepMessages` is compared with ``records.encode`` of the builders' record for the
same step, and every blocked move's event likewise. The runs cover obstacles and none,
blocked moves, steps with no transition, float feedback, a model that changes, and arms of
one to seven links. Random steps (hypothesis) are compared with records built field by field,
not by the builders: msgspec's encoding of the equivalent record, whatever the numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from types import SimpleNamespace
from typing import ClassVar

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from steps import step_record_after

from rsstp_format import records
from rsstp_format.vocabulary import BLOCKER_ARITY
from rsstp_sim import (
    AgentView,
    RandomStrategy,
    Runner,
    StepOutcome,
    StrategyBase,
    load_scenario,
)
from rsstp_sim.arm.geometry import ARM_BLOCKER_KINDS, Blocker
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.world import Pose as ArmPose
from rsstp_sim.recording import builders
from rsstp_sim.recording.chunks import Message
from rsstp_sim.recording.step_messages import BlockMessages, StepMessages, Steps
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.strategies import Strategy, make_strategy
from rsstp_sim.transition_system import TransitionSystem
from scenarios import arm_toml


class EvenActionsOnly(StrategyBase):
    """Random actions in a one-state model with transitions for the even actions only: every
    odd action is a step with no transition."""

    name: ClassVar[str] = "even-only"

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        model = TransitionSystem(1, actions=actions)
        for action in actions[::2]:
            model.add(0, 0, action)
        return model

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]


def seven_links() -> Scenario:
    text = arm_toml(
        [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4],
        [0, 20, 20, 20, 20, 20, 20],
        5,
        [((2.0, 2.5), 0.4), ((-1.0, 1.0), 0.3), ((0.5, -3.0), 0.2)],
        feedback={"mode": "float", "target_deg": [10, 20, 20, 20, 20, 20, 20]},
    )
    return parse_scenario(text, origin="seven.toml")


CASES: list[tuple[str, Callable[[], Strategy]]] = [
    ("three-joint", RandomStrategy),
    ("two-joint-30", lambda: make_strategy("learner")),
    ("thesis-obstacles", lambda: make_strategy("roulette")),
    ("one-joint-10", EvenActionsOnly),
    ("thesis-algo", lambda: make_strategy("splitter")),
    ("seven", RandomStrategy),
    ("rover-two-rooms", RandomStrategy),  # the rover's own truth (walls, obstacles, edges)
    ("rover-one-way", RandomStrategy),  # and its one-way door
]


def expected_step(runner: Runner, outcome: StepOutcome | None) -> bytes:
    """``records.encode`` of the builders' step record (the independent computation)."""
    return records.encode(step_record_after(runner.world.current, runner.model, outcome))


def live(
    runner: Runner, steps: int, taken: list[StepOutcome], expected: list[bytes] | None = None
) -> Iterator[StepOutcome]:
    """Up to ``steps`` steps of ``runner``, each kept in ``taken`` as it is taken, with its
    message's bytes in ``expected``."""
    for _ in range(steps):
        if runner.stopped is not None:
            return
        taken.append(runner.step())
        if expected is not None:
            expected.append(expected_step(runner, taken[-1]))
        yield taken[-1]


STEP, EVENT, THEN = 4, 8, 9  # the channels here


@pytest.mark.parametrize(("scenario_name", "strategy"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.parametrize("block_steps", [1, 37, 4096])
def test_every_message_is_the_encoders(
    scenario_name: str, strategy: Callable[[], Strategy], block_steps: int
) -> None:
    scenario = seven_links() if scenario_name == "seven" else load_scenario(scenario_name)
    runner = Runner(scenario, strategy(), seed=3)
    messages = StepMessages()
    head, tail = messages.first(
        runner.world.current,
        internal_state=runner.model.current,
        model_version=runner.model.version,
    )
    assert head + tail == expected_step(runner, None)
    taken: list[StepOutcome] = []
    expected: list[bytes] = []
    followed: list[int] = []  # the steps ``then`` was called for

    def then(outcome: StepOutcome) -> Iterator[Message]:
        followed.append(outcome.step)
        yield (THEN, outcome.step, b"after", b"")

    blocks = messages.blocks(
        live(runner, 3000, taken, expected),
        runner.world,
        runner.model,
        channel=STEP,
        waiting=(),
        then=then,
        steps=block_steps,
        max_bytes=1 << 20,
    )
    got = [(ch, t, data + tail) for ch, t, data, tail in BlockMessages(STEP, EVENT).of(blocks)]
    # The independent order: each step's message; then, for a step with no transition,
    # then's message (its events are the recorder's); for a blocked step, its event.
    want: list[tuple[int, int, bytes]] = []
    for outcome, step_bytes in zip(taken, expected, strict=True):
        t = outcome.step
        want.append((STEP, t * 1_000_000, step_bytes))
        if outcome.no_transition:
            want.append((THEN, t, b"after"))
        elif outcome.blocker is not None:
            event = builders.blocked_event(t, action=outcome.action, blocker=outcome.blocker)
            want.append((EVENT, t * 1_000_000, records.encode(event)))
            got_event = messages.blocked_event(t, outcome.action, outcome.blocker)
            assert got_event == records.encode(event)  # the recorder's, for a whole step
    assert got == want
    assert followed == [o.step for o in taken if o.no_transition]
    assert messages.column_events == sum(
        o.blocker is not None and not o.no_transition for o in taken
    )
    # Each case shows what it is here for.
    if scenario_name in ("three-joint", "thesis-obstacles", "seven"):
        assert any(o.blocker is not None for o in taken)
    if scenario_name == "one-joint-10":
        assert any(o.no_transition for o in taken)
    if scenario_name in ("two-joint-30", "thesis-algo"):
        assert len({record.split(b'"model_version":')[1][:4] for record in expected}) > 1


def test_then_follows_every_step_while_something_waits() -> None:
    """While something waits (a model change, a note), a step's messages are whole and
    ``then`` follows it, a blocked step's included (its event comes from ``then``)."""
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=1)
    waiting: list[int] = []
    taken: list[StepOutcome] = []
    followed: list[int] = []

    def steps() -> Iterator[StepOutcome]:
        for outcome in live(runner, 400, taken):
            if outcome.step % 10 == 0 or outcome.blocker is not None and outcome.step % 2:
                waiting.append(1)  # as a model change or a note during the step would
            yield outcome

    def then(outcome: StepOutcome) -> Iterator[Message]:
        followed.append(outcome.step)
        waiting.clear()
        return iter(())

    messages = StepMessages()
    blocks = messages.blocks(
        steps(),
        runner.world,
        runner.model,
        channel=STEP,
        waiting=waiting,
        then=then,
        steps=64,
        max_bytes=1 << 20,
    )
    got = list(BlockMessages(STEP, EVENT).of(blocks))
    assert [m[1] // 1_000_000 for m in got if m[0] == STEP] == [o.step for o in taken]
    waited = [o.step for o in taken if o.step % 10 == 0 or o.blocker is not None and o.step % 2]
    assert followed == waited
    blocked = [o.step for o in taken if o.blocker is not None and o.step not in waited]
    assert blocked  # blocked steps of both kinds
    assert [m[1] // 1_000_000 for m in got if m[0] == EVENT] == blocked
    assert messages.column_events == len(blocked)


def test_past_its_bound_the_pose_cache_keeps_nothing_more_and_the_bytes_stay() -> None:
    """A world of many obstacles or a long run: once the cached parts reach the bound, the
    poses met after are encoded at each visit, to the same bytes."""
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=5)
    messages = StepMessages(cache_bytes=3000)  # a pose's parts are about 500 bytes
    taken: list[StepOutcome] = []
    expected: list[bytes] = []
    blocks = list(
        messages.blocks(
            live(runner, 500, taken, expected),
            runner.world,
            runner.model,
            channel=STEP,
            waiting=(),
            then=lambda _: iter(()),
            steps=50,
            max_bytes=2000,  # (a block of a few new tails)
        )
    )
    got = [data + tail for ch, _, data, tail in BlockMessages(STEP, EVENT).of(blocks) if ch == STEP]
    assert got == expected
    # A block ends at 50 steps, or sooner after 2,000 bytes of new tails: many blocks early.
    steps_in = [
        sum(len(i.columns) // 4 if isinstance(i, Steps) else i[0] == STEP for i in block)
        for block in blocks
    ]
    assert sum(steps_in) == 500 and max(steps_in) <= 50 and len(blocks) > 10
    assert min(steps_in[:3]) < 10  # (every pose new at first: a block of a few steps)
    poses = {record.split(b'"truth":')[1] for record in expected}
    assert len(poses) > 50  # many poses, past the few the bound keeps
    # The poses' parts and the tails given (at the one model version) share the bound.
    sizes = [len(head) + len(tail) for head, tail, _ in messages._poses.values()]
    sizes += [
        len(t)
        for block in blocks
        for item in block
        if isinstance(item, Steps)
        for t in item.new_tails
    ]
    assert 3000 <= sum(sizes) < 3000 + max(sizes)  # kept while below the bound, then no more


# ------------------------------------------------- random steps against the records


class FakePose:
    """A world pose as :class:`StepMessages` reads it (compared by identity): its observation
    and its ground truth as flat lists (positions ``x0, y0, x1, ...``; distances tip by tip)."""

    def __init__(
        self,
        angles: list[int],
        positions: list[float],
        distances: list[float],
        *,
        feedback: float,
        sensation: bool,
    ) -> None:
        self.angles, self.positions, self.distances = angles, positions, distances
        self.feedback, self.sensation = feedback, sensation

    def truth_values(self) -> tuple[list[int], list[float], list[float]]:
        return self.angles, self.positions, self.distances

    # The arm's byte templates, under test: they read the numbers through truth_values.
    truth_json = ArmPose.truth_json

    def truth_record(self, blocker: Blocker | None) -> records.TruthRecord:
        """The record of this pose's truth, built field by field (not by the builders)."""
        xy, n = self.positions, len(self.angles)
        m = len(self.distances) // n
        return records.TruthRecord(
            angles_deg=tuple(self.angles),
            joint_positions=tuple(
                records.PointRecord(x=xy[2 * k], y=xy[2 * k + 1]) for k in range(n + 1)
            ),
            blocked=blocker is not None,
            blocked_by=None
            if blocker is None
            else records.BlockedByRecord(kind=blocker.kind, indices=blocker.indices),
            distances=tuple(
                records.DistancesRecord(obstacles=tuple(self.distances[k * m : (k + 1) * m]))
                for k in range(n)
            ),
        )


finite = st.floats(allow_nan=False, allow_infinity=False)
state_ids = st.integers(min_value=0, max_value=2**40)


@st.composite
def poses(draw: st.DrawFn, n: int, m: int) -> FakePose:
    return FakePose(
        draw(st.lists(st.integers(0, 359), min_size=n, max_size=n)),
        draw(st.lists(finite, min_size=2 * (n + 1), max_size=2 * (n + 1))),
        draw(st.lists(finite, min_size=n * m, max_size=n * m)),
        feedback=draw(st.floats(min_value=0.0, max_value=1.0)),
        sensation=draw(st.booleans()),
    )


@st.composite
def blockers(draw: st.DrawFn) -> Blocker:
    kind = draw(st.sampled_from(ARM_BLOCKER_KINDS))
    indices = draw(st.lists(st.integers(0, 50), min_size=1, max_size=1))
    if BLOCKER_ARITY[kind] == 2:
        indices.append(draw(st.integers(0, 50)))
    return Blocker(kind, tuple(indices))


@st.composite
def runs(draw: st.DrawFn) -> tuple[list[FakePose], list[tuple[StepOutcome, int, int]]]:
    """A few poses of an arm of ``n`` links among ``m`` obstacles, and steps among them from
    a random first step: each an outcome, its pose's number and the model's version after
    it (which grows now and then). The world is deterministic, as every world is: the same
    action from the same pose meets the same blocker (or none) every time."""
    n, m = draw(st.integers(1, 5)), draw(st.integers(0, 4))
    pose_list = draw(st.lists(poses(n, m), min_size=1, max_size=4))
    t = draw(st.integers(1, 10**9))
    version = draw(st.integers(0, 2**40))
    physics: dict[tuple[int, int], Blocker | None] = {}
    steps = []
    for _ in range(draw(st.integers(1, 25))):
        version += draw(st.sampled_from([0, 0, 0, 1]))
        action, pose = draw(st.integers(0, 2 * n - 1)), draw(st.integers(0, len(pose_list) - 1))
        if (pose, action) not in physics:
            physics[pose, action] = draw(st.none() | blockers())
        outcome = StepOutcome(
            t,
            action,
            draw(state_ids),
            draw(state_ids),
            physics[pose, action],
            draw(st.booleans()),
            0,
        )
        steps.append((outcome, pose, version))
        t += 1
    return pose_list, steps


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    run=runs(),
    cache_bytes=st.sampled_from([0, 600, 1 << 20]),
    block_steps=st.integers(1, 8),
    max_bytes=st.sampled_from([100, 1 << 20]),
    waiting=st.sampled_from([(), ("a model message",)]),
    reset=st.tuples(state_ids, state_ids),
)
def test_random_steps_are_the_encoding_of_their_records(
    run: tuple[list[FakePose], list[tuple[StepOutcome, int, int]]],
    cache_bytes: int,
    block_steps: int,
    max_bytes: int,
    waiting: tuple[str, ...],
    reset: tuple[int, int],
) -> None:
    """The templates' bytes of random steps (random floats, ids, blockers, versions; a pose
    cache from none to roomy; blocks of any size) are msgspec's encoding of the records of
    the same steps, built field by field; and each blocked step's event is its record's."""
    pose_list, steps = run
    messages = StepMessages(cache_bytes=cache_bytes)
    first = pose_list[steps[0][1]]
    internal_state, model_version = reset
    head, tail = messages.first(first, internal_state=internal_state, model_version=model_version)
    agent = records.AgentRecord(
        internal_state=internal_state,
        sensation=first.sensation,
        feedback=first.feedback,
        model_version=model_version,
        no_transition=False,
    )
    step_0 = records.StepRecord(step=0, agent=agent, truth=first.truth_record(None))
    assert head + tail == records.encode(step_0)

    world, model = SimpleNamespace(current=first), SimpleNamespace(version=-1)

    def outcomes() -> Iterator[StepOutcome]:
        for outcome, pose, version in steps:
            world.current, model.version = pose_list[pose], version
            yield outcome

    def then(outcome: StepOutcome) -> Iterator[Message]:
        if outcome.blocker is not None:  # (as the recorder: the event of a step given whole)
            event = messages.blocked_event(outcome.step, outcome.action, outcome.blocker)
            yield EVENT, outcome.step * 1_000_000, event, b""

    blocks = messages.blocks(
        outcomes(),
        world,  # type: ignore[arg-type]
        model,  # type: ignore[arg-type]
        channel=STEP,
        waiting=waiting,
        then=then,
        steps=block_steps,
        max_bytes=max_bytes,
    )
    got = [(ch, at, data + tail) for ch, at, data, tail in BlockMessages(STEP, EVENT).of(blocks)]
    want = []
    for outcome, pose, version in steps:
        t, action, before, after, blocker, no_transition, _ = outcome
        agent = records.AgentRecord(
            action=action,
            state_before=before,
            internal_state=after,
            sensation=pose_list[pose].sensation,
            feedback=pose_list[pose].feedback,
            model_version=version,
            no_transition=no_transition,
        )
        record = records.StepRecord(
            step=t, agent=agent, truth=pose_list[pose].truth_record(blocker)
        )
        want.append((STEP, t * 1_000_000, records.encode(record)))
        if blocker is not None:
            by = {"kind": blocker.kind, "indices": list(blocker.indices)}
            text = f"action {action} blocked: {blocker.describe()}"
            event = records.EventRecord(
                step=t, kind="blocked", text=text, data={"action": action, "blocked_by": by}
            )
            want.append((EVENT, t * 1_000_000, records.encode(event)))
    assert got == want
