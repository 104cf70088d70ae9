"""The chain of model messages: each version must follow from the previous one.

Every ``/rsstp/model`` message carries the operations applied since the previous message. A
*keyframe* (every message of a schema 2.x file; the first one and one every so often in 3.x)
carries the whole model (a sparse snapshot) too, a *change* does not. :class:`ChainCheck`
rebuilds each version from the previous one with :meth:`TransitionSystem.apply`: a keyframe
must give its own snapshot, so a model at any step is known to be the one the run had, and a
change is the version rebuilt. Every record it hands back is whole (its ``keyframe`` says
whether the file held it whole).
"""

from __future__ import annotations

import bisect
from array import array
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, cast

import msgspec

from rsstp_format.records import ModelRecord, RecordFormatError, TransitionsRecord, encode
from rsstp_replay.errors import CorruptRecording
from rsstp_sim.errors import ModelError
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["HEADS", "ChainCheck", "ModelHead", "build_model"]


ModelHead: Any = msgspec.defstruct(
    "ModelHead",
    [(f.name, f.type) for f in msgspec.structs.fields(ModelRecord) if f.name != "transitions"],
    kw_only=True,
    gc=False,
)
"""A ``/rsstp/model`` message read without its transitions (the parser skips them): the
fields of :class:`~rsstp_format.records.ModelRecord` but those. What
:meth:`ChainCheck.head` needs to rebuild the version and write its bytes again."""


HEADS = msgspec.json.Decoder(list[ModelHead])
"""Decodes a chunk's model messages joined as one JSON array."""


def build_model(path: Path, record: ModelRecord) -> TransitionSystem:
    """The model of one message, from its snapshot (its version included)."""
    try:
        return TransitionSystem.from_snapshot(record.snapshot(), version=record.version)
    except ModelError as exc:
        raise CorruptRecording(f"{path}: {_name(record)}: invalid snapshot: {exc}") from None


class ChainCheck:
    """Check the model messages in file order, one at a time as they are decoded (call it
    with each, then :meth:`finish`); :class:`CorruptRecording` names the version. No message
    may come after ``last_step``, the recording's last step.

    The first message (a keyframe) is built; every later message's operations are applied to the
    model rebuilt so far. A change is that model, handed back whole; a keyframe's snapshot is
    compared with it field by field, so a snapshot is never built twice. The transitions are
    compared through what the operations touched: the previous snapshot, with the rows of every
    state whose transitions an operation may have changed replaced by the rebuilt model's, must
    be the message's snapshot (whole tuples compared at C speed, Python only for the touched
    rows). The record handed back then holds those patched tuples, whose ints are the previous
    record's: a run's thousands of snapshots, which repeat most of their transitions, share one
    int object per state id instead of one per transition end. A snapshot that differs (or lists
    its transitions out of order) is compared in full, which names the difference.
    """

    def __init__(self, path: Path, *, last_step: int) -> None:
        self._path, self._last_step = path, last_step
        self._previous: ModelRecord | None = None
        self._model: TransitionSystem | None = None

    def __call__(self, record: ModelRecord) -> ModelRecord:
        """Check ``record``, the next message decoded whole; the record to keep."""
        if self._previous is None:
            return self._first(record)
        touched = self._advance(record)
        if not record.keyframe:
            return self._change(record, touched)
        return self._compare(record, touched)

    def head(self, head: ModelHead, data: bytes, decode: Callable[[], ModelRecord]) -> ModelRecord:
        """Check the next message from its ``head`` (decoded without the transitions) and its
        bytes: when ``data`` is, byte for byte, the message of the version its operations
        make (as the recorder writes it), its transitions are never parsed. Otherwise the
        message is decoded whole (``decode``) and compared field by field, which names any
        difference (equal values written another way pass)."""
        previous = self._previous
        if previous is None:
            return self._first(decode())
        fields = {name: getattr(head, name) for name in head.__struct_fields__}
        if not head.keyframe:  # a change: its head is all of it
            try:
                change = ModelRecord(**fields)
                change._check()
            except RecordFormatError as exc:
                raise CorruptRecording(f"{self._path}: {_name(head)}: {exc}") from None
            return self._change(change, self._advance(change))
        touched = self._advance(head)
        model = self._model
        assert model is not None
        patched = _patched(previous.transitions, model, touched)
        expected = ModelRecord(**fields, transitions=patched.as_lists())
        if encode(expected) != data:
            return self._compare(decode(), touched, patched)
        return self._accept(msgspec.structs.replace(expected, transitions=patched), "")

    def _first(self, record: ModelRecord) -> ModelRecord:
        if not record.keyframe:
            raise CorruptRecording(
                f"{self._path}: the first model message ({_name(record)}) is a change: "
                f"expected a keyframe, the whole model"
            )
        if record.step != 0:
            raise CorruptRecording(
                f"{self._path}: the first model message is at step {record.step}, expected step 0"
            )
        self._model = model = build_model(self._path, record)
        _check_flags(self._path, record, model)
        self._previous = record
        return record

    def _advance(self, record: ModelRecord | ModelHead) -> set[int]:
        """Apply the next message's operations to the model rebuilt so far (after checking
        its step); the states whose transitions they may have changed."""
        path, previous, model = self._path, self._previous, self._model
        assert previous is not None and model is not None
        if record.step > self._last_step:
            raise CorruptRecording(
                f"{path}: {_name(record)} comes after the last step, {self._last_step:,}"
            )
        if record.step < previous.step:
            raise CorruptRecording(
                f"{path}: {_name(record)} comes after the model message of step "
                f"{previous.step}: expected the steps in order"
            )
        touched: set[int] = set()
        for k, operation in enumerate(record.operations):
            try:
                touched |= model.sources_changed_by(operation.kind, operation.args)
                model.apply(operation.to_operation())
            except ModelError as exc:
                raise CorruptRecording(
                    f"{path}: {_name(record)}: operation {k} ({operation.kind} "
                    f"{list(operation.args)}) does not apply to version {previous.version}: {exc}"
                ) from None
        model.drain_operations()
        return touched

    def _compare(
        self, record: ModelRecord, touched: set[int], patched: _Compact | None = None
    ) -> ModelRecord:
        """Compare a message decoded whole with the model its operations made."""
        previous, model = self._previous, self._model
        assert previous is not None and model is not None
        if patched is None:
            patched = _patched(previous.transitions, model, touched)
        if patched.holds(record.transitions):
            record = msgspec.structs.replace(record, transitions=patched)
            return self._accept(record, _difference(model, record))
        return self._accept(record, _difference(model, record, full=True))

    def _change(self, record: ModelRecord, touched: set[int]) -> ModelRecord:
        """A change: the version its operations made from the previous one, whole."""
        previous, model = self._previous, self._model
        assert previous is not None and model is not None
        patched = _patched(previous.transitions, model, touched)
        whole = msgspec.structs.replace(record, states=model.states, transitions=patched)
        return self._accept(whole, _difference(model, whole))

    def _accept(self, record: ModelRecord, difference: str) -> ModelRecord:
        path, previous, model = self._path, self._previous, self._model
        assert previous is not None and model is not None
        if difference:
            raise CorruptRecording(
                f"{path}: {_name(record)}: its operations applied to version "
                f"{previous.version} do not give its snapshot ({difference})"
            )
        if record.current not in model:
            raise CorruptRecording(
                f"{path}: {_name(record)}: invalid snapshot: current {record.current} is not "
                f"one of the states"
            )
        model.current = record.current
        _check_flags(path, record, model)
        self._previous = record
        return record

    def finish(self) -> None:
        """After the last message: there must have been one."""
        if self._previous is None:
            raise CorruptRecording(
                f"{self._path}: no /rsstp/model message (expected one at step 0)"
            )


def _patched(previous: TransitionsRecord, rebuilt: TransitionSystem, touched: set[int]) -> _Compact:
    """The previous snapshot's transitions with the rows of the ``touched`` states (sorted by
    source, action and target) replaced by the rebuilt model's, in compact columns."""
    source, action, target = previous.source, previous.action, previous.target
    ids = max(rebuilt.next_id, -min(rebuilt.states, default=0))
    moves = max(max(rebuilt.actions, default=0), -min(rebuilt.actions, default=0))
    columns = (_column(ids), _column(moves), _column(ids))
    done = 0
    try:
        for state in sorted(touched):
            lo = bisect.bisect_left(source, state, done)
            hi = bisect.bisect_right(source, state, lo)
            _extend(columns, source[done:lo], action[done:lo], target[done:lo])
            if state in rebuilt:
                rows = rebuilt.transitions_from(state)
                _extend(columns, (state,) * len(rows), [a for a, _ in rows], [t for _, t in rows])
            done = hi
        _extend(columns, source[done:], action[done:], target[done:])
    except OverflowError:  # an id past the model's own: the comparison names it
        return _Compact.of(array("q"), array("q"), array("q"))
    return _Compact.of(*columns)


def _extend(columns: tuple[array[int], ...], *parts: Sequence[int]) -> None:
    """Append each part to its column (an array of the column's type is copied at C
    speed; one of another type, after a version outgrew 2-byte ids, value by value)."""
    for column, part in zip(columns, parts, strict=True):
        if isinstance(part, array) and part.typecode != column.typecode:
            column.extend(part.tolist())
        else:
            column.extend(part)  # type: ignore[arg-type]


class _Compact(TransitionsRecord, frozen=True, kw_only=True, gc=False):
    """Transitions in ``array.array`` columns of the narrowest signed type that holds the
    model's ids (2 bytes each below 32,768 states, where a tuple's slot takes 8). The fields
    are declared as the record's tuples; here they hold arrays, sequences of ints too."""

    @classmethod
    def of(cls, source: array[int], action: array[int], target: array[int]) -> _Compact:
        return cls(source=cast(Any, source), action=cast(Any, action), target=cast(Any, target))

    def as_lists(self) -> TransitionsRecord:
        """The same transitions in lists (what the JSON encoder writes)."""
        source, action, target = (
            cast("array[int]", column).tolist()
            for column in (self.source, self.action, self.target)
        )
        return TransitionsRecord(
            source=cast(Any, source), action=cast(Any, action), target=cast(Any, target)
        )

    def holds(self, other: TransitionsRecord) -> bool:
        """Whether ``other`` has the same transitions in the same order."""
        for mine, theirs in (
            (self.source, other.source),
            (self.action, other.action),
            (self.target, other.target),
        ):
            assert isinstance(mine, array)
            try:
                if mine != array(mine.typecode, theirs):
                    return False
            except (OverflowError, TypeError):  # an id that does not fit: not one of ours
                return False
        return True


def _column(largest: int) -> array[int]:
    """An empty column of the narrowest signed type for ids of at most ``largest`` in
    absolute value."""
    for code in ("h", "i"):
        if largest < 1 << (8 * array(code).itemsize - 1):
            return array(code)
    return array("q")


def _difference(rebuilt: TransitionSystem, record: ModelRecord, *, full: bool = False) -> str:
    """What differs between the rebuilt model and the message's snapshot ("" for nothing);
    the transitions are compared only with ``full`` (the caller compared them already)."""
    if rebuilt.version != record.version:
        return f"they make version {rebuilt.version}"
    if rebuilt.states != tuple(record.states):
        return f"states {list(rebuilt.states)}, the snapshot has {list(record.states)}"
    if rebuilt.next_id != record.next_id:
        return f"next id {rebuilt.next_id}, the snapshot has {record.next_id}"
    if rebuilt.actions != tuple(record.actions):
        return f"actions {list(rebuilt.actions)}, the snapshot has {list(record.actions)}"
    if not full:
        return ""
    made = tuple(rebuilt.transitions())
    found = record.triples()
    if made != found and made != tuple(sorted(found)):  # the writer sorts them
        extra = sorted(set(made) - set(found))[:3]
        missing = sorted(set(found) - set(made))[:3]
        return f"transitions differ: rebuilt only {extra}, snapshot only {missing}"
    return ""


def _check_flags(path: Path, record: ModelRecord, model: TransitionSystem) -> None:
    pairs = model.nondeterministic_pairs
    if record.nondeterministic_pairs != pairs or record.deterministic != (pairs == 0):
        raise CorruptRecording(
            f"{path}: {_name(record)}: says deterministic={record.deterministic} with "
            f"{record.nondeterministic_pairs} nondeterministic pairs; its transitions have "
            f"{pairs}"
        )


def _name(record: ModelRecord | ModelHead) -> str:
    return f"model version {record.version} (step {record.step})"
