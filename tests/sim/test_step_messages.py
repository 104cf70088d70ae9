"""Step and blocked-event messages from templates: the bytes of the record types' encoder.

Each run here is played live, without a recorder; every step's message from
:class:`StepMessages` is compared with ``records.encode`` of the builders' record for the
same step, and every blocked move's event likewise. The runs cover obstacles and none,
blocked moves, steps with no transition, float feedback, a model that changes, and arms of
one to seven links.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import ClassVar

import pytest
from steps import step_record_after

from rsstp_sim import (
    AgentView,
    RandomStrategy,
    Runner,
    StepOutcome,
    StrategyBase,
    load_scenario,
)
from rsstp_sim.recording import builders, records
from rsstp_sim.recording.chunks import Message
from rsstp_sim.recording.step_messages import BlockMessages, StepMessages, Steps
from rsstp_sim.scenario import Scenario, parse_scenario
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
