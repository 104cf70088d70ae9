"""Building records from the simulator's live objects: the scenario, a step's outcome and
pose, a model version, and the events (blocked moves, missing transitions, refinements,
contradictions, notes). :mod:`rsstp_format.records` says what the records are.

>>> note_event(3, "exploring joint 1")
EventRecord(step=3, kind='note', text='exploring joint 1', data={})
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

import msgspec

from rsstp_format.records import (
    AgentRecord,
    BlockedByRecord,
    DistancesRecord,
    DoorRecord,
    EventKind,
    EventRecord,
    FeedbackRecord,
    ModelRecord,
    ObstacleRecord,
    OperationRecord,
    ParamRecord,
    PointRecord,
    RegionRecord,
    RoverRecord,
    RoverScenarioRecord,
    RoverStepRecord,
    RoverTruthRecord,
    ScenarioRecord,
    SegmentRecord,
    StepRecord,
    StrategyRecord,
    TransitionsRecord,
    TruthRecord,
    encode_json,
)
from rsstp_sim.coupling import stop_text
from rsstp_sim.errors import RecordFormatError
from rsstp_sim.rover import RoverBlocker, RoverPose, RoverScenario
from rsstp_sim.transition_system import Operation

if TYPE_CHECKING:
    from rsstp_sim.coupling import Event
    from rsstp_sim.geometry import Blocker
    from rsstp_sim.scenario import AnyScenario
    from rsstp_sim.strategies import StrategyOrigin
    from rsstp_sim.transition_system import TransitionSystem
    from rsstp_sim.world import Pose

__all__ = [
    "blocked_by_record",
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
    "truth_record",
]


def scenario_record(
    scenario: AnyScenario,
    *,
    seed: int,
    strategy_name: str,
    strategy_params: Mapping[str, Any],
    strategy_origin: StrategyOrigin,
) -> ScenarioRecord | RoverScenarioRecord:
    """The scenario message of a run (``rsstp.Scenario``, a rover's ``rsstp.RoverScenario``).

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
    common: dict[str, Any] = {
        "name": scenario.name,
        "description": scenario.description,
        "origin": re.split(r"[\\/]", scenario.origin)[-1],
        "sha256": scenario.sha256,
        "actions": tuple(int(v) for v in scenario.actions),
        "obstacles": tuple(
            ObstacleRecord(center=_point(o.center), radius=float(o.radius))
            for o in scenario.obstacles
        ),
        "seed": int(seed),
        "strategy": strategy,
    }
    if isinstance(scenario, RoverScenario):
        return _rover_scenario_record(scenario, common)
    target = scenario.feedback_target_deg
    return ScenarioRecord(
        n_joints=scenario.n_joints,
        lengths=tuple(float(v) for v in scenario.lengths),
        initial_deg=tuple(int(v) for v in scenario.initial_deg),
        step_deg=int(scenario.step_deg),
        feedback=FeedbackRecord(
            mode=scenario.feedback_mode,
            tolerance=float(scenario.tolerance),
            tolerance_abs=float(scenario.tolerance * scenario.total_length),
            points=tuple(_point(xy) for xy in scenario.feedback_points),
            target_deg=None if target is None else tuple(int(v) for v in target),
        ),
        collision=scenario.collision,
        **common,
    )


def _rover_scenario_record(scenario: RoverScenario, common: dict[str, Any]) -> RoverScenarioRecord:
    heading = scenario.feedback_heading
    return RoverScenarioRecord(
        rover=RoverRecord(
            room=scenario.room,
            start=scenario.start,
            heading_deg=scenario.start_heading * scenario.turn_deg,
            turn_deg=scenario.turn_deg,
            radius=float(scenario.robot_radius),
            walls=tuple(
                SegmentRecord(start=_point(w.start), end=_point(w.end)) for w in scenario.walls
            ),
            doors=tuple(
                DoorRecord(start=_point(d.start), end=_point(d.end), toward=_point(d.toward))
                for d in scenario.doors
            ),
        ),
        feedback=RegionRecord(
            mode=scenario.feedback_mode,
            center=_point(scenario.feedback_center),
            radius=float(scenario.feedback_radius),
            heading_deg=None if heading is None else heading * scenario.turn_deg,
        ),
        **common,
    )


def _point(xy: Any) -> PointRecord:
    return PointRecord(x=float(xy[0]), y=float(xy[1]))


def step_record(
    step: int,
    pose: Pose | RoverPose,
    *,
    action: int | None,
    state_before: int | None,
    internal_state: int,
    model_version: int,
    no_transition: bool,
    blocker: Blocker | RoverBlocker | None,
) -> StepRecord | RoverStepRecord:
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
    if isinstance(pose, RoverPose):
        assert blocker is None or isinstance(blocker, RoverBlocker)
        truth = rover_truth_record(pose, blocker)
        return RoverStepRecord(step=int(step), agent=agent, truth=truth)
    assert not isinstance(blocker, RoverBlocker)  # (an arm's pose: an arm's blocker)
    return StepRecord(step=int(step), agent=agent, truth=truth_record(pose, blocker))


@functools.lru_cache(maxsize=1 << 12)
def truth_record(pose: Pose, blocker: Blocker | None) -> TruthRecord:
    """The truth record of a step ending in ``pose`` after a move that ``blocker`` blocked
    (None: it moved). Poses are cached read-only objects, so a random walk revisiting them
    gets the same immutable record."""
    angles, points, distances = pose.truth_values()
    m = len(distances) // len(angles)
    return TruthRecord(
        angles_deg=tuple(angles),
        joint_positions=tuple(
            [PointRecord(x=x, y=y) for x, y in zip(points[0::2], points[1::2], strict=True)]
        ),
        blocked=blocker is not None,
        blocked_by=blocked_by_record(blocker),
        distances=tuple(
            [
                DistancesRecord(obstacles=tuple(distances[k * m : (k + 1) * m]))
                for k in range(len(angles))
            ]
        ),
    )


def rover_truth_record(pose: RoverPose, blocker: RoverBlocker | None) -> RoverTruthRecord:
    """The truth record of a rover's step ending in ``pose`` (``blocker``: None when it
    moved)."""
    return RoverTruthRecord(
        cell=pose.cell,
        heading_deg=pose.heading_deg,
        position=_point(pose.position),
        blocked=blocker is not None,
        blocked_by=blocked_by_record(blocker),
    )


def blocked_by_record(blocker: Blocker | RoverBlocker | None) -> BlockedByRecord | None:
    """The record of a :class:`~rsstp_sim.geometry.Blocker` (None stays None)."""
    if blocker is None:
        return None
    return BlockedByRecord(kind=blocker.kind, indices=tuple(int(i) for i in blocker.indices))


def operation_record(op: Operation) -> OperationRecord:
    """The record of a model :class:`~rsstp_sim.transition_system.Operation`."""
    return OperationRecord(
        kind=op.kind,
        args=tuple(int(v) for v in op.args),
        result=None if op.result is None else int(op.result),
        changed=bool(op.changed),
    )


def model_record(
    model: TransitionSystem, *, step: int, operations: Iterable[Operation]
) -> ModelRecord:
    """The ``rsstp.Model`` message: ``model`` as it is at ``step``, after ``operations``."""
    source, action, target = model.transition_columns()
    pairs = model.nondeterministic_pairs
    return ModelRecord(
        version=int(model.version),
        step=int(step),
        states=model.states,
        next_id=int(model.next_id),
        current=int(model.current),
        actions=model.actions,
        transitions=TransitionsRecord(
            source=tuple(source), action=tuple(action), target=tuple(target)
        ),
        operations=tuple(operation_record(op) for op in operations),
        deterministic=pairs == 0,
        nondeterministic_pairs=pairs,
    )


def blocked_event(step: int, *, action: int, blocker: Blocker | RoverBlocker) -> EventRecord:
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
    """The record of a :class:`~rsstp_sim.coupling.Event` from the runner's ``on_event``.

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
