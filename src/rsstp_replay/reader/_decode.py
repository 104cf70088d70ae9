"""Step messages into columns: many messages per decoder call, numpy arrays preallocated.

The messages of one chunk are joined into one JSON array (one copy of their bytes) and
decoded by msgspec into typed structs (``gc=False``: no garbage-collector tracking for
millions of small objects); their fields are then copied column by column into numpy arrays
sized for the whole recording, and the structs are dropped before the next chunk. The
structs check types and ranges while decoding (integers stay integers, angles in
``0..359``, feedback in ``[0, 1]``); shapes and the rules between fields are checked on the
columns.

The joint positions and obstacle distances of an arm's step depend on its pose alone, and
parsing their floats is most of the cost of a step, so a batch is decoded without them, and
only the first message of each pose met is decoded whole: the table's numbers of a pose are
that message's, what the file holds. Whether they are what the scenario's geometry gives, and
the same at every visit, is the physics check's business (``rsstp-replay check --physics``),
so a recording written before a geometry fix still opens, and that check names the first
step that differs.
"""

from __future__ import annotations

import re
from itertools import chain
from typing import Annotated, Any

import msgspec
import numpy as np
import numpy.typing as npt
import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_format.records import json_array
from rsstp_format.vocabulary import BLOCKER_ARITY, BLOCKER_KINDS, BlockerKind
from rsstp_replay.errors import BadStep, ReplayError

__all__ = [
    "BLOCKED_COLUMNS",
    "ROVER_COLUMNS",
    "BLOCKER_KINDS",
    "StepColumns",
    "blocker_label",
    "blocker_texts",
]

_Count = Annotated[int, msgspec.Meta(ge=0, le=2**63 - 1)]
"""A count or an id: read into int64 columns, so bounded where it is read."""
_Angle = Annotated[int, msgspec.Meta(ge=0, le=359)]
_Closeness = Annotated[float, msgspec.Meta(ge=0.0, le=1.0)]


class _Agent(msgspec.Struct, gc=False, kw_only=True):
    action: _Count | None = None  # absent at step 0
    state_before: _Count | None = None
    internal_state: _Count
    sensation: bool
    feedback: _Closeness
    model_version: _Count
    no_transition: bool


class _BlockedBy(msgspec.Struct, gc=False, frozen=True):
    kind: BlockerKind
    indices: Annotated[tuple[_Count, ...], msgspec.Meta(min_length=1, max_length=2)]


class _Point(msgspec.Struct, gc=False):
    x: float
    y: float


class _Distances(msgspec.Struct, gc=False):
    obstacles: list[float]


class _Truth(msgspec.Struct, gc=False, kw_only=True):
    angles_deg: list[_Angle]
    joint_positions: list[_Point]
    blocked: bool
    blocked_by: _BlockedBy | None = None  # absent when the arm moved
    distances: list[_Distances]


class _Step(msgspec.Struct, gc=False):
    step: _Count
    agent: _Agent
    truth: _Truth


class _PoseTruth(msgspec.Struct, gc=False):
    """The ground truth of a step without the numbers that follow from its angles (skipped by
    the parser, not built)."""

    angles_deg: list[_Angle]
    blocked: bool
    blocked_by: _BlockedBy | None = None


class _PoseStep(msgspec.Struct, gc=False):
    step: _Count
    agent: _Agent
    truth: _PoseTruth


class _RoverTruth(msgspec.Struct, gc=False):
    """A rover's ground truth after a step (``rsstp.RoverStep``)."""

    cell: Annotated[list[_Count], msgspec.Meta(min_length=2, max_length=2)]
    heading_deg: _Angle
    position: _Point
    blocked: bool
    blocked_by: _BlockedBy | None = None


class _RoverStep(msgspec.Struct, gc=False):
    step: _Count
    agent: _Agent
    truth: _RoverTruth


class _AgentStep(msgspec.Struct, gc=False):
    """A step message without its ground truth (skipped by the parser, not built)."""

    step: _Count
    agent: _Agent


_DECODERS: dict[tuple[str, bool], tuple[msgspec.json.Decoder[Any], msgspec.json.Decoder[Any]]] = {
    ("arm", True): (msgspec.json.Decoder(list[_PoseStep]), msgspec.json.Decoder(_Step)),
    ("rover", True): (msgspec.json.Decoder(list[_RoverStep]), msgspec.json.Decoder(_RoverStep)),
}
for _body in ("arm", "rover"):
    _DECODERS[_body, False] = (
        msgspec.json.Decoder(list[_AgentStep]),
        msgspec.json.Decoder(_AgentStep),
    )
_WHOLE_STEPS = msgspec.json.Decoder(list[_Step])
"""Whole arm step messages, many in one call (the first message of each pose met)."""

# BLOCKER_KINDS (rsstp_sim.interface) are the categories of the steps table's ``blocked_kind``
# column, in that order in every recording (so tables of several recordings concatenate with
# the categorical kept).

BLOCKED_COLUMNS: dict[str, tuple[str, ...]] = {
    "fold": ("blocked_joint",),
    "obstacle": ("blocked_link", "blocked_obstacle"),
    "links": ("blocked_link_i", "blocked_link_j"),
    "room": ("blocked_edge",),
    "wall": ("blocked_wall",),
    "door": ("blocked_door",),
}
"""The steps table's index columns of each blocker kind, in the order of the step message's
``truth.blocked_by.indices``: a column holds a value exactly at the steps blocked by its kind
(nullable ``Int64``, missing elsewhere)."""

_KIND_DTYPE = pd.CategoricalDtype(list(BLOCKER_KINDS))

_BODY_KINDS: dict[str, tuple[str, ...]] = {
    "arm": ("fold", "obstacle", "links"),
    "rover": ("room", "obstacle", "wall", "door"),
}
"""The blocker kinds of each body: its steps table has their index columns."""

ROVER_COLUMNS = ("cell_x", "cell_y", "heading_deg")
"""A rover's pose in the steps table: its cell and heading (degrees), the ground truth's
``value_names``."""


def blocker_label(kind: BlockerKind, indices: tuple[int, ...]) -> str:
    """A blocker as text (the viewer's label): ``fold joint 1``, ``obstacle 1 link 2``,
    ``links 0 2``; a rover's ``room edge 3``, ``wall 0``, ``door 1``."""
    arity = BLOCKER_ARITY[kind]
    if len(indices) != arity:
        found = list(indices)
        raise BadStep(f"truth.blocked_by: a {kind} blocker has {arity} indices, found {found}")
    if kind == "fold":
        return f"fold joint {indices[0]}"
    if kind == "obstacle":
        return f"obstacle {indices[1]} link {indices[0]}"
    if kind == "links":
        return f"links {indices[0]} {indices[1]}"
    if kind == "room":
        return f"room edge {indices[0]}"
    return f"{kind} {indices[0]}"


class StepColumns:
    """The columns of ``n_rows`` step messages, filled batch by batch with :meth:`add`.

    With ``truth=False`` only the agent's fields are decoded (what a memory needs).
    """

    def __init__(
        self,
        n_rows: int,
        *,
        n_joints: int,
        n_obstacles: int,
        truth: bool = True,
        body: str = "arm",
        numbers: bool = True,
    ) -> None:
        self.body = body
        self.numbers = numbers
        self.n_rows = n_rows
        self.n_joints = n_joints
        self.n_obstacles = n_obstacles
        self.truth = truth
        self.rows = 0
        self.step = np.empty(n_rows, np.int64)
        self.log_time = np.empty(n_rows, np.int64)
        self.action = np.empty(n_rows, np.int64)
        self.state_before = np.empty(n_rows, np.int64)
        self.internal_state = np.empty(n_rows, np.int64)
        self.sensation = np.empty(n_rows, np.bool_)
        self.feedback = np.empty(n_rows, np.float64)
        self.model_version = np.empty(n_rows, np.int64)
        self.no_transition = np.empty(n_rows, np.bool_)
        self.action_nulls: list[int] = []
        self.state_before_nulls: list[int] = []
        if truth:
            self.blocked = np.empty(n_rows, np.bool_)
            self.blocker = np.full(n_rows, -1, np.int16)
            self.blocker_labels: dict[_BlockedBy, int] = {}
            # One row per column, so each DataFrame column is a contiguous array.
            self.angles_deg = np.empty((n_joints, n_rows), np.int64)
            self.rover_values = np.empty((3 if body == "rover" else 0, n_rows), np.int64)
            # An arm's pose code -> its positions (n + 1, 2) and distances (n, m), as the
            # first message at that pose holds them.
            # x0, y0, x1, y1, ... then the distances tip by tip
            self.pose_numbers: dict[int, list[float]] = {}
            self._met = np.zeros(0, np.int64)
            self._places = 360 ** np.arange(n_joints, dtype=np.int64)

    # -- filling ----------------------------------------------------------------------------

    def add(self, parts: list[memoryview], log_times: npt.ArrayLike) -> None:
        """Decode a batch of step messages (their JSON bytes, and their log times) into the
        next rows."""
        if not parts:
            return
        batch, one = _DECODERS[self.body, self.truth]
        try:
            rows: list[Any] = batch.decode(json_array(parts))
        except (msgspec.DecodeError, RecursionError):
            rows = []
        if len(rows) != len(parts):  # find the culprit, one message at a time
            for index, part in enumerate(parts):
                try:
                    one.decode(part)
                except msgspec.DecodeError as exc:
                    raise BadStep(_describe(exc), index=index) from None
                except RecursionError:
                    raise BadStep("nested too deeply", index=index) from None
            raise BadStep("the messages do not decode one by one", index=0)
        k = len(rows)
        r = self.rows
        if r + k > self.n_rows:
            raise BadStep(f"more step messages than the {self.n_rows} counted", index=0)
        s = slice(r, r + k)
        self.step[s] = [x.step for x in rows]
        self.log_time[s] = log_times
        agents = [x.agent for x in rows]
        self.action[s] = _nullable([a.action for a in agents], r, self.action_nulls)
        self.state_before[s] = _nullable(
            [a.state_before for a in agents], r, self.state_before_nulls
        )
        self.internal_state[s] = [a.internal_state for a in agents]
        self.sensation[s] = np.array([a.sensation for a in agents], np.bool_)
        self.feedback[s] = [a.feedback for a in agents]
        self.model_version[s] = [a.model_version for a in agents]
        self.no_transition[s] = np.array([a.no_transition for a in agents], np.bool_)
        if self.truth:
            self._add_truth([x.truth for x in rows], r, parts)
        self.rows = r + k

    def _read_numbers(self, parts: list[memoryview], angles: npt.NDArray[np.int64]) -> None:
        """The positions and distances of every pose of this batch not met before, from its
        first message here (see the module docstring): those messages decoded whole, in one
        call."""
        codes = angles @ self._places
        met = self._met  # the codes of the poses read so far, sorted
        if len(met):
            at = np.minimum(np.searchsorted(met, codes), len(met) - 1)
            unmet = np.flatnonzero(met[at] != codes)
            if not len(unmet):
                return
        else:
            unmet = np.arange(len(codes))
        fresh, first = np.unique(codes[unmet], return_index=True)
        self._met = np.insert(met, np.searchsorted(met, fresh), fresh)
        indices = unmet[first].tolist()
        new = fresh.tolist()
        try:
            truths = [
                step.truth for step in _WHOLE_STEPS.decode(json_array([parts[i] for i in indices]))
            ]
        except msgspec.DecodeError:
            truths = []
            for index in indices:  # which one, and why
                try:
                    truths.append(_DECODERS["arm", True][1].decode(parts[index]).truth)
                except msgspec.DecodeError as exc:
                    raise BadStep(_describe(exc), index=index) from None
        n, m = self.n_joints, self.n_obstacles
        known = self.pose_numbers
        for code, index, truth in zip(new, indices, truths, strict=True):
            if len(truth.joint_positions) != n + 1:
                found = len(truth.joint_positions)
                raise BadStep(
                    f"truth.joint_positions: expected {n + 1} points, found {found}", index=index
                )
            rows = [tip.obstacles for tip in truth.distances]
            if len(rows) != n:
                raise BadStep(
                    f"truth.distances: expected {n} entries (one per tip), found {len(rows)}",
                    index=index,
                )
            if any(len(row) != m for row in rows):
                raise BadStep(f"truth.distances: expected {m} obstacles per tip", index=index)
            numbers = [v for p in truth.joint_positions for v in (p.x, p.y)]
            for row in rows:
                numbers += row
            known[code] = numbers

    def _add_rover_truth(self, truths: list[_RoverTruth], s: slice) -> None:
        """A rover's cell and heading; its position must be its cell's centre."""
        k = s.stop - s.start
        cells = np.fromiter(chain.from_iterable(t.cell for t in truths), np.int64, 2 * k)
        self.rover_values[:2, s] = cells.reshape(k, 2).T
        self.rover_values[2, s] = [t.heading_deg for t in truths]
        found = np.array([(t.position.x, t.position.y) for t in truths], np.float64)
        wrong = np.flatnonzero((found != cells.reshape(k, 2) + 0.5).any(axis=1))
        if wrong.size:
            index = int(wrong[0])
            raise BadStep(
                f"truth.position {found[index].tolist()} is not the centre of its cell "
                f"{cells.reshape(k, 2)[index].tolist()}",
                index=index,
            )

    def _add_truth(self, truths: list[Any], r: int, parts: list[memoryview]) -> None:
        k = len(truths)
        n = self.n_joints
        s = slice(r, r + k)
        if self.body == "rover":
            self._add_rover_truth(truths, s)
        else:
            angles = [t.angles_deg for t in truths]
            _check_lengths(angles, n, "truth.angles_deg", "angles")
            flat = np.fromiter(chain.from_iterable(angles), np.int64, k * n)
            self.angles_deg[:, s] = flat.reshape(k, n).T
            if self.numbers:
                self._read_numbers(parts, flat.reshape(k, n))
        self.blocked[s] = np.array([t.blocked for t in truths], np.bool_)
        labels = self.blocker_labels
        bys = [t.blocked_by for t in truths]
        with_blocker = k - bys.count(None)
        if not with_blocker:
            return
        # The rows with a blocker are the blocked ones, unless one stands where the arm moved
        # (check() then names it): then every row is looked at.
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
        steps = self.step
        bad = np.flatnonzero(steps != np.arange(self.n_rows))
        if bad.size:
            t = int(bad[0])
            raise BadStep(f"expected step {t} in this place, found step {steps[t]}", step=t)
        nullable = (("action", self.action_nulls), ("state_before", self.state_before_nulls))
        for name, nulls in nullable:
            if self.n_rows and nulls[:1] != [0]:
                raise BadStep(f"agent.{name}: expected none at step 0 (the reset)", step=0)
            if len(nulls) > 1:
                raise BadStep(f"agent.{name}: missing after step 0", step=nulls[1])
        unknown = np.flatnonzero(~np.isin(self.action[1:], np.array(actions, np.int64)))
        if unknown.size:
            t = int(unknown[0]) + 1
            raise BadStep(
                f"agent.action {self.action[t]} is not one of the scenario's actions "
                f"{list(actions)}",
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
    ) -> pd.DataFrame:
        """The steps table, indexed by ``step`` (see :meth:`rsstp_replay.Recording.steps` for
        the columns; :meth:`check` made the steps ``0 .. n_rows - 1``); ``geometry=False``
        leaves out the joint positions and distances, ``blockers=False`` what blocked a move
        (``blocked_kind`` and the indices; ``blocked`` stays); ``copy=True`` gives a table
        that shares no array with these columns; ``rows``: only those rows (a part of the
        table, its index the steps' numbers)."""
        part = slice(0, self.n_rows) if rows is None else rows
        start, stop = part.start, part.stop
        action_mask = np.zeros(stop - start, np.bool_)
        action_mask[[t - start for t in self.action_nulls if start <= t < stop]] = True
        before_mask = np.zeros(stop - start, np.bool_)
        before_mask[[t - start for t in self.state_before_nulls if start <= t < stop]] = True
        columns: dict[str, Any] = {
            "action": pd.arrays.IntegerArray(self.action[part], action_mask),
            "state_before": pd.arrays.IntegerArray(self.state_before[part], before_mask),
            "internal_state": self.internal_state[part],
            "sensation": self.sensation[part],
            "feedback": self.feedback[part],
            "model_version": self.model_version[part],
            "no_transition": self.no_transition[part],
        }
        if self.truth:
            columns["blocked"] = self.blocked[part]
            if blockers:
                columns |= self._blocked_columns(part)
            for j in range(self.n_joints):
                columns[f"angle_deg_{j}"] = self.angles_deg[j, part]
            for name, values in zip(ROVER_COLUMNS, self.rover_values, strict=False):
                columns[name] = values[part]
        if self.truth and geometry and self.body == "rover":
            columns["x"] = self.rover_values[0, part] + 0.5
            columns["y"] = self.rover_values[1, part] + 0.5
        elif self.truth and geometry:
            if not self.numbers:
                raise ReplayError("the joint positions were not read (numbers=False)")
            columns |= self._geometry_columns(part)
        return pd.DataFrame(columns, index=pd.RangeIndex(start, stop, name="step"), copy=copy)

    def _geometry_columns(self, part: slice) -> dict[str, npt.NDArray[np.float64]]:
        """``joint{k}_x``, ``joint{k}_y`` and ``dist_{k}_{j}`` of the rows ``part``: each
        distinct pose's numbers as the file holds them (found by its code,
        ``sum_j angle_j * 360**j``), each column taken whole from those."""
        index, codes = pd.factorize(self._places @ self.angles_deg[:, part])
        n, m = self.n_joints, self.n_obstacles
        known = self.pose_numbers
        numbers = np.array([known[code] for code in np.asarray(codes).tolist()], np.float64)
        numbers = numbers.reshape(len(codes), 2 * (n + 1) + n * m)
        positions = numbers[:, : 2 * (n + 1)].reshape(len(codes), n + 1, 2)
        distances = numbers[:, 2 * (n + 1) :].reshape(len(codes), n, m)
        columns = {}
        for k in range(n + 1):
            columns[f"joint{k}_x"] = positions[:, k, 0].take(index)
            columns[f"joint{k}_y"] = positions[:, k, 1].take(index)
        for k in range(n):
            for j in range(m):
                columns[f"dist_{k}_{j}"] = distances[:, k, j].take(index)
        return columns

    def _blocked_columns(self, part: slice) -> dict[str, Any]:
        """``blocked_kind`` and the index columns of :data:`BLOCKED_COLUMNS` of the rows
        ``part``, taken from the per-row blocker codes through one small table per column (no
        object per row)."""
        n_codes = len(self.blocker_labels)
        # Code -1 (not blocked) takes the last entry: no kind, every index missing.
        kinds = np.full(n_codes + 1, -1, np.int8)
        values = {
            name: np.full(n_codes + 1, -1, np.int64)
            for kind in _BODY_KINDS[self.body]
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


def _nullable(values: list[int | None], first: int, nulls: list[int]) -> list[int] | Any:
    """``values`` with -1 for ``None``, noting the rows of the nulls (rare: step 0 only)."""
    if None not in values:
        return values
    nulls.extend(first + i for i, v in enumerate(values) if v is None)
    return [-1 if v is None else v for v in values]


def _check_lengths(items: list[Any], expected: int, field: str, what: str) -> None:
    if set(map(len, items)) != {expected}:
        index, found = next((i, len(x)) for i, x in enumerate(items) if len(x) != expected)
        raise BadStep(f"{field}: expected {expected} {what}, found {found}", index=index)


_AT = re.compile(r"(?P<message>.*) - at `\$(?P<at>.*)`")


def _describe(exc: msgspec.DecodeError) -> str:
    """msgspec's message as ``field.path: problem``."""
    text = str(exc)
    located = _AT.fullmatch(text)
    if located is None:
        return text[:1].lower() + text[1:]
    message = located["message"]
    return f"{located['at'].lstrip('.')}: {message[:1].lower()}{message[1:]}"
