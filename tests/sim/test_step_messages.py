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
from rsstp_sim.recording.step_messages import StepMessages
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


def live(runner: Runner, steps: int, taken: list[StepOutcome]) -> Iterator[StepOutcome]:
    """Up to ``steps`` steps of ``runner``, each kept in ``taken`` as it is taken."""
    for _ in range(steps):
        if runner.stopped is not None:
            return
        taken.append(runner.step())
        yield taken[-1]


@pytest.mark.parametrize(("scenario_name", "strategy"), CASES, ids=[c[0] for c in CASES])
def test_every_message_is_the_encoders(
    scenario_name: str, strategy: Callable[[], Strategy]
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
    followed: list[int] = []  # the steps ``then`` was called for

    def then(outcome: StepOutcome) -> Iterator[Message]:
        followed.append(outcome.step)
        yield (9, outcome.step, b"after", b"")

    stream = messages.stream(
        live(runner, 3000, taken), runner.world, runner.model, channel=4, waiting=(), then=then
    )
    blocked = no_transition = 0
    versions = {runner.model.version}
    expected_then: list[int] = []
    for channel, log_time, head, tail in stream:
        outcome = taken[-1]
        if channel == 9:  # then's message, right after its step's
            assert (log_time, head) == (outcome.step, b"after")
            continue
        assert (channel, log_time) == (4, outcome.step * 1_000_000)
        assert head + tail == expected_step(runner, outcome), outcome
        if outcome.blocker is not None:
            blocked += 1
            event = builders.blocked_event(
                outcome.step, action=outcome.action, blocker=outcome.blocker
            )
            got = messages.blocked_event(outcome.step, outcome.action, outcome.blocker)
            assert got == records.encode(event)
        if outcome.blocker is not None or outcome.no_transition:
            expected_then.append(outcome.step)
        no_transition += outcome.no_transition
        versions.add(runner.model.version)
    assert followed == expected_then
    # Each case shows what it is here for.
    if scenario_name in ("three-joint", "thesis-obstacles", "seven"):
        assert blocked
    if scenario_name == "one-joint-10":
        assert no_transition
    if scenario_name in ("two-joint-30", "thesis-algo"):
        assert len(versions) > 1


def test_then_follows_every_step_while_something_waits() -> None:
    runner = Runner(load_scenario("two-joint-30"), RandomStrategy(), seed=1)
    waiting: list[int] = []
    taken: list[StepOutcome] = []
    followed: list[int] = []

    def steps() -> Iterator[StepOutcome]:
        for outcome in live(runner, 40, taken):
            if outcome.step % 10 == 0:
                waiting.append(1)  # as a model change or a note during the step would
            yield outcome

    def then(outcome: StepOutcome) -> Iterator[Message]:
        followed.append(outcome.step)
        waiting.clear()
        return iter(())

    stream = StepMessages().stream(
        steps(), runner.world, runner.model, channel=1, waiting=waiting, then=then
    )
    assert len(list(stream)) == 40
    plain = [o.step for o in taken if o.blocker is None and not o.no_transition]
    assert len(plain) > 30
    assert followed == [
        o.step for o in taken if o.step % 10 == 0 or o.blocker is not None or o.no_transition
    ]


def test_past_its_bound_the_pose_cache_keeps_nothing_more_and_the_bytes_stay() -> None:
    """A world of many obstacles or a long run: once the cached parts reach the bound, the
    poses met after are encoded at each visit, to the same bytes."""
    runner = Runner(load_scenario("three-joint"), RandomStrategy(), seed=5)
    messages = StepMessages(cache_bytes=3000)  # a pose's parts are about 500 bytes
    poses = set()
    taken: list[StepOutcome] = []
    stream = messages.stream(
        live(runner, 500, taken),
        runner.world,
        runner.model,
        channel=1,
        waiting=(),
        then=lambda _: iter(()),
    )
    for _, _, head, tail in stream:
        poses.add(runner.world.current)
        assert head + tail == expected_step(runner, taken[-1]), taken[-1]
    assert len(poses) > 50
    # The poses' parts and the steps' tails (at the one model version) share the bound.
    sizes = [len(head) + len(tail) for head, tail, _ in messages._poses.values()]
    sizes += [len(tail) for tail in messages._tails.values()]
    assert 3000 <= sum(sizes) < 3000 + max(sizes)  # kept while below the bound, then no more
