"""Coupling the agent with the world, one step at a time (docs/model.md).

One step: the strategy picks an action; the world executes it (blocked or
not); the internal state moves to a successor of (current state, action),
chosen by the run's seeded generator when there are several, and stays (with
a ``no_transition`` event) when there is none; the memory gets the entry; the
strategy may refine the model. The agent never sees whether the move was
blocked: that is ground truth, kept for analysis.

The internal state of a step is the model's current state at the *end* of the
step, after the refinement: a strategy that re-localises (sets
``model.current``, or merges the current state away) changes where the agent
is, and the memory entry of the step says so. So the state of entry ``t`` is
always a state of the model as it was at the end of step ``t``, and it is the
state step ``t + 1`` starts from (docs/contract.md).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal, NamedTuple

import numpy as np

from rsstp_sim.bodies import make_world
from rsstp_sim.errors import ActionError, StrategyError
from rsstp_sim.interface import Blocker, World
from rsstp_sim.memory import Memory
from rsstp_sim.scenario import AnyScenario
from rsstp_sim.strategies import AgentView, Strategy, StrategyBase
from rsstp_sim.transition_system import Operation, TransitionSystem
from rsstp_sim.words import counted

__all__ = [
    "Event",
    "RunSummary",
    "Runner",
    "StepOutcome",
    "check_strategy",
    "start_agent",
    "stop_text",
]

EventKind = Literal["no_transition", "note"]


class StepOutcome(NamedTuple):
    """What happened in one step (the ground truth ``blocker`` included).

    ``followed`` is the successor the transition led to; ``state_after`` is the internal
    state at the end of the step, after the strategy's refinement (the two differ when the
    strategy re-localised).
    """

    step: int
    action: int
    state_before: int
    state_after: int
    blocker: Blocker | None
    no_transition: bool
    followed: int


@dataclass(frozen=True, slots=True)
class Event:
    """Something worth a line in the log: a step with no transition, or a strategy note.

    A note's ``data`` is empty, or ``{"phase": p}`` when the strategy entered phase ``p``
    at this step (:meth:`~rsstp_sim.strategies.AgentView.enter`).
    """

    step: int
    kind: EventKind
    text: str
    data: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class RunSummary:
    steps: int
    blocked: int
    no_transition: int
    sensations: dict[bool, int] = field(default_factory=dict)
    model_states: int = 0
    model_transitions: int = 0
    deterministic: bool = True
    stopped: str | None = None
    budget: int | None = None

    def to_text(self) -> str:
        seen = ", ".join(f"{str(k).lower()}: {v:,}" for k, v in sorted(self.sensations.items()))
        stop = (
            ""
            if self.stopped is None
            else f"{stop_text(self.steps, self.budget)}: {self.stopped}\n"
        )
        return (
            stop + f"steps: {self.steps:,}\n"
            f"blocked moves: {self.blocked:,}\n"
            f"steps with no transition in the model: {self.no_transition:,}\n"
            f"sensations seen: {seen}\n"
            f"model: {counted(self.model_states, 'state')}, "
            f"{counted(self.model_transitions, 'transition')}, "
            f"{'deterministic' if self.deterministic else 'nondeterministic'}"
        )


def start_agent(
    strategy: Strategy,
    actions: tuple[int, ...],
    rng: np.random.Generator,
    sensation: bool,
    feedback: float,
    *,
    float_feedback: bool,
    notes: Callable[[str], None],
    phases: Callable[[str], None],
) -> AgentView:
    """The agent at the start of a run: the strategy's initial model, the memory's entry 0
    (what was sensed and felt at the start pose) and the strategy reset on its view."""
    model = strategy.initial_model(actions)
    model.drain_operations()
    memory = Memory()
    memory.reset(model.current, sensation, feedback)
    agent = AgentView(memory, model, actions, rng, notes, phases, float_feedback=float_feedback)
    strategy.reset(agent)
    return agent


def check_strategy(strategy: Strategy, actions: tuple[int, ...], *, float_feedback: bool) -> None:
    """Raise the strategy's error if it does not accept a world of ``actions`` and of float
    (else boolean) feedback, what its agent sees of a scenario: the strategy reset on an agent
    at a start that senses nothing. No world is built (a sweep checks every pair before any
    run)."""
    start_agent(
        strategy,
        actions,
        np.random.default_rng(0),
        False,
        0.0,
        float_feedback=float_feedback,
        notes=lambda _text: None,
        phases=lambda _phase: None,
    )


def stop_text(step: int, budget: int | None) -> str:
    """How a run the strategy ended is told (the recording's stop event, info, the audit)."""
    of = "" if budget is None else f" of a budget of {budget:,}"
    return f"stopped by the strategy at step {step:,}{of}"


class Runner:
    """Runs a strategy in a scenario with one seeded generator per run.

    ``on_event`` receives every :class:`Event`; ``on_model_change`` receives the
    model operations applied during a step (or at reset) as soon as the step
    ends. Both are how a recorder observes the run from outside.

    ``world``: the world the agent acts in (by default the scenario's body's, made here). A
    loop that moves the world itself (a Gymnasium env) passes its world, and tells the runner
    of each move with :meth:`taken` instead of calling :meth:`step`.

    A strategy that calls :meth:`~rsstp_sim.strategies.AgentView.stop` ends the run:
    :attr:`stopped` is then its reason, :meth:`run` returns early and :meth:`step` refuses.
    """

    def __init__(
        self,
        scenario: AnyScenario,
        strategy: Strategy,
        *,
        seed: int,
        on_event: Callable[[Event], None] | None = None,
        on_model_change: Callable[[int, Sequence[Operation]], None] | None = None,
        world: World | None = None,
    ) -> None:
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise StrategyError(f"seed must be an integer >= 0, got {seed!r}")
        self.scenario = scenario
        self.strategy = strategy
        self.seed = seed
        self.world: World = make_world(scenario) if world is None else world
        self._on_event = on_event
        self._on_model_change = on_model_change
        self.reset()

    def reset(self) -> None:
        """Start over: world at the start pose, fresh model and memory, entry 0 written."""
        self.rng = np.random.default_rng(self.seed)
        pose = self.world.reset()
        self.blocked = 0
        self.no_transition = 0
        self._step = 0
        self.agent = start_agent(
            self.strategy,
            self.scenario.actions,
            self.rng,
            pose.sensation,
            pose.feedback,
            float_feedback=self.scenario.feedback_mode == "float",
            notes=self._note,
            phases=self._phase,
        )
        self.model: TransitionSystem = self.agent.model
        self.memory = self.agent.memory
        self._choose = self.strategy.choose_action
        # A strategy that keeps StrategyBase's refine does not refine: no call, and no check
        # for a re-localised state after each step.
        refine = getattr(type(self.strategy), "refine", None)
        self._refine = None if refine is StrategyBase.refine else self.strategy.refine
        if self.model.current != self.memory.last_state:
            self.memory.relocate_last(self.model.current)
        self._version = self.model.version
        self._flush_model()

    @property
    def step_index(self) -> int:
        """Steps taken since the reset."""
        return self._step

    @property
    def stopped(self) -> str | None:
        """Why the strategy ended the run (at :attr:`step_index`), or None: it has not."""
        return self.agent.stopped

    def _note(self, text: str) -> None:
        if self._on_event is not None:
            self._on_event(Event(self._step, "note", text))

    def _phase(self, phase: str) -> None:
        if self._on_event is not None:
            self._on_event(Event(self._step, "note", f"phase: {phase}", {"phase": phase}))

    def _flush_model(self) -> None:
        ops = self.model.drain_operations()
        self._version = self.model.version
        if ops and self._on_model_change is not None:
            self._on_model_change(self._step, ops)

    def step(self) -> StepOutcome:
        """One coupled step (see the module docstring)."""
        if self.agent.stopped is not None:
            raise StrategyError(
                f"strategy {self.strategy.name!r} ended the run at step {self._step} "
                f"({self.agent.stopped}): no further step"
            )
        try:
            action = self._choose(self.agent)
        except Exception as exc:  # the strategy's own code: name it, and the step
            raise self._failed("choose_action", exc) from None
        try:
            blocker = self.world.move(action)
        except ActionError as exc:
            raise StrategyError(
                f"strategy {self.strategy.name!r} at step {self._step + 1}: {exc}"
            ) from None
        return self.taken(action, blocker)

    def taken(self, action: int, blocker: Blocker | None) -> StepOutcome:
        """The rest of a step whose move the world has made (``blocker``: its answer): the
        internal transition, the memory entry, the strategy's refinement. :meth:`step` calls
        it after moving the world; a loop that moves the world itself calls it after each
        move."""
        model = self.model
        self._step += 1
        before = model.current
        successors = model.successors(before, action)
        if len(successors) == 1:
            after = successors[0]
        elif successors:
            after = successors[int(self.rng.integers(len(successors)))]
        else:
            after = before
        empty = not successors
        if after != before:
            model.current = after
        pose = self.world.current
        self.memory.append(action, after, pose.sensation, pose.feedback)
        if blocker is not None:
            self.blocked += 1
        if empty:
            self.no_transition += 1
            if self._on_event is not None:
                self._on_event(
                    Event(
                        self._step,
                        "no_transition",
                        f"no transition from state {before} by action {action}: "
                        f"the internal state stays",
                    )
                )
        now = after
        if self._refine is not None:
            try:
                self._refine(self.agent)
            except Exception as exc:  # the strategy's own code (a model operation included)
                raise self._failed("refine", exc) from None
            now = model.current
            if now != after:
                self.memory.relocate_last(now)
        if model.version != self._version:  # (a strategy might change it in choose_action)
            self._flush_model()
        return StepOutcome(self._step, action, before, now, blocker, empty, after)

    def _failed(self, method: str, exc: Exception) -> StrategyError:
        """One line for an exception out of the strategy's ``method`` at this step."""
        step = self._step + (1 if method == "choose_action" else 0)
        return StrategyError(
            f"strategy {self.strategy.name!r} failed in {method} at step {step}: "
            f"{type(exc).__name__}: {exc}"
        )

    def run(self, steps: int, *, progress: Callable[[int], None] | None = None) -> RunSummary:
        """Take ``steps`` more steps and summarise the run so far; ``progress`` is called with
        the steps done every 65,536 steps."""
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
            raise StrategyError(f"steps must be an integer >= 0, got {steps!r}")
        step, agent = self.step, self.agent
        budget = self._step + steps
        done = 0
        while done < steps and agent.stopped is None:
            block = min(1 << 16, steps - done)
            for _ in range(block):
                step()
                done += 1
                if agent.stopped is not None:
                    break
            if progress is not None:
                progress(done)
        return self.summary(budget=budget)

    def summary(self, *, budget: int | None = None) -> RunSummary:
        """The run so far; ``budget``: the steps it was given (said when the strategy
        stopped it)."""
        sensations = self.memory.sensations
        true = int(np.count_nonzero(sensations))
        seen = {False: len(sensations) - true, True: true}
        return RunSummary(
            steps=self._step,
            blocked=self.blocked,
            no_transition=self.no_transition,
            sensations={k: v for k, v in seen.items() if v},
            model_states=len(self.model),
            model_transitions=len(self.model.transitions()),
            deterministic=self.model.is_deterministic(),
            stopped=self.agent.stopped,
            budget=budget if self.agent.stopped is not None else None,
        )
