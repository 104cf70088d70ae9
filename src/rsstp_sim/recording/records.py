"""The records of a recording: plain dataclasses that mirror ``schemas/*.json`` one to one.

Each message schema (``rsstp.Scenario``, ``rsstp.Step``, ``rsstp.Model``, ``rsstp.Event``)
has a record class, and each nested object of a schema has one too. Field names, order and
types are those of the schema: JSON arrays are tuples, JSON objects whose keys are free
(``strategy.params``, an event's ``data``) are dicts of JSON values, ``null`` is ``None``.

- ``record.to_json()`` gives the JSON-ready dict (keys in schema order, arrays as lists);
- ``Record.from_json(data)`` reads one back, ignoring keys it does not know (a later 1.x may
  add fields) and refusing missing or mistyped ones with a :class:`RecordFormatError` that
  names the field path; value ranges are the schema's business
  (:func:`rsstp_sim.recording.schemas.validate`);
- :func:`encode` and :func:`decode` turn records into the bytes of an MCAP message and back
  (msgspec, the fastest: see ``bench/encoding.py``); floats are written as their shortest
  round-trip representation, so ground truth survives exactly.

The builders (:func:`scenario_record`, :func:`step_record`, :func:`model_record` and the
event helpers) make records from the simulator's live objects.

>>> record = note_event(3, "exploring joint 1")
>>> encode(record)
b'{"step":3,"kind":"note","text":"exploring joint 1","data":{}}'
>>> decode("rsstp.Event", encode(record)) == record
True
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal, Self, TypeVar

import msgspec

from rsstp_sim.errors import RecordFormatError
from rsstp_sim.transition_system import Operation

if TYPE_CHECKING:
    from rsstp_sim.coupling import Event
    from rsstp_sim.geometry import Blocker
    from rsstp_sim.scenario import Scenario
    from rsstp_sim.transition_system import TransitionSystem
    from rsstp_sim.world import Pose

__all__ = [
    "AgentRecord",
    "BlockedByRecord",
    "EventRecord",
    "FeedbackRecord",
    "MessageRecord",
    "ModelRecord",
    "ObstacleRecord",
    "OperationRecord",
    "RECORD_TYPES",
    "RecordFormatError",
    "ScenarioRecord",
    "StepRecord",
    "StrategyRecord",
    "TruthRecord",
    "blocked_by_record",
    "blocked_event",
    "contradiction_event",
    "decode",
    "encode",
    "event_record",
    "model_record",
    "no_transition_event",
    "note_event",
    "operation_events",
    "operation_record",
    "scenario_record",
    "step_record",
]

FeedbackMode = Literal["bool", "float"]
CollisionMode = Literal["swept", "endpoint"]
BlockerKind = Literal["fold", "obstacle", "links"]
OperationKind = Literal["split", "merge", "add", "delete"]
EventKind = Literal[
    "blocked", "no_transition", "split", "merge", "add", "delete", "note", "contradiction"
]
Point = tuple[float, float]


class _Record:
    """JSON conversion, shared by every record class."""

    __slots__ = ()

    def to_json(self) -> dict[str, Any]:
        """The JSON-ready dict: keys in schema order, arrays as lists, ``None`` for null.

        Exactly what the record's message bytes decode to.
        """
        result: dict[str, Any] = _DECODE_JSON(_ENCODER.encode(self))
        return result

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Self:
        """Read a record from decoded JSON; unknown keys are ignored, missing ones refused."""
        record = _convert(data, cls, getattr(cls, "schema_name", cls.__name__))
        record._check()
        return record

    def _check(self) -> None:
        """Checks beyond the field types (where the schema has them)."""


# ---------------------------------------------------------------- rsstp.Scenario


@dataclass(frozen=True, slots=True)
class ObstacleRecord(_Record):
    """A circular obstacle: ``center`` ``[x, y]`` and ``radius``, in length units."""

    center: Point
    radius: float


@dataclass(frozen=True, slots=True)
class FeedbackRecord(_Record):
    """Where the tips must be for the sensation (``points``: one ``[x, y]`` per joint).

    ``tolerance`` is relative to the total arm length; ``tolerance_abs`` is in length
    units; ``target_deg`` is the pose defining the points, or ``None`` if they were given.
    """

    mode: FeedbackMode
    tolerance: float
    tolerance_abs: float
    points: tuple[Point, ...]
    target_deg: tuple[int, ...] | None


@dataclass(frozen=True, slots=True)
class StrategyRecord(_Record):
    """The strategy's name and its parameters (JSON values)."""

    name: str
    params: dict[str, Any]


@dataclass(frozen=True, slots=True)
class ScenarioRecord(_Record):
    """``rsstp.Scenario`` on ``/rsstp/scenario``: the run's world, seed and strategy."""

    schema_name: ClassVar[str] = "rsstp.Scenario"

    name: str
    description: str
    origin: str
    sha256: str
    n_joints: int
    lengths: tuple[float, ...]
    initial_deg: tuple[int, ...]
    step_deg: int
    actions: tuple[int, ...]
    obstacles: tuple[ObstacleRecord, ...]
    feedback: FeedbackRecord
    collision: CollisionMode
    seed: int
    strategy: StrategyRecord


# -------------------------------------------------------------------- rsstp.Step


@dataclass(frozen=True, slots=True)
class AgentRecord(_Record):
    """What the agent knows after a step (``action`` and ``state_before`` None at step 0)."""

    action: int | None
    state_before: int | None
    internal_state: int
    sensation: bool
    feedback: float
    model_version: int
    no_transition: bool


@dataclass(frozen=True, slots=True)
class BlockedByRecord(_Record):
    """Why a move was blocked: ``fold`` ``[joint]``, ``obstacle`` ``[link, obstacle]``,
    ``links`` ``[link_i, link_j]``."""

    kind: BlockerKind
    indices: tuple[int, ...]


@dataclass(frozen=True, slots=True)
class TruthRecord(_Record):
    """Ground truth after a step: angles (degrees), positions and distances (length units)."""

    angles_deg: tuple[int, ...]
    joint_positions: tuple[Point, ...]
    blocked: bool
    blocked_by: BlockedByRecord | None
    distances: tuple[tuple[float, ...], ...]


@dataclass(frozen=True, slots=True)
class StepRecord(_Record):
    """``rsstp.Step`` on ``/rsstp/step``: one step (0 = the reset), agent view and truth."""

    schema_name: ClassVar[str] = "rsstp.Step"

    step: int
    agent: AgentRecord
    truth: TruthRecord


# ------------------------------------------------------------------- rsstp.Model


@dataclass(frozen=True, slots=True)
class OperationRecord(_Record):
    """One model operation, as :class:`~rsstp_sim.transition_system.Operation`."""

    kind: OperationKind
    args: tuple[int, ...]
    result: int | None
    changed: bool

    def to_operation(self) -> Operation:
        """The operation, ready for :meth:`TransitionSystem.apply`."""
        return Operation(self.kind, self.args, self.result, self.changed)


@dataclass(frozen=True, slots=True)
class ModelRecord(_Record):
    """``rsstp.Model`` on ``/rsstp/model``: the model after a change, and the operations since
    the previous model message."""

    schema_name: ClassVar[str] = "rsstp.Model"

    version: int
    step: int
    states: tuple[int, ...]
    next_id: int
    current: int
    actions: tuple[int, ...]
    transitions: tuple[tuple[int, int, int], ...]
    operations: tuple[OperationRecord, ...]
    deterministic: bool
    nondeterministic_pairs: int

    def snapshot(self) -> dict[str, object]:
        """The model in :meth:`TransitionSystem.snapshot` form (for ``from_snapshot``)."""
        return {
            "states": list(self.states),
            "next_id": self.next_id,
            "current": self.current,
            "actions": list(self.actions),
            "transitions": [list(triple) for triple in self.transitions],
        }


# ------------------------------------------------------------------- rsstp.Event


@dataclass(frozen=True, slots=True)
class EventRecord(_Record):
    """``rsstp.Event`` on ``/rsstp/event``: one line of log (``text``), ``data`` by ``kind``:

    - ``blocked``: ``{action, blocked_by: {kind, indices}}``;
    - ``no_transition``: ``{state, action}``;
    - ``split``, ``merge``, ``add``, ``delete``: ``{args, result}`` as in :class:`OperationRecord`;
    - ``note``: ``{}``;
    - ``contradiction``: ``{state, i, j, actions}``.
    """

    schema_name: ClassVar[str] = "rsstp.Event"

    step: int
    kind: EventKind
    text: str
    data: dict[str, Any]

    def _check(self) -> None:
        try:
            msgspec.convert(self.data, _EVENT_DATA[self.kind])
        except msgspec.ValidationError as exc:
            raise RecordFormatError(
                f"rsstp.Event: {_format_error(exc, '.data')} (kind {self.kind!r})"
            ) from None


MessageRecord = ScenarioRecord | StepRecord | ModelRecord | EventRecord
"""The records that are MCAP messages (one per schema)."""

RECORD_TYPES: dict[str, type[MessageRecord]] = {
    cls.schema_name: cls for cls in (ScenarioRecord, StepRecord, ModelRecord, EventRecord)
}
"""Schema name -> record class."""

_DECODERS = {name: msgspec.json.Decoder(cls) for name, cls in RECORD_TYPES.items()}


# ----------------------------------------------------------------------- bytes


def encode(record: MessageRecord) -> bytes:
    """The message bytes: compact UTF-8 JSON, keys in schema order, shortest float reprs.

    msgspec serialises the dataclass directly, without building a dict (the fastest of
    json, orjson and msgspec: ``bench/encoding.py``); the JSON equals ``record.to_json()``.
    """
    return _ENCODER.encode(record)


def decode(schema_name: str, data: bytes) -> MessageRecord:
    """Read a message's bytes as the record of ``schema_name`` (``rsstp.Step``, ...).

    Unknown keys are ignored; a missing or mistyped field raises :class:`RecordFormatError`
    naming its path. Value ranges are checked by :func:`~rsstp_sim.recording.schemas.validate`.
    """
    decoder = _DECODERS.get(schema_name)
    if decoder is None:
        raise RecordFormatError(
            f"unknown schema {schema_name!r} (known: {', '.join(RECORD_TYPES)})"
        )
    try:
        record: MessageRecord = decoder.decode(data)
    except msgspec.ValidationError as exc:
        raise RecordFormatError(f"{schema_name}: {_format_error(exc)}") from None
    except msgspec.DecodeError as exc:
        raise RecordFormatError(f"{schema_name}: invalid JSON: {exc}") from None
    record._check()
    return record


# ---------------------------------------------------------------------- builders


def scenario_record(
    scenario: Scenario, *, seed: int, strategy_name: str, strategy_params: Mapping[str, Any]
) -> ScenarioRecord:
    """The ``rsstp.Scenario`` message of a run.

    ``origin`` keeps only the base name of a scenario file (recordings must not depend on
    the directory they were made in); ``strategy_params`` must be JSON-serialisable.
    """
    try:
        params = msgspec.json.decode(_ENCODER.encode(dict(strategy_params)))
    except (TypeError, msgspec.EncodeError) as exc:
        raise RecordFormatError(
            f"rsstp.Scenario: strategy.params: expected JSON values, found "
            f"{dict(strategy_params)!r} ({exc})"
        ) from None
    target = scenario.feedback_target_deg
    return ScenarioRecord(
        name=scenario.name,
        description=scenario.description,
        origin=re.split(r"[\\/]", scenario.origin)[-1],
        sha256=scenario.sha256,
        n_joints=scenario.n_joints,
        lengths=tuple(float(v) for v in scenario.lengths),
        initial_deg=tuple(int(v) for v in scenario.initial_deg),
        step_deg=int(scenario.step_deg),
        actions=tuple(int(v) for v in scenario.actions),
        obstacles=tuple(
            ObstacleRecord((float(o.center[0]), float(o.center[1])), float(o.radius))
            for o in scenario.obstacles
        ),
        feedback=FeedbackRecord(
            mode=scenario.feedback_mode,
            tolerance=float(scenario.tolerance),
            tolerance_abs=float(scenario.tolerance * scenario.total_length),
            points=tuple((float(x), float(y)) for x, y in scenario.feedback_points),
            target_deg=None if target is None else tuple(int(v) for v in target),
        ),
        collision=scenario.collision,
        seed=int(seed),
        strategy=StrategyRecord(str(strategy_name), params),
    )


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
) -> StepRecord:
    """The ``rsstp.Step`` message of step ``step`` ending in the world pose ``pose``.

    ``action`` and ``state_before`` are None at step 0 (the reset); ``blocker`` is the
    world's answer to the move (None when the arm moved, and at step 0).
    """
    return StepRecord(
        int(step),
        AgentRecord(
            None if action is None else int(action),
            None if state_before is None else int(state_before),
            int(internal_state),
            bool(pose.sensation),
            float(pose.feedback),
            int(model_version),
            bool(no_transition),
        ),
        _truth_record(pose, blocker),
    )


@functools.lru_cache(maxsize=1 << 12)
def _truth_record(pose: Pose, blocker: Blocker | None) -> TruthRecord:
    """A pose's truth (and the move's blocker); poses are cached read-only objects, so a
    random walk revisiting them gets the same immutable record."""
    positions: list[list[float]] = pose.joint_positions.tolist()
    distances: list[list[float]] = pose.distances.tolist()
    return TruthRecord(
        tuple(int(v) for v in pose.angles_deg),
        tuple((x, y) for x, y in positions),
        blocker is not None,
        blocked_by_record(blocker),
        tuple(tuple(row) for row in distances),
    )


def blocked_by_record(blocker: Blocker | None) -> BlockedByRecord | None:
    """The record of a :class:`~rsstp_sim.geometry.Blocker` (None stays None)."""
    if blocker is None:
        return None
    return BlockedByRecord(blocker.kind, tuple(int(i) for i in blocker.indices))


def operation_record(op: Operation) -> OperationRecord:
    """The record of a model :class:`~rsstp_sim.transition_system.Operation`."""
    return OperationRecord(
        op.kind,
        tuple(int(v) for v in op.args),
        None if op.result is None else int(op.result),
        bool(op.changed),
    )


def model_record(
    model: TransitionSystem, *, step: int, operations: Iterable[Operation]
) -> ModelRecord:
    """The ``rsstp.Model`` message: ``model`` as it is at ``step``, after ``operations``."""
    transitions = tuple(model.transitions())
    pairs = 0
    run = 0
    previous: tuple[int, int] | None = None
    for s, a, _ in transitions:
        if (s, a) == previous:
            run += 1
            if run == 2:
                pairs += 1
        else:
            previous, run = (s, a), 1
    return ModelRecord(
        version=int(model.version),
        step=int(step),
        states=model.states,
        next_id=int(model.next_id),
        current=int(model.current),
        actions=model.actions,
        transitions=transitions,
        operations=tuple(operation_record(op) for op in operations),
        deterministic=pairs == 0,
        nondeterministic_pairs=pairs,
    )


def blocked_event(step: int, *, action: int, blocker: Blocker) -> EventRecord:
    """A ``blocked`` event: ``action`` did not move the arm, because of ``blocker``."""
    by = {"kind": blocker.kind, "indices": [int(i) for i in blocker.indices]}
    return EventRecord(
        int(step),
        "blocked",
        f"action {action} blocked: {blocker.describe()}",
        {"action": int(action), "blocked_by": by},
    )


def no_transition_event(step: int, *, state: int, action: int) -> EventRecord:
    """A ``no_transition`` event: the model had no transition from ``state`` by ``action``."""
    return EventRecord(
        int(step),
        "no_transition",
        f"no transition from state {state} by action {action}: the internal state stays",
        {"state": int(state), "action": int(action)},
    )


def note_event(step: int, text: str) -> EventRecord:
    """A strategy ``note`` (line breaks become spaces: an event is one line)."""
    return EventRecord(int(step), "note", _one_line(text), {})


def event_record(
    event: Event, *, state: int | None = None, action: int | None = None
) -> EventRecord:
    """The record of a :class:`~rsstp_sim.coupling.Event` from the runner's ``on_event``.

    A ``no_transition`` event needs the ``state`` that stayed and the ``action`` (the
    runner's event only says them in its text); a ``note`` needs nothing more.
    """
    if event.kind == "note":
        return note_event(event.step, event.text)
    if state is None or action is None:
        raise RecordFormatError(
            f"rsstp.Event: a {event.kind} event needs state and action, "
            f"found state={state!r}, action={action!r}"
        )
    return EventRecord(
        int(event.step),
        "no_transition",
        _one_line(event.text),
        {"state": int(state), "action": int(action)},
    )


def operation_events(step: int, operations: Iterable[Operation]) -> tuple[EventRecord, ...]:
    """One ``split``/``merge``/``add``/``delete`` event per model operation."""
    return tuple(
        EventRecord(
            int(step),
            op.kind,
            _describe_operation(op),
            {
                "args": [int(v) for v in op.args],
                "result": None if op.result is None else int(op.result),
            },
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
    return EventRecord(
        int(step),
        "contradiction",
        _one_line(line),
        {"state": int(state), "i": int(i), "j": int(j), "actions": acts},
    )


def _describe_operation(op: Operation) -> str:
    if op.kind == "split":
        return f"split state {op.args[0]}: new state {op.result}"
    if op.kind == "merge":
        return f"merge state {op.args[1]} into state {op.args[0]}"
    s, t, a = op.args
    return f"{op.kind} transition {s} -{a}-> {t}"


def _one_line(text: str) -> str:
    return " ".join(text.splitlines()) if "\n" in text or "\r" in text else text


# ------------------------------------------------------------- msgspec plumbing


_ENCODER = msgspec.json.Encoder()
_DECODE_JSON = msgspec.json.Decoder().decode
_MISSING = re.compile(r"Object missing required field `(?P<field>[^`]*)`(?: - at `\$(?P<at>.*)`)?")
_AT = re.compile(r"(?P<message>.*) - at `\$(?P<at>.*)`")


def _format_error(exc: msgspec.MsgspecError, prefix: str = "") -> str:
    """msgspec's message as ``path: problem`` (``data.blocked_by.indices[0]: expected ...``)."""
    text = str(exc)
    missing = _MISSING.fullmatch(text)
    if missing is not None:
        path = prefix + (missing["at"] or "") + "." + missing["field"]
        return f"{path.lstrip('.')}: missing"
    located = _AT.fullmatch(text)
    message, path = (located["message"], prefix + located["at"]) if located else (text, prefix)
    message = message[:1].lower() + message[1:]
    return f"{path.lstrip('.')}: {message}" if path else message


_R = TypeVar("_R")


def _convert(data: object, cls: type[_R], label: str) -> _R:
    try:
        record = msgspec.convert(data, cls)
    except msgspec.ValidationError as exc:
        raise RecordFormatError(f"{label}: {_format_error(exc)}") from None
    return record


@dataclass(frozen=True, slots=True)
class _BlockedData:
    action: int
    blocked_by: BlockedByRecord


@dataclass(frozen=True, slots=True)
class _NoTransitionData:
    state: int
    action: int


@dataclass(frozen=True, slots=True)
class _NoteData:
    pass


@dataclass(frozen=True, slots=True)
class _OperationData:
    args: tuple[int, ...]
    result: int | None


@dataclass(frozen=True, slots=True)
class _ContradictionData:
    state: int
    i: int
    j: int
    actions: tuple[int, ...]


_EVENT_DATA: dict[str, type[Any]] = {
    "blocked": _BlockedData,
    "no_transition": _NoTransitionData,
    "split": _OperationData,
    "merge": _OperationData,
    "add": _OperationData,
    "delete": _OperationData,
    "note": _NoteData,
    "contradiction": _ContradictionData,
}
