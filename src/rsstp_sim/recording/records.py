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

:mod:`rsstp_sim.recording.builders` makes records from the simulator's live objects.

>>> record = EventRecord(3, "note", "exploring joint 1", {})
>>> encode(record)
b'{"step":3,"kind":"note","text":"exploring joint 1","data":{}}'
>>> decode("rsstp.Event", encode(record)) == record
True
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar, Literal, Self, TypeVar

import msgspec

from rsstp_sim.errors import RecordFormatError
from rsstp_sim.geometry import BlockerKind
from rsstp_sim.scenario import CollisionMode, FeedbackMode
from rsstp_sim.transition_system import Operation, OperationKind

if TYPE_CHECKING:
    pass

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
    "decode",
    "encode",
]

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


# ------------------------------------------------------------- msgspec plumbing


_ENCODER = msgspec.json.Encoder()
encode_json = _ENCODER.encode
"""JSON bytes of plain values (dicts, lists, numbers, text), as the records are written."""
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
