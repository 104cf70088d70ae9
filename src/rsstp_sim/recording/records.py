"""The records of a recording: msgspec structs that mirror ``schemas/*.json`` one to one.

Each message schema (``rsstp.Scenario``, ``rsstp.Step``, ``rsstp.Model``, ``rsstp.Event``)
has a record class, and each nested object of a schema has one too. Field names, order and
types are those of the schema: JSON arrays are tuples, points are :class:`PointRecord`
``{x, y}``, a model's transitions a :class:`TransitionsRecord` of three parallel arrays. A
field the schema makes optional is ``None`` in Python and left out of the JSON (schema 2.0
writes no ``null``: see ``schemas/README.md``); an event's ``data`` is a dict of the fields
its kind has.

- ``record.to_json()`` gives the JSON-ready dict (keys in schema order, arrays as lists);
- ``Record.from_json(data)`` reads one back, ignoring keys it does not know (a later 2.x may
  add fields) and refusing missing or mistyped ones with a :class:`RecordFormatError` that
  names the field path; value ranges are the schema's business
  (:func:`rsstp_sim.recording.schemas.validate`);
- :func:`encode` and :func:`decode` turn records into the bytes of an MCAP message and back
  (msgspec, the fastest: see ``bench/encoding.py``); floats are written as their shortest
  round-trip representation, so ground truth survives exactly.

:mod:`rsstp_sim.recording.builders` makes records from the simulator's live objects.

>>> record = EventRecord(step=3, kind="note", text="exploring joint 1", data={})
>>> encode(record)
b'{"step":3,"kind":"note","text":"exploring joint 1","data":{}}'
>>> decode("rsstp.Event", encode(record)) == record
True
>>> encode(AgentRecord(internal_state=0, sensation=False, feedback=0.5, model_version=0,
...                    no_transition=False))
b'{"internal_state":0,"sensation":false,"feedback":0.5,"model_version":0,"no_transition":false}'
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar, Literal, Self, TypeVar

import msgspec

from rsstp_sim.errors import RecordFormatError
from rsstp_sim.geometry import BlockerKind
from rsstp_sim.scenario import CollisionMode, FeedbackMode
from rsstp_sim.transition_system import Operation, OperationKind, snapshot_form

__all__ = [
    "AgentRecord",
    "BlockedByRecord",
    "DistancesRecord",
    "EventRecord",
    "FeedbackRecord",
    "MessageRecord",
    "ModelRecord",
    "ObstacleRecord",
    "OperationRecord",
    "ParamRecord",
    "PointRecord",
    "RECORD_TYPES",
    "RecordFormatError",
    "ScenarioRecord",
    "StepRecord",
    "StrategyRecord",
    "TransitionsRecord",
    "TruthRecord",
    "decode",
    "decode_many",
    "json_array",
    "encode",
]

EventKind = Literal[
    "blocked", "no_transition", "split", "merge", "add", "delete", "note", "contradiction"
]


class _Record(msgspec.Struct, frozen=True, omit_defaults=True, kw_only=True):
    """JSON conversion, shared by every record class."""

    def to_json(self) -> dict[str, Any]:
        """The JSON-ready dict: keys in schema order, arrays as lists, optional fields that
        are ``None`` left out.

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


# ---------------------------------------------------------------- shared shapes


class PointRecord(_Record, frozen=True, kw_only=True):
    """A point ``{x, y}`` in the world frame (length units)."""

    x: float
    y: float


# ---------------------------------------------------------------- rsstp.Scenario


class ObstacleRecord(_Record, frozen=True, kw_only=True):
    """A circular obstacle: ``center`` ``{x, y}`` and ``radius``, in length units."""

    center: PointRecord
    radius: float


class FeedbackRecord(_Record, frozen=True, kw_only=True):
    """Where the tips must be for the sensation (``points``: one ``{x, y}`` per joint).

    ``tolerance`` is relative to the total arm length; ``tolerance_abs`` is in length
    units; ``target_deg`` is the pose defining the points, or ``None`` (absent) if they were
    given.
    """

    mode: FeedbackMode
    tolerance: float
    tolerance_abs: float
    points: tuple[PointRecord, ...]
    target_deg: tuple[int, ...] | None = None


class ParamRecord(_Record, frozen=True, kw_only=True):
    """One strategy parameter: its ``name`` and its value as JSON text (``"0.1"``,
    ``"[0, 1]"``), so every parameter has the same type whatever its value."""

    name: str
    value: str


class StrategyRecord(_Record, frozen=True, kw_only=True):
    """The strategy: its name, where its class lives (``import_path``, ``package.module:Class``)
    and the distribution that provides it with that distribution's version (absent for a
    module that no installed distribution provides), and its parameters in name order."""

    name: str
    import_path: str
    distribution: str | None = None
    version: str | None = None
    params: tuple[ParamRecord, ...]

    def param_values(self) -> dict[str, Any]:
        """The parameters as the strategy took them: name -> JSON value."""
        return {p.name: _DECODE_JSON(p.value) for p in self.params}


class ScenarioRecord(_Record, frozen=True, kw_only=True):
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


class AgentRecord(_Record, frozen=True, kw_only=True):
    """What the agent knows after a step (``action`` and ``state_before`` None, absent from
    the JSON, at step 0)."""

    action: int | None = None
    state_before: int | None = None
    internal_state: int
    sensation: bool
    feedback: float
    model_version: int
    no_transition: bool


class BlockedByRecord(_Record, frozen=True, kw_only=True):
    """Why a move was blocked: ``fold`` ``[joint]``, ``obstacle`` ``[link, obstacle]``,
    ``links`` ``[link_i, link_j]``."""

    kind: BlockerKind
    indices: tuple[int, ...]


class DistancesRecord(_Record, frozen=True, kw_only=True):
    """The distances from one link tip to each obstacle's surface (length units), in
    scenario order."""

    obstacles: tuple[float, ...]


class TruthRecord(_Record, frozen=True, kw_only=True):
    """Ground truth after a step: angles (degrees), positions and distances (length units);
    ``blocked_by`` None (absent) when the arm moved."""

    angles_deg: tuple[int, ...]
    joint_positions: tuple[PointRecord, ...]
    blocked: bool
    blocked_by: BlockedByRecord | None = None
    distances: tuple[DistancesRecord, ...]


class StepRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Step`` on ``/rsstp/step``: one step (0 = the reset), agent view and truth."""

    schema_name: ClassVar[str] = "rsstp.Step"

    step: int
    agent: AgentRecord
    truth: TruthRecord


# ------------------------------------------------------------------- rsstp.Model


class TransitionsRecord(_Record, frozen=True, kw_only=True, gc=False):
    """Every transition of a model as three parallel arrays, sorted by source, action and
    target: transition ``i`` is ``source[i] -action[i]-> target[i]`` (state ids and action
    ids). Parallel arrays keep a model message as compact as a list of triples, in a shape
    every JSON-Schema viewer can address."""

    source: tuple[int, ...]
    action: tuple[int, ...]
    target: tuple[int, ...]

    def __len__(self) -> int:
        return len(self.source)

    def triples(self) -> tuple[tuple[int, int, int], ...]:
        """The ``(source, action, target)`` triples, as
        :meth:`~rsstp_sim.transition_system.TransitionSystem.transitions` gives them."""
        return tuple(zip(self.source, self.action, self.target, strict=True))

    def _check(self) -> None:
        if not len(self.source) == len(self.action) == len(self.target):
            raise RecordFormatError(
                f"transitions: source, action and target differ in length "
                f"({len(self.source)}, {len(self.action)}, {len(self.target)})"
            )


class OperationRecord(_Record, frozen=True, kw_only=True):
    """One model operation, as :class:`~rsstp_sim.transition_system.Operation` (``result``
    None, absent, for the operations that create nothing)."""

    kind: OperationKind
    args: tuple[int, ...]
    result: int | None = None
    changed: bool

    def to_operation(self) -> Operation:
        """The operation, ready for :meth:`TransitionSystem.apply`."""
        return Operation(self.kind, self.args, self.result, self.changed)


class ModelRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Model`` on ``/rsstp/model``: the model after a change, and the operations since
    the previous model message."""

    schema_name: ClassVar[str] = "rsstp.Model"

    version: int
    step: int
    states: tuple[int, ...]
    next_id: int
    current: int
    actions: tuple[int, ...]
    transitions: TransitionsRecord
    operations: tuple[OperationRecord, ...]
    deterministic: bool
    nondeterministic_pairs: int

    def triples(self) -> tuple[tuple[int, int, int], ...]:
        """The transitions as ``(source, action, target)`` triples, sorted as written."""
        return self.transitions.triples()

    def snapshot(self) -> dict[str, object]:
        """The model in :meth:`TransitionSystem.snapshot` form (for ``from_snapshot``)."""
        return snapshot_form(self.states, self.next_id, self.current, self.actions, self.triples())

    def _check(self) -> None:
        try:
            self.transitions._check()
        except RecordFormatError as exc:
            raise RecordFormatError(f"{self.schema_name}: {exc}") from None


# ------------------------------------------------------------------- rsstp.Event


class EventRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Event`` on ``/rsstp/event``: one line of log (``text``), ``data`` by ``kind``:

    - ``blocked``: ``{action, blocked_by: {kind, indices}}``;
    - ``no_transition``: ``{state, action}``;
    - ``split``, ``merge``, ``add``, ``delete``: ``{args}`` and ``result`` when the operation
      created a state, as in :class:`OperationRecord`;
    - ``note``: ``{}``, or ``{phase}`` (the strategy entered that phase), or ``{stop, budget}``
      (the strategy ended the run: its reason, and the steps it was given when known);
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
_MANY = {name: msgspec.json.Decoder(list[cls]) for name, cls in RECORD_TYPES.items()}  # type: ignore[valid-type]


# ----------------------------------------------------------------------- bytes


def encode(record: MessageRecord) -> bytes:
    """The message bytes: compact UTF-8 JSON, keys in schema order, shortest float reprs.

    msgspec serialises the struct directly, without building a dict (the fastest of
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
    except RecursionError:
        raise RecordFormatError(f"{schema_name}: nested too deeply") from None
    record._check()
    return record


def decode_many(schema_name: str, parts: Sequence[bytes | memoryview]) -> list[MessageRecord]:
    """:func:`decode` of many messages of one schema at once (one parser call for them all:
    a chunk's events, say). Raises :class:`RecordFormatError` when any of them is bad; which
    one, and why, is what :func:`decode` of each says."""
    decoder = _MANY.get(schema_name)
    if decoder is None:
        raise RecordFormatError(
            f"unknown schema {schema_name!r} (known: {', '.join(RECORD_TYPES)})"
        )
    try:
        found: list[MessageRecord] = decoder.decode(json_array(parts))
    except msgspec.DecodeError as exc:
        raise RecordFormatError(f"{schema_name}: a message of the batch: {exc}") from None
    except RecursionError:
        raise RecordFormatError(f"{schema_name}: a message of the batch nests too deeply") from None
    if len(found) != len(parts):  # a part that is several JSON values, or none
        raise RecordFormatError(f"{schema_name}: {len(parts)} messages decode as {len(found)}")
    for record in found:
        record._check()
    return found


def json_array(parts: Sequence[bytes | memoryview]) -> bytes:
    """The JSON array of ``parts`` (each the bytes of one JSON value, a message's, say), built
    with one copy of their bytes (a chunk's messages: a megabyte).

    >>> json_array([b'{"a":1}', memoryview(b"2")])
    b'[{"a":1},2]'
    """
    if len(parts) < 2:
        return b"".join((b"[", *parts, b"]"))
    return b",".join([b"[" + parts[0], *parts[1:-1], b"".join((parts[-1], b"]"))])


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


class _BlockedData(msgspec.Struct):
    action: int
    blocked_by: BlockedByRecord


class _NoTransitionData(msgspec.Struct):
    state: int
    action: int


class _NoteData(msgspec.Struct):
    phase: str | None = None
    stop: str | None = None
    budget: int | None = None


class _OperationData(msgspec.Struct):
    args: tuple[int, ...]
    result: int | None = None


class _ContradictionData(msgspec.Struct):
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
