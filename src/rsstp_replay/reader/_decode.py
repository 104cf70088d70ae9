"""Step messages into columns: many messages per decoder call, numpy arrays preallocated.

The messages of one chunk are joined into one JSON array (one copy of their bytes) and
decoded by msgspec into typed structs (``gc=False``: no garbage-collector tracking for
millions of small objects); their fields are then copied column by column into numpy arrays
sized for the whole recording, and the structs are dropped before the next chunk. The
structs check types and ranges while decoding (integers stay integers, angles in
``0..359``, feedback in ``[0, 1]``); shapes and the rules between fields are checked on the
columns.

The fields every body's step has (the agent's, the blocker) are read here; a body's own
ground truth by its :class:`BodyReader` (:data:`BODY_READERS`: the arm's in
:mod:`~rsstp_replay.reader._arm`, the rover's in :mod:`~rsstp_replay.reader._rover`).
"""

from __future__ import annotations

import operator
import re
from typing import Annotated, Any, NamedTuple, Protocol

import msgspec
import numpy as np
import numpy.typing as npt
import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_format.records import json_array
from rsstp_format.schemas import STEP_NS
from rsstp_format.vocabulary import (
    BLOCKED_COLUMNS,
    BLOCKER_ARITY,
    BLOCKER_KINDS,
    BLOCKER_LABELS,
    BlockerKind,
)
from rsstp_replay.errors import BadStep
from rsstp_sim.bodies import registered

__all__ = [
    "BLOCKED_COLUMNS",
    "BLOCKER_KINDS",
    "BODY_READERS",
    "Agent",
    "Angle",
    "BlockedBy",
    "Closeness",
    "Count",
    "Point",
    "BodyReader",
    "LogTimes",
    "StepColumns",
    "TruthColumns",
    "blocker_label",
    "blocker_texts",
    "body_reader",
    "check_lengths",
    "describe",
]

Count = Annotated[int, msgspec.Meta(ge=0, le=2**63 - 1)]
"""A count or an id: read into int64 columns, so bounded where it is read."""
Angle = Annotated[int, msgspec.Meta(ge=0, le=359)]
Closeness = Annotated[float, msgspec.Meta(ge=0.0, le=1.0)]


class Agent(msgspec.Struct, gc=False, kw_only=True):
    """The agent's part of a step message (``rsstp.Step``'s ``agent``: every body's)."""

    action: Count | None = None  # absent at step 0
    state_before: Count | None = None
    internal_state: Count
    sensation: bool
    feedback: Closeness
    model_version: Count
    no_transition: bool


class BlockedBy(msgspec.Struct, gc=False, frozen=True):
    """What blocked a move (``truth.blocked_by``: every body's)."""

    kind: BlockerKind
    indices: Annotated[tuple[Count, ...], msgspec.Meta(min_length=1, max_length=2)]


class Point(msgspec.Struct, gc=False):
    """A point ``{x, y}``."""

    x: float
    y: float


class _AgentStep(msgspec.Struct, gc=False):
    """A step message without its ground truth (skipped by the parser, not built)."""

    step: Count
    agent: Agent


_KIND_DTYPE = pd.CategoricalDtype(list(BLOCKER_KINDS))
"""The categories of the steps table's ``blocked_kind`` column: every body's blocker kinds
(:data:`~rsstp_format.vocabulary.BLOCKER_KINDS`), in that order in every recording, so tables
of several recordings concatenate with the categorical kept."""


def blocker_label(kind: BlockerKind, indices: tuple[int, ...]) -> str:
    """A blocker as text (the viewer's label, :data:`~rsstp_format.vocabulary.BLOCKER_LABELS`):
    ``fold joint 1``, ``obstacle 1 link 2``, ``links 0 2``; a rover's ``room edge 3``,
    ``wall 0``, ``door 1``."""
    arity = BLOCKER_ARITY[kind]
    if len(indices) != arity:
        found = list(indices)
        raise BadStep(f"truth.blocked_by: a {kind} blocker has {arity} indices, found {found}")
    return BLOCKER_LABELS[kind].format(*indices)


_AGENT_DECODERS = (msgspec.json.Decoder(list[_AgentStep]), msgspec.json.Decoder(_AgentStep))
"""Many step messages of any body without their truth, and one."""

BODY_READERS: dict[str, str] = {
    "arm": "rsstp_replay.reader._arm:ARM",
    "rover": "rsstp_replay.reader._rover:ROVER",
}
"""Body name -> ``module:attribute`` of its :class:`BodyReader` (one line a body)."""


class TruthColumns(Protocol):
    """A body's part of the steps table: the ground truth's pose columns, filled batch by
    batch (the blocker fields, which every body's truth has, are :class:`StepColumns`')."""

    batch: msgspec.json.Decoder[Any]
    """Decodes many of the body's step messages (a JSON array) into structs."""
    one: msgspec.json.Decoder[Any]
    """Decodes one (to name the culprit of a batch that failed)."""

    def add(self, truths: list[Any], rows: slice, parts: list[memoryview]) -> None:
        """The truths of a batch (its ``parts``, their bytes) into ``rows``; :class:`BadStep`
        (its ``index`` in the batch) for a bad one."""

    def columns(self, part: slice, *, geometry: bool, narrow: bool = False) -> dict[str, Any]:
        """The columns of the rows ``part``: the pose's, and with ``geometry`` the numbers
        that follow from it (positions, distances); ``narrow``: integer columns may be in a
        narrower dtype than int64."""


class BodyReader(Protocol):
    """How the reader reads one body's steps (:data:`BODY_READERS`)."""

    kinds: tuple[BlockerKind, ...]
    """The body's blocker kinds: its steps table has their index columns."""

    def truth_columns(self, n_rows: int, scenario: Any, *, numbers: bool) -> TruthColumns:
        """Empty columns for ``n_rows`` steps of ``scenario``; ``numbers``: read the numbers
        that follow from a pose too (else :meth:`TruthColumns.columns` has no geometry)."""

    def pose_columns(self, scenario: Any) -> tuple[str, ...]:
        """The steps table's integer columns that say a pose."""

    def place_columns(self, scenario: Any) -> tuple[str, str]:
        """The steps table's columns that place the body in the plane (its tip, its
        centre), present with the geometry."""

    def shape_difference(self, record: Any, scenario: Any) -> str | None:
        """How the scenario message's shape (what the columns are sized by) differs from
        the attached scenario file's, as ``the message has ..., its scenario file ...``;
        None when it does not."""


def body_reader(name: str) -> BodyReader:
    """The registered reader of body ``name`` (KeyError for none)."""
    reader: BodyReader = registered(BODY_READERS, name)
    return reader


class LogTimes(NamedTuple):
    """The log times of ``n_rows`` consecutive steps from ``first_step``: each step's
    ``step * STEP_NS`` but at the rows of ``odd`` (rows, their log times)."""

    n_rows: int
    first_step: int
    odd: tuple[tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]], ...]

    def values(self) -> npt.NDArray[np.int64]:
        times = (np.arange(self.n_rows, dtype=np.int64) + self.first_step) * STEP_NS
        for rows, found in self.odd:
            times[rows] = found
        return times


class StepColumns:
    """The columns of ``n_rows`` step messages, filled batch by batch with :meth:`add`.

    With ``truth`` (a body's :class:`TruthColumns`) the ground truth is decoded too; without,
    only the agent's fields (what a memory needs).
    """

    def __init__(
        self,
        n_rows: int,
        *,
        truth: TruthColumns | None = None,
        kinds: tuple[BlockerKind, ...] = (),
        keep_steps: bool = False,
    ) -> None:
        self.n_rows = n_rows
        self.truth = truth is not None
        self._pose = truth
        self._kinds = kinds
        self.rows = 0
        # The step numbers and log times are what the rows say (``first_step + row``, times
        # STEP_NS) but where noted: nothing per row in a long run. ``keep_steps`` keeps them
        # whole (a chunk's columns, searched by step).
        self.first_step: int | None = None
        self._wrong_step: tuple[int, int] | None = None  # the first row whose step differs
        self._steps: _IntColumn | None = _IntColumn(n_rows) if keep_steps else None
        self._odd_times: list[tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]] = []
        self.action = _IntColumn(n_rows)
        self.state_before = _IntColumn(n_rows)
        self.internal_state = _IntColumn(n_rows)
        self.sensation = np.empty(n_rows, np.bool_)
        self.feedback = np.empty(n_rows, np.float64)
        self.model_version = _IntColumn(n_rows)
        self.no_transition = np.empty(n_rows, np.bool_)
        self.action_nulls: list[int] = []
        self.state_before_nulls: list[int] = []
        if truth is not None:
            self.blocked = np.empty(n_rows, np.bool_)
            self.blocker = np.full(n_rows, -1, np.int16)
            self.blocker_labels: dict[BlockedBy, int] = {}

    @property
    def step(self) -> npt.NDArray[np.int64]:
        """Each row's step number."""
        if self._steps is not None:
            return self._steps.values[: self.rows].astype(np.int64)
        steps = np.arange(self.rows, dtype=np.int64) + (self.first_step or 0)
        if self._wrong_step is not None:  # pragma: no cover - check() refuses such columns
            raise BadStep("the step numbers were not kept", step=self._wrong_step[0])
        return steps

    @property
    def log_time(self) -> npt.NDArray[np.int64]:
        """Each row's log time (ns)."""
        return self.log_times().values()

    def log_times(self) -> LogTimes:
        """The rows' log times, kept apart from these columns (a few numbers)."""
        return LogTimes(self.rows, self.first_step or 0, tuple(self._odd_times))

    # -- filling ----------------------------------------------------------------------------

    def add(self, parts: list[memoryview], log_times: npt.ArrayLike) -> None:
        """Decode a batch of step messages (their JSON bytes, and their log times) into the
        next rows."""
        if not parts:
            return
        batch, one = _AGENT_DECODERS if self._pose is None else (self._pose.batch, self._pose.one)
        try:
            rows: list[Any] = batch.decode(json_array(parts))
        except (msgspec.DecodeError, RecursionError):
            rows = []
        if len(rows) != len(parts):  # find the culprit, one message at a time
            for index, part in enumerate(parts):
                try:
                    one.decode(part)
                except msgspec.DecodeError as exc:
                    raise BadStep(describe(exc), index=index) from None
                except RecursionError:
                    raise BadStep("nested too deeply", index=index) from None
            raise BadStep("the messages do not decode one by one", index=0)
        k = len(rows)
        r = self.rows
        if r + k > self.n_rows:
            raise BadStep(f"more step messages than the {self.n_rows} counted", index=0)
        s = slice(r, r + k)
        steps = np.fromiter(map(_STEP, rows), np.int64, k)
        self._note_steps(steps, np.asarray(log_times, np.int64), r)
        agents = list(map(_AGENT, rows))
        self.action.put(s, _nullable(list(map(_ACTION, agents)), r, self.action_nulls))
        self.state_before.put(
            s, _nullable(list(map(_STATE_BEFORE, agents)), r, self.state_before_nulls)
        )
        self.internal_state.put(s, np.fromiter(map(_INTERNAL_STATE, agents), np.int64, k))
        self.sensation[s] = np.fromiter(map(_SENSATION, agents), np.bool_, k)
        self.feedback[s] = np.fromiter(map(_FEEDBACK, agents), np.float64, k)
        self.model_version.put(s, np.fromiter(map(_MODEL_VERSION, agents), np.int64, k))
        self.no_transition[s] = np.fromiter(map(_NO_TRANSITION, agents), np.bool_, k)
        if self._pose is not None:
            truths = list(map(_TRUTH, rows))
            self._pose.add(truths, s, parts)
            self._add_blockers(truths, r)
        self.rows = r + k

    def _note_steps(
        self, steps: npt.NDArray[np.int64], log_times: npt.NDArray[np.int64], r: int
    ) -> None:
        """Where the rows ``r ..`` of a batch say another step than ``first_step + row``, and
        another log time than their step's."""
        if self.first_step is None and len(steps):
            self.first_step = int(steps[0])
        rows = np.arange(r, r + len(steps), dtype=np.int64)
        if self._steps is not None:
            self._steps.put(slice(r, r + len(steps)), steps)
        wrong = np.flatnonzero(steps != rows + (self.first_step or 0))
        if len(wrong) and self._wrong_step is None:
            self._wrong_step = (r + int(wrong[0]), int(steps[wrong[0]]))
        odd = np.flatnonzero(log_times != steps * STEP_NS)
        if len(odd):
            self._odd_times.append((rows[odd], log_times[odd]))

    def _add_blockers(self, truths: list[Any], r: int) -> None:
        k = len(truths)
        s = slice(r, r + k)
        self.blocked[s] = np.array([t.blocked for t in truths], np.bool_)
        labels = self.blocker_labels
        bys = [t.blocked_by for t in truths]
        with_blocker = k - bys.count(None)
        if not with_blocker:
            return
        # The rows with a blocker are the blocked ones, unless one stands where the body
        # moved (check() then names it): then every row is looked at.
        blocked = np.flatnonzero(self.blocked[s]).tolist()
        among = sum(bys[index] is not None for index in blocked)
        for index in blocked if among == with_blocker else range(k):
            by = bys[index]
            if by is not None:
                code = labels.get(by)
                if code is None:
                    try:
                        blocker_label(by.kind, by.indices)
                    except BadStep as exc:
                        raise BadStep(exc.text, index=index) from None
                    code = labels[by] = len(labels)
                self.blocker[r + index] = code

    # -- checks and results --------------------------------------------------------------------

    def check(self, *, actions: tuple[int, ...]) -> None:
        """The rules between fields and between messages; :class:`BadStep` names the step."""
        if self.rows != self.n_rows:
            raise BadStep(f"expected {self.n_rows} step messages, found {self.rows}")
        wrong = (0, self.first_step) if self.first_step else self._wrong_step
        if wrong is not None:
            t, found = wrong
            raise BadStep(f"expected step {t} in this place, found step {found}", step=t)
        nullable = (("action", self.action_nulls), ("state_before", self.state_before_nulls))
        for name, nulls in nullable:
            if self.n_rows and nulls[:1] != [0]:
                raise BadStep(f"agent.{name}: expected none at step 0 (the reset)", step=0)
            if len(nulls) > 1:
                raise BadStep(f"agent.{name}: missing after step 0", step=nulls[1])
        action = self.action.values
        unknown = np.flatnonzero(~np.isin(action[1:], np.array(actions, np.int64)))
        if unknown.size:
            t = int(unknown[0]) + 1
            raise BadStep(
                f"agent.action {action[t]} is not one of the scenario's actions {list(actions)}",
                step=t,
            )
        if self.truth:
            mismatch = np.flatnonzero(self.blocked != (self.blocker >= 0))
            if mismatch.size:
                raise BadStep("truth.blocked and truth.blocked_by disagree", step=int(mismatch[0]))
            if self.n_rows and self.blocked[0]:
                raise BadStep("truth.blocked: expected false at step 0 (the reset)", step=0)

    def frame(
        self,
        *,
        geometry: bool = True,
        blockers: bool = True,
        copy: bool = False,
        rows: slice | None = None,
        narrow: bool = False,
    ) -> pd.DataFrame:
        """The steps table, indexed by ``step`` (see :meth:`rsstp_replay.Recording.steps` for
        the columns; :meth:`check` made the steps ``0 .. n_rows - 1``); ``geometry=False``
        leaves out the joint positions and distances, ``blockers=False`` what blocked a move
        (``blocked_kind`` and the indices; ``blocked`` stays); ``copy=True`` gives a table
        that shares no array with these columns; ``rows``: only those rows (a part of the
        table, its index the steps' numbers); ``narrow=True``: each integer column in the
        narrowest dtype that holds its values (as kept; else int64, as documented), a pose's
        too where its body keeps it narrow."""
        part = slice(0, self.n_rows) if rows is None else rows
        start, stop = part.start, part.stop
        action_mask = np.zeros(stop - start, np.bool_)
        action_mask[[t - start for t in self.action_nulls if start <= t < stop]] = True
        before_mask = np.zeros(stop - start, np.bool_)
        before_mask[[t - start for t in self.state_before_nulls if start <= t < stop]] = True
        ints = {
            name: getattr(self, name).values[part]
            for name in ("action", "state_before", "internal_state", "model_version")
        }
        if not narrow:
            ints = {name: values.astype(np.int64) for name, values in ints.items()}
        columns: dict[str, Any] = {
            "action": pd.arrays.IntegerArray(ints["action"], action_mask),
            "state_before": pd.arrays.IntegerArray(ints["state_before"], before_mask),
            "internal_state": ints["internal_state"],
            "sensation": self.sensation[part],
            "feedback": self.feedback[part],
            "model_version": ints["model_version"],
            "no_transition": self.no_transition[part],
        }
        if self._pose is not None:
            columns["blocked"] = self.blocked[part]
            if blockers:
                columns |= self._blocked_columns(part)
            columns |= self._pose.columns(part, geometry=geometry, narrow=narrow)
        return pd.DataFrame(columns, index=pd.RangeIndex(start, stop, name="step"), copy=copy)

    def _blocked_columns(self, part: slice) -> dict[str, Any]:
        """``blocked_kind`` and the index columns of :data:`BLOCKED_COLUMNS` of the rows
        ``part``, taken from the per-row blocker codes through one small table per column (no
        object per row)."""
        n_codes = len(self.blocker_labels)
        # Code -1 (not blocked) takes the last entry: no kind, every index missing.
        kinds = np.full(n_codes + 1, -1, np.int8)
        values = {
            name: np.full(n_codes + 1, -1, np.int64)
            for kind in self._kinds
            for name in BLOCKED_COLUMNS[kind]
        }
        for by, code in self.blocker_labels.items():
            kinds[code] = BLOCKER_KINDS.index(by.kind)
            for name, index in zip(BLOCKED_COLUMNS[by.kind], by.indices, strict=True):
                values[name][code] = index
        blocker = self.blocker[part]
        columns: dict[str, Any] = {
            "blocked_kind": pd.Categorical.from_codes(kinds[blocker], dtype=_KIND_DTYPE)
        }
        for name, table in values.items():
            column = table[blocker]
            columns[name] = pd.arrays.IntegerArray(column, column < 0)
        return columns


def blocker_texts(steps: pd.DataFrame, rows: npt.NDArray[np.int64]) -> npt.NDArray[np.object_]:
    """The :func:`blocker_label` of each of ``rows`` of a steps table, from its blocked
    columns (``""`` where the move was not blocked); each distinct blocker is formatted once."""
    kinds = steps["blocked_kind"].cat.codes.to_numpy()[rows].astype(np.int64)
    names = [name for names in BLOCKED_COLUMNS.values() for name in names if name in steps]
    parts = [steps[name].to_numpy(np.int64, na_value=-1)[rows] for name in names]
    keys, inverse = np.unique(np.stack([kinds, *parts], axis=1), axis=0, return_inverse=True)
    texts = []
    for key in keys.tolist():
        if key[0] < 0:
            texts.append("")
            continue
        kind = BLOCKER_KINDS[key[0]]
        indices = tuple(
            key[1 + names.index(name)] for name in BLOCKED_COLUMNS[kind]
        )  # (its body's)
        texts.append(blocker_label(kind, indices))
    return np.array(texts, object)[inverse.reshape(-1)]


_STEP = operator.attrgetter("step")
_AGENT = operator.attrgetter("agent")
_TRUTH = operator.attrgetter("truth")
_ACTION = operator.attrgetter("action")
_STATE_BEFORE = operator.attrgetter("state_before")
_INTERNAL_STATE = operator.attrgetter("internal_state")
_SENSATION = operator.attrgetter("sensation")
_FEEDBACK = operator.attrgetter("feedback")
_MODEL_VERSION = operator.attrgetter("model_version")
_NO_TRANSITION = operator.attrgetter("no_transition")

_WIDTHS = (np.int8, np.int16, np.int32, np.int64)


class _IntColumn:
    """An integer column filled batch by batch, kept in the narrowest of int8 .. int64 that
    holds every value put so far (copied into a wider one when a batch needs it): a long run's
    state ids and versions take two or four bytes a step, not eight."""

    def __init__(self, n_rows: int) -> None:
        self.values: npt.NDArray[np.signedinteger[Any]] = np.empty(n_rows, np.int8)

    def put(self, rows: slice, values: npt.ArrayLike) -> None:
        batch = np.asarray(values, np.int64)
        if len(batch):
            low, high = int(batch.min()), int(batch.max())
            limits = np.iinfo(self.values.dtype)
            if low < limits.min or high > limits.max:
                fits = (w for w in _WIDTHS if np.iinfo(w).min <= low and high <= np.iinfo(w).max)
                self.values = self.values.astype(np.result_type(next(fits), self.values.dtype))
        self.values[rows] = batch


def _nullable(values: list[int | None], first: int, nulls: list[int]) -> list[int] | Any:
    """``values`` with -1 for ``None``, noting the rows of the nulls (rare: step 0 only)."""
    if None not in values:
        return values
    nulls.extend(first + i for i, v in enumerate(values) if v is None)
    return [-1 if v is None else v for v in values]


def check_lengths(items: list[Any], expected: int, field: str, what: str) -> None:
    if set(map(len, items)) != {expected}:
        index, found = next((i, len(x)) for i, x in enumerate(items) if len(x) != expected)
        raise BadStep(f"{field}: expected {expected} {what}, found {found}", index=index)


_AT = re.compile(r"(?P<message>.*) - at `\$(?P<at>.*)`")


def describe(exc: msgspec.DecodeError) -> str:
    """msgspec's message as ``field.path: problem``."""
    text = str(exc)
    located = _AT.fullmatch(text)
    if located is None:
        return text[:1].lower() + text[1:]
    message = located["message"]
    return f"{located['at'].lstrip('.')}: {message[:1].lower()}{message[1:]}"
