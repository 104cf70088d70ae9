"""Building records from the simulator's live objects: the world (its scenario), a step's
outcome and pose, a model version, and the events (blocked moves, missing transitions, refinements,
contradictions, notes). :mod:`rsstp_format.records` says what the records are.

>>> note_event(3, "exploring joint 1")
EventRecord(step=3, kind='note', text='exploring joint 1', data={})
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import msgspec

from rsstp_format.records import (
    NO_TRANSITIONS,
    STEP_RECORDS,
    AgentRecord,
    EventKind,
    EventRecord,
    ModelRecord,
    ObstacleRecord,
    OperationRecord,
    ParamRecord,
    PointRecord,
    ScenarioMessage,
    StepMessage,
    StrategyRecord,
    TransitionsRecord,
    encode_json,
)
from rsstp_sim.bodies import body_named
from rsstp_sim.errors import RecordFormatError
from rsstp_sim.runner import stop_text
from rsstp_sim.transition_system import Operation

if TYPE_CHECKING:
    from rsstp_sim.interface import Blocker, Pose, World
    from rsstp_sim.runner import Event
    from rsstp_sim.strategies import StrategyOrigin
    from rsstp_sim.transition_system import TransitionSystem

__all__ = [
    "blocked_event",
    "contradiction_event",
    "event_record",
    "model_record",
    "no_transition_event",
    "note_event",
    "operation_events",
    "operation_record",
    "scenario_record",
    "step_record",
]


def scenario_record(
    world: World,
    *,
    seed: int,
    strategy_name: str,
    strategy_params: Mapping[str, Any],
    strategy_origin: StrategyOrigin,
) -> ScenarioMessage:
    """The scenario message of a run in ``world`` (``rsstp.Scenario``, a rover's
    ``rsstp.RoverScenario``): its scenario, as its body writes it.

    ``origin`` keeps only the base name of a scenario file (recordings must not depend on
    the directory they were made in); ``strategy_params`` must be JSON-serialisable, and are
    written in name order, each value as JSON text.
    """
    params: list[ParamRecord] = []
    for name, value in sorted(strategy_params.items()):
        try:
            params.append(ParamRecord(name=str(name), value=encode_json(value).decode()))
        except (TypeError, msgspec.EncodeError) as exc:
            raise RecordFormatError(
                f"rsstp.Scenario: strategy.params: expected JSON values, found "
                f"{name}={value!r} ({exc})"
            ) from None
    strategy = StrategyRecord(
        name=str(strategy_name),
        import_path=strategy_origin.import_path,
        distribution=strategy_origin.distribution,
        version=strategy_origin.version,
        params=tuple(params),
    )
    scenario = world.scenario
    common: dict[str, Any] = {
        "name": scenario.name,
        "description": scenario.description,
        "origin": re.split(r"[\\/]", scenario.origin)[-1],
        "sha256": scenario.sha256,
        "actions": tuple(int(v) for v in scenario.actions),
        "obstacles": tuple(
            ObstacleRecord(center=PointRecord.of(o.center), radius=float(o.radius))
            for o in scenario.obstacles
        ),
        "seed": int(seed),
        "strategy": strategy,
    }
    record: ScenarioMessage = body_named(scenario.body).scenario_record(scenario, common)
    return record


def step_record(
    step: int,
    pose: Pose,
    *,
    action: int | None,
    state_before: int | None,
    internal_state: int,
    model_version: int,
    no_transition: bool,
    blocker: Blocker | None,
) -> StepMessage:
    """The step message of step ``step`` ending in the world pose ``pose`` (``rsstp.Step``;
    a rover's ``rsstp.RoverStep``).

    ``action`` and ``state_before`` are None at step 0 (the reset); ``blocker`` is the
    world's answer to the move (None when the arm moved, and at step 0).
    """
    agent = AgentRecord(
        action=None if action is None else int(action),
        state_before=None if state_before is None else int(state_before),
        internal_state=int(internal_state),
        sensation=bool(pose.sensation),
        feedback=float(pose.feedback),
        model_version=int(model_version),
        no_transition=bool(no_transition),
    )
    truth = pose.truth_record(blocker)
    step_type: Any = STEP_RECORDS[type(truth)]
    record: StepMessage = step_type(step=int(step), agent=agent, truth=truth)
    return record


def operation_record(op: Operation) -> OperationRecord:
    """The record of a model :class:`~rsstp_sim.transition_system.Operation`."""
    return OperationRecord(
        kind=op.kind,
        args=tuple(int(v) for v in op.args),
        result=None if op.result is None else int(op.result),
        changed=bool(op.changed),
    )


def model_record(
    model: TransitionSystem,
    *,
    step: int,
    operations: Iterable[Operation],
    keyframe: bool = True,
) -> ModelRecord:
    """The ``rsstp.Model`` message: ``model`` as it is at ``step``, after ``operations``; a
    keyframe (the whole model) or, with ``keyframe=False``, a change (its states and
    transitions left out: the operations give them)."""
    pairs = model.nondeterministic_pairs
    states: tuple[int, ...] = ()
    transitions = NO_TRANSITIONS
    if keyframe:
        source, action, target = model.transition_columns()
        states = model.states
        transitions = TransitionsRecord(
            source=tuple(source), action=tuple(action), target=tuple(target)
        )
    return ModelRecord(
        version=int(model.version),
        step=int(step),
        states=states,
        next_id=int(model.next_id),
        current=int(model.current),
        actions=model.actions,
        transitions=transitions,
        operations=tuple(operation_record(op) for op in operations),
        deterministic=pairs == 0,
        nondeterministic_pairs=pairs,
        keyframe=keyframe,
    )


def blocked_event(step: int, *, action: int, blocker: Blocker) -> EventRecord:
    """A ``blocked`` event: ``action`` did not move the arm, because of ``blocker``."""
    by = {"kind": blocker.kind, "indices": [int(i) for i in blocker.indices]}
    return _event(
        int(step),
        "blocked",
        f"action {action} blocked: {blocker.describe()}",
        {"action": int(action), "blocked_by": by},
    )


def no_transition_event(step: int, *, state: int, action: int) -> EventRecord:
    """A ``no_transition`` event: the model had no transition from ``state`` by ``action``."""
    return _event(
        int(step),
        "no_transition",
        f"no transition from state {state} by action {action}: the internal state stays",
        {"state": int(state), "action": int(action)},
    )


def note_event(step: int, text: str, data: Mapping[str, Any] | None = None) -> EventRecord:
    """A strategy ``note`` (line breaks become spaces: an event is one line); ``data`` is
    ``{}``, ``{"phase": p}`` (the strategy entered phase ``p``) or a :func:`stop_event`'s."""
    return _event(step, "note", _one_line(text), dict(data or {}))


def stop_event(step: int, *, reason: str, budget: int | None) -> EventRecord:
    """The last event of a run the strategy ended at ``step`` (of ``budget`` steps, when the
    run had one): a note with data ``{"stop": reason, "budget": budget}``."""
    data: dict[str, Any] = {"stop": _one_line(reason)}
    if budget is not None:
        data["budget"] = int(budget)
    return note_event(step, f"{stop_text(step, budget)}: {reason}", data)


def event_record(
    event: Event, *, state: int | None = None, action: int | None = None
) -> EventRecord:
    """The record of a :class:`~rsstp_sim.runner.Event` from the runner's ``on_event``.

    A ``no_transition`` event needs the ``state`` that stayed and the ``action`` (the
    runner's event only says them in its text); a ``note`` needs nothing more.
    """
    if event.kind == "note":
        return note_event(event.step, event.text, event.data)
    if state is None or action is None:
        raise RecordFormatError(
            f"rsstp.Event: a {event.kind} event needs state and action, "
            f"found state={state!r}, action={action!r}"
        )
    return _event(
        int(event.step),
        "no_transition",
        _one_line(event.text),
        {"state": int(state), "action": int(action)},
    )


def operation_events(step: int, operations: Iterable[Operation]) -> tuple[EventRecord, ...]:
    """One ``split``/``merge``/``add``/``delete`` event per model operation."""
    return tuple(
        _event(
            step,
            op.kind,
            _describe_operation(op),
            {"args": [int(v) for v in op.args]}
            | ({} if op.result is None else {"result": int(op.result)}),
        )
        for op in operations
    )


def contradiction_event(
    step: int, *, state: int, i: int, j: int, actions: Iterable[int], text: str | None = None
) -> EventRecord:
    """A ``contradiction`` event: steps ``i < j`` in ``state`` disagree after ``actions``."""
    acts = [int(a) for a in actions]
    line = (
        text
        if text is not None
        else (
            f"state {state} is contradictory: steps {i} and {j} then actions {acts} "
            f"end in different sensations"
        )
    )
    return _event(
        int(step),
        "contradiction",
        _one_line(line),
        {"state": int(state), "i": int(i), "j": int(j), "actions": acts},
    )


def _event(step: int, kind: EventKind, text: str, data: dict[str, Any]) -> EventRecord:
    return EventRecord(step=int(step), kind=kind, text=text, data=data)


def _describe_operation(op: Operation) -> str:
    if op.kind == "split":
        return f"split state {op.args[0]}: new state {op.result}"
    if op.kind == "merge":
        return f"merge state {op.args[1]} into state {op.args[0]}"
    s, t, a = op.args
    return f"{op.kind} transition {s} -{a}-> {t}"


def _one_line(text: str) -> str:
    return " ".join(text.splitlines()) if "\n" in text or "\r" in text else text
