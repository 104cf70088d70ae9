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
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, cast, overload

import msgspec
import numpy as np
import numpy.typing as npt

from rsstp_format.records import ModelRecord, RecordFormatError, TransitionsRecord, encode
from rsstp_replay.errors import CorruptRecording
from rsstp_replay.reader._chunks import gc_paused
from rsstp_replay.reader._replay import KeyedVersion, KeyLayout
from rsstp_sim.errors import ModelError
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.words import counted

__all__ = [
    "HEADS",
    "ChainCheck",
    "DeterminismPart",
    "ModelHead",
    "ModelHistory",
    "build_model",
    "model_history",
    "version_alive",
    "version_heads",
    "version_sizes",
    "version_state_ids",
]


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

DeterminismPart = tuple[list[tuple[int, int, tuple[int, ...]]], list[tuple[int, int]]]
"""A state's pairs with several successors and with none
(:meth:`TransitionSystem.determinism_of`)."""


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
    model rebuilt so far. A change is that model; a keyframe's snapshot must be it: when the
    message's bytes are those of the rebuilt model's keyframe (as the recorder writes them), its
    transitions are never parsed, else it is compared field by field, which names the
    difference. Each checked version goes to :attr:`history`, which keeps the changes and a
    whole model now and then, not every version whole.
    """

    def __init__(self, path: Path, *, last_step: int) -> None:
        self._path, self._last_step = path, last_step
        self._previous: ModelRecord | ModelHead | None = None
        self._model: TransitionSystem | None = None
        self._columns: _Compact | None = None  # the last keyframe's transitions
        self._touched: set[int] = set()  # the states whose rows changed since
        self._record_touched: set[int] = set()  # ... by the last message's operations
        self.history = ModelHistory()

    def __call__(self, record: ModelRecord) -> None:
        """Check ``record``, the next message decoded whole."""
        if self._previous is None:
            self._first(record)
            return
        self._advance(record)
        if not record.keyframe:
            self._accept(record, compare=False)
            return
        patched = self._patch()
        if patched.holds(record.transitions):
            self._accept(record, compare=False, columns=patched)
        else:
            self._accept(record, compare=True)

    def head(self, head: ModelHead, data: bytes, decode: Callable[[], ModelRecord]) -> None:
        """Check the next message from its ``head`` (decoded without the transitions) and its
        bytes: when ``data`` is, byte for byte, the message of the version its operations
        make (as the recorder writes it), its transitions are never parsed. Otherwise the
        message is decoded whole (``decode``) and compared field by field, which names any
        difference (equal values written another way pass)."""
        if self._previous is None:
            self._first(decode())
            return
        fields = {name: getattr(head, name) for name in head.__struct_fields__}
        if not head.keyframe:  # a change: its head is all of it
            try:
                change = ModelRecord(**fields)
                change._check()
            except RecordFormatError as exc:
                raise CorruptRecording(f"{self._path}: {_name(head)}: {exc}") from None
            self._advance(change)
            self._accept(change, compare=False)
            return
        self._advance(head)
        patched = self._patch()
        expected = ModelRecord(**fields, transitions=patched.as_lists())
        if encode(expected) != data:
            record = decode()
            if patched.holds(record.transitions):
                self._accept(record, compare=False, columns=patched)
            else:
                self._accept(record, compare=True)
            return
        self._accept(expected, compare=False, columns=patched)

    def _first(self, record: ModelRecord) -> None:
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
        self._columns = _patched(record.transitions, model, set())
        self.history.add(record, model, columns=self._columns)

    def _advance(self, record: ModelRecord | ModelHead) -> None:
        """Apply the next message's operations to the model rebuilt so far (after checking
        its step)."""
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
        self._touched |= touched
        self._record_touched = touched

    def _patch(self) -> _Compact:
        """The rebuilt model's transitions, from the last keyframe's with the touched rows
        replaced (C speed but for those rows); they become the last keyframe's."""
        model, columns = self._model, self._columns
        assert model is not None and columns is not None
        patched = _patched(columns, model, self._touched)
        self._touched = set()
        return patched

    def _accept(
        self, record: ModelRecord, *, compare: bool, columns: _Compact | None = None
    ) -> None:
        """Check ``record`` against the model its operations made (its whole snapshot too,
        with ``compare``: a keyframe whose transitions were not the rebuilt model's, whose
        difference is then named). ``columns``: its transitions, compact, when known."""
        path, previous, model = self._path, self._previous, self._model
        assert previous is not None and model is not None
        difference = _difference(model, record, full=compare)
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
        if columns is not None:
            self._columns = columns
        self.history.add(record, model, columns=columns, touched=self._record_touched)

    def finish(self) -> ModelHistory:
        """After the last message: there must have been one. The versions checked."""
        if self._previous is None:
            raise CorruptRecording(
                f"{self._path}: no /rsstp/model message (expected one at step 0)"
            )
        return self.history


CHECKPOINT_SHARE = 32
"""A :class:`ModelHistory` keeps a whole model once the operations since the last one reach
a 32nd of the model's size (states and transitions): rebuilding a version applies at most
that many operations (about 750 at 4,841 states and 19,364 transitions), and the whole models
kept hold about 32 values per operation (6 bytes per transition and 8 per state below 32,768
states: 150 to 200 bytes per operation, about what the operations themselves take)."""


class ModelHistory(Sequence[ModelRecord]):
    """A recording's model versions, kept as their changes.

    Indexing gives a version whole (states and transitions, in tuples as a decoded message
    has them; its ``keyframe`` says whether the file held it whole), rebuilt from the nearest
    whole model kept before it by applying the operations since; :meth:`model` gives it as a
    model, the operations applied to sorted arrays (:mod:`~rsstp_replay.reader._replay`).
    ``share``: a whole model is kept once the operations since the last reach ``1/share`` of
    the model's size (:data:`CHECKPOINT_SHARE`); it is the last one kept with the rows of the
    states the operations since touched replaced, when :meth:`add` is told them. Walking
    forward reuses the version rebuilt last, so each version costs its own operations and
    the copy of its transitions. What the audits read of every version needs no rebuilding:
    :attr:`heads` (each message as the file holds a change, no states or transitions; the
    first one whole), :meth:`sizes`, :meth:`alive` and :meth:`determinism_changes` (kept as
    each version is added, from the model its operations made). Memory follows the
    operations, not the versions times the model's size.
    """

    def __init__(self, *, share: int = CHECKPOINT_SHARE) -> None:
        self._share = share
        self._heads: list[ModelRecord] = []
        self._n_states = array("q")
        self._n_transitions = array("q")
        self._born: dict[int, int] = {}
        self._merged: dict[int, int] = {}
        self._kept: list[int] = []
        self._whole: list[ModelRecord] = []
        self._since = 0
        self._touched: set[int] | None = set()  # the states whose rows changed since (None:
        # not known)
        self._id_bound = 0  # above every state id of every version
        self._action_bound = 0  # above every action
        self._cache: tuple[int, TransitionSystem] | None = None
        self._keyed: tuple[int, KeyedVersion] | None = None
        self._determinism: list[dict[int, DeterminismPart | None]] = []
        self._actions: tuple[int, ...] = ()
        self._with_pairs: set[int] = set()  # the states whose last listed part has pairs

    def add(
        self,
        record: ModelRecord | ModelHead,
        model: TransitionSystem,
        *,
        columns: TransitionsRecord | None = None,
        touched: set[int] | None = None,
    ) -> None:
        """The next version: its message (checked), the model it gives (rebuilt) and, when
        known, that model's transitions (compact columns) and the states whose transitions
        out its operations changed (:meth:`TransitionSystem.sources_changed_by`)."""
        k = len(self._heads)
        self._since += len(record.operations)
        if touched is None or self._touched is None:
            self._touched = None
        else:
            self._touched |= touched
        self._id_bound = max(self._id_bound, record.next_id)
        self._action_bound = max(self._action_bound, max(record.actions, default=-1) + 1)
        size = len(model) + model.n_transitions
        if k == 0 or self._since * self._share >= size:
            if columns is None and k > 0 and self._touched is not None:
                columns = self._patched(model, self._touched)
            self._kept.append(k)
            self._whole.append(_whole(record, model, columns=columns))
            self._since = 0
            self._touched = set()
        if k == 0:
            self._heads.append(self._whole[0])
            self._born.update(dict.fromkeys(model.states, 0))
        else:
            self._heads.append(_light(record))
        for operation in record.operations:
            if operation.kind == "split" and isinstance(operation.result, int):
                self._born[operation.result] = k
            elif operation.kind == "merge":
                self._merged[operation.args[1]] = k
        self._n_states.append(len(model))
        self._n_transitions.append(model.n_transitions)
        if touched is None or k == 0 or model.actions != self._actions:
            # Every state (a new action: each one's empty pairs change), and the states listed
            # with pairs before, so that one merged away in the same version is cleared.
            touched = set(model.states) | (touched or set()) | self._with_pairs
        self._actions = model.actions
        parts: dict[int, DeterminismPart | None] = {}
        for state in touched:
            part = model.determinism_of(state) if state in model else None
            if part is not None and (part[0] or part[1]):
                parts[state] = part
                self._with_pairs.add(state)
            else:
                parts[state] = None
                self._with_pairs.discard(state)
        self._determinism.append(parts)

    def __len__(self) -> int:
        return len(self._heads)

    @overload
    def __getitem__(self, index: int) -> ModelRecord: ...
    @overload
    def __getitem__(self, index: slice) -> list[ModelRecord]: ...
    def __getitem__(self, index: int | slice) -> ModelRecord | list[ModelRecord]:
        picked = range(len(self._heads))[index]  # (out of range: the IndexError iteration ends on)
        if isinstance(picked, range):
            return [self._rebuilt(k) for k in picked]
        return self._rebuilt(picked)

    @property
    def heads(self) -> Sequence[ModelRecord]:
        """Every message as a change (operations, step, version, current, flags; no states or
        transitions), but the first, whole."""
        return self._heads

    def state_ids(self) -> list[int]:
        """Every state id any version has, sorted."""
        return sorted(self._born)

    def sizes(self) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """Each version's number of states and of transitions."""
        return (
            np.frombuffer(self._n_states, np.int64).copy(),
            np.frombuffer(self._n_transitions, np.int64).copy(),
        )

    def alive(self, index: npt.ArrayLike, states: npt.ArrayLike) -> npt.NDArray[np.bool_]:
        """Whether ``states[i]`` is a state of the version at ``index[i]``, element-wise (a
        state comes with the first version or a split, and leaves with a merge)."""
        at = np.asarray(index, np.int64)
        ids = np.asarray(states, np.int64)
        n = len(self._heads)
        width = max(max(self._born, default=0), int(ids.max(initial=0))) + 1
        born = np.full(width, n, np.int64)
        born[np.fromiter(self._born, np.int64)] = np.fromiter(self._born.values(), np.int64)
        gone = np.full(width, n, np.int64)
        if self._merged:
            merged = np.fromiter(self._merged, np.int64)
            gone[merged] = np.fromiter(self._merged.values(), np.int64)
        inside = (ids >= 0) & (at >= 0)
        safe = np.where(inside, ids, 0)
        return inside & (born[safe] <= at) & (at < gone[safe])

    def determinism_changes(self, index: int) -> Mapping[int, DeterminismPart | None]:
        """The states whose part of the determinism report (their pairs with several
        successors and with none: :meth:`TransitionSystem.determinism_of`) version ``index``
        may have changed, each with its part, None when it has neither kind of pair or is
        gone; every state of the first version, and of a version whose actions grew."""
        return self._determinism[index]

    def model(self, index: int) -> TransitionSystem:
        """Version ``index`` (0 .. len - 1) as a model of its own (the caller's to change):
        the operations since the nearest whole model kept applied to arrays, one model made
        at the end (from the model rebuilt last, copied, when the ids are too wide for the
        arrays' keys). The garbage collector is paused meanwhile: the model is tens of
        thousands of acyclic dicts and tuples, and each collection would walk every object
        the reader holds."""
        k = range(len(self._heads))[index]
        with gc_paused():
            keyed = self._keyed_version(k)
            if keyed is None:
                return self._rebuilt_model(k).copy()
            head = self._heads[k]
            return keyed.model(
                actions=head.actions,
                next_id=head.next_id,
                current=head.current,
                version=head.version,
            )

    def arrays(self, index: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
        """Version ``index``'s state ids, sorted, and its transitions as rows ``(source,
        action, target)``, sorted: the operations since the nearest whole model kept applied
        to arrays, as :meth:`model` applies them, without a model made (a model, when the ids
        are too wide for the keys). Walking forward reuses the version reached last."""
        k = range(len(self._heads))[index]
        keyed = self._keyed_version(k)
        if keyed is not None:
            return keyed.arrays()
        model = self._rebuilt_model(k)
        rows = np.asarray(model.transitions(), np.int64).reshape(-1, 3)
        return np.asarray(model.states, np.int64), rows

    def _keyed_version(self, k: int) -> KeyedVersion | None:
        """Version ``k``'s transitions as sorted keys, from the last whole model kept at or
        before it (or from the version rebuilt so last, when that lies between); None when
        the keys would not fit in 63 bits."""
        layout = KeyLayout.fitting(id_bound=self._id_bound, action_bound=self._action_bound)
        if layout is None:
            return None
        slot = bisect.bisect_right(self._kept, k) - 1
        kept = self._kept[slot]
        cache = self._keyed
        if cache is not None and kept <= cache[0] <= k and cache[1].layout == layout:
            done, keyed = cache
        else:
            whole = self._whole[slot]
            transitions = whole.transitions
            keys = layout.keys(transitions.source, transitions.action, transitions.target)
            states = np.asarray(whole.states, np.int64)
            keyed = KeyedVersion(layout, states, keys, whole.next_id)
            done = kept
        for later in self._heads[done + 1 : k + 1]:
            keyed.apply(later.operations)
        self._keyed = (k, keyed)
        return keyed

    def _patched(self, model: TransitionSystem, touched: set[int]) -> _Compact | None:
        """``model``'s transitions from the last whole model kept, the rows of the
        ``touched`` states replaced (None when that does not give them all)."""
        patched = _patched(self._whole[-1].transitions, model, touched)
        return patched if len(patched.source) == model.n_transitions else None

    def _rebuilt(self, k: int) -> ModelRecord:
        """Version ``k`` whole."""
        slot = bisect.bisect_right(self._kept, k) - 1
        head = self._heads[k]
        if self._kept[slot] == k:
            whole = self._whole[slot]
            columns = (tuple(whole.transitions.source), tuple(whole.transitions.action),
                       tuple(whole.transitions.target))  # fmt: skip
            return msgspec.structs.replace(
                whole, keyframe=head.keyframe, transitions=TransitionsRecord(
                    source=columns[0], action=columns[1], target=columns[2]
                ),
            )  # fmt: skip
        model = self._rebuilt_model(k)
        return msgspec.structs.replace(_whole(head, model, compact=False), keyframe=head.keyframe)

    def _rebuilt_model(self, k: int) -> TransitionSystem:
        """Version ``k``'s model, rebuilt from the last whole model kept at or before it (or
        from the model rebuilt last, when that lies between): the history's own, cached."""
        slot = bisect.bisect_right(self._kept, k) - 1
        kept = self._kept[slot]
        cache = self._cache
        if cache is not None and kept <= cache[0] <= k:
            done, model = cache
        else:
            whole = self._whole[slot]
            transitions = whole.transitions
            model = TransitionSystem.from_columns(
                whole.states,
                whole.actions,
                (transitions.source, transitions.action, transitions.target),
                next_id=whole.next_id,
                current=whole.current,
                version=whole.version,
            )
            done = kept
        for later in self._heads[done + 1 : k + 1]:
            for operation in later.operations:
                model.apply(operation.to_operation())
        model.drain_operations()
        model.current = self._heads[k].current
        self._cache = (k, model)
        return model


def model_history(versions: Sequence[ModelRecord]) -> ModelHistory:
    """``versions`` as a :class:`ModelHistory`: itself (a recording's, checked as it was
    read), or model messages given in a plain sequence (the first whole, each later one's
    operations applying to the one before, as a recorder makes them) rebuilt one after the
    other, each checked against its message's version and states (:class:`ModelError`)."""
    if isinstance(versions, ModelHistory):
        return versions
    history = ModelHistory()
    model: TransitionSystem | None = None
    for record in versions:
        if model is None:
            model = TransitionSystem.from_snapshot(record.snapshot(), version=record.version)
            history.add(record, model)
        else:
            history.add(record, model, touched=_advance(model, record))
    return history


def _advance(model: TransitionSystem, record: ModelRecord) -> set[int]:
    """Apply ``record``'s operations to ``model`` (the previous version) and check the result
    against the record (version and states; :class:`ModelError` names the version); the
    states whose transitions out the operations may have changed."""
    where = f"model version {record.version} (step {record.step})"
    changed: set[int] = set()
    for operation in record.operations:
        try:
            changed |= model.sources_changed_by(operation.kind, operation.args)
            model.apply(operation.to_operation())
        except ModelError as exc:
            raise ModelError(f"{where}: its operations do not apply: {exc}") from None
    model.drain_operations()
    if model.version != record.version:
        raise ModelError(
            f"{where}: its operations lead from the previous version to version "
            f"{model.version}, not {record.version}"
        )
    if record.states and model.states != record.states:  # (a change's message has none)
        raise ModelError(
            f"{where}: its operations give states {_short(model.states)}, the message says "
            f"{_short(record.states)}"
        )
    model.current = record.current
    return changed


def _short(states: Sequence[int]) -> str:
    return str(list(states)) if len(states) <= 20 else counted(len(states), "state")


def version_heads(versions: Sequence[ModelRecord]) -> Sequence[ModelRecord]:
    """What to walk to read every version's message without rebuilding each: a
    :class:`ModelHistory`'s :attr:`~ModelHistory.heads`, else the records themselves."""
    return versions.heads if isinstance(versions, ModelHistory) else versions


def version_sizes(
    versions: Sequence[ModelRecord],
) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Each version's number of states and of transitions."""
    if isinstance(versions, ModelHistory):
        return versions.sizes()
    n = len(versions)
    return (
        np.fromiter((len(r.states) for r in versions), np.int64, n),
        np.fromiter((len(r.transitions) for r in versions), np.int64, n),
    )


def version_state_ids(versions: Sequence[ModelRecord]) -> list[int]:
    """Every state id any of ``versions`` has, sorted."""
    if isinstance(versions, ModelHistory):
        return versions.state_ids()
    every: set[int] = set()
    for record in versions:  # a set's update is C's loop
        every.update(record.states)
    return sorted(every)


def version_alive(
    versions: Sequence[ModelRecord], index: npt.ArrayLike, states: npt.ArrayLike
) -> npt.NDArray[np.bool_]:
    """Whether ``states[i]`` is a state of ``versions[index[i]]``, element-wise (False for a
    negative index or state)."""
    if isinstance(versions, ModelHistory):
        return versions.alive(index, states)
    at = np.asarray(index, np.int64)
    ids = np.asarray(states, np.int64)
    sizes = np.fromiter((len(record.states) for record in versions), np.int64, len(versions))
    members = np.fromiter(
        (s for record in versions for s in record.states), np.int64, int(sizes.sum())
    )
    base = int(max(members.max(initial=0), ids.max(initial=0))) + 1
    keys = np.sort(np.repeat(np.arange(len(versions), dtype=np.int64), sizes) * base + members)
    wanted = np.maximum(at, 0) * base + ids
    where = np.minimum(np.searchsorted(keys, wanted), max(len(keys) - 1, 0))
    return (at >= 0) & (ids >= 0) & (keys[where] == wanted) if len(keys) else at < -1


def _whole(
    record: ModelRecord | ModelHead,
    model: TransitionSystem,
    *,
    compact: bool = True,
    columns: TransitionsRecord | None = None,
) -> ModelRecord:
    """``record`` (a message, or its head) with the states and transitions of ``model``:
    the transitions in compact columns to keep (``columns``, when known), in tuples
    (``compact=False``) to hand out, as a decoded message has them."""
    fields = {name: getattr(record, name) for name in ModelHead.__struct_fields__}
    fields["states"] = model.states
    if compact and columns is not None:
        return ModelRecord(**fields, transitions=columns)
    source, action, target = model.transition_columns()
    if not compact:
        columns = TransitionsRecord(
            source=tuple(source), action=tuple(action), target=tuple(target)
        )
        return ModelRecord(**fields, transitions=columns)
    moves = max(max(model.actions, default=0), -min(model.actions, default=0))
    compacted = (_column(model.next_id), _column(moves), _column(model.next_id))
    _extend(compacted, source, action, target)
    return ModelRecord(**fields, transitions=_Compact.of(*compacted))


def _light(record: ModelRecord | ModelHead) -> ModelRecord:
    """``record`` without its states and transitions (its ``keyframe`` as in the file)."""
    fields = {name: getattr(record, name) for name in ModelHead.__struct_fields__}
    fields["states"] = ()
    return ModelRecord(**fields)


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
    if record.keyframe and rebuilt.states != tuple(record.states):  # (a change has none)
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
