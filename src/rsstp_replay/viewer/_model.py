"""The internal model drawn on the world: every state where the arm was while the agent was
in it, its transitions as arrows coloured by action, the current state highlighted.

Placement: a state sits at the mean position of the arm's tip over the steps at which it was
the current state in the last model version that was in it (its latest meaning seen: before a
split the same id stood for more), whatever range is shown; so a model that learned the world
looks like the arm's workspace, and a state id (never reused) never moves. A state that was
never current sits beside the state it was split from (states of the initial model that were
never current: at the base).
A state current at several distinct poses over those steps (aliasing, or a true class of
several poses) gets a thin line to the tip of each, the :data:`POSE_LINES` most visited.

Logging: one entity per state, ``world/model/state/{id}``, with a row only at the steps where
that state appears, its transitions change (found by replaying each version's operations
and marking the states they touch) or its role changes, and an :class:`rr.Clear` when it is
deleted; so the data grows with the number of changes, not with versions times model size. At
a row:

- ``Points2D``: the state, coloured by its role in the last version that was in it (what the
  truth audit says it stood for over that version's steps:
  :mod:`rsstp_replay.audits.state_roles`, colours :data:`ROLE_COLORS`; unvisited until a
  version was in it; dark grey without the truth), labelled with its id where the label fits
  (:func:`labelled_states`; the id is in the entity path, shown on hover, everywhere);
- ``Arrows2D``: one arrow per transition to another state, from the state towards the
  target (stopping short of it), coloured by action (:data:`ACTION_COLORS`), several actions
  to the same target side by side; and one short stub arrow per self-loop ``s -a-> s`` (a
  move the model says leaves the state: what a blocked move is), from the state in the
  direction of its action's colour wheel slot (:data:`LOOP_LENGTH`);
- ``LineStrips2D``, once with the state's first row: the thin lines to its poses.

One entity path per state: the web viewer's work grows with the paths (a thousand states on
three paths each took it most of a minute).

The current state is ``world/model/current``: a ring at its place, with a row at each step at
which it changes, labelled ``now: {id}`` through a static annotation context (a class id per
state). ``world/model/legend`` names the role colours (static, in a corner).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import chain

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_format.records import ModelRecord
from rsstp_replay.audits.contract import version_index
from rsstp_replay.audits.state_roles import (
    ALIASED,
    EXACT,
    REDUNDANT,
    ROLE_NAMES,
    UNVISITED,
    state_roles,
)
from rsstp_replay.reader import version_heads, version_state_ids
from rsstp_replay.viewer._chunks import TIMELINE, send_rows
from rsstp_sim import palette
from rsstp_sim.arrays import distinct
from rsstp_sim.transition_system import TransitionSystem

__all__ = [
    "ACTION_COLORS",
    "CURRENT",
    "LABEL_ROOM",
    "LEGEND",
    "LOOP_LENGTH",
    "MODEL",
    "POSE_LINES",
    "ROLE_COLORS",
    "STATES",
    "StatePlaces",
    "Roles",
    "labelled_states",
    "log_current_state",
    "log_legend",
    "log_model",
    "roles_by_version",
    "state_rows",
    "state_path",
    "state_places",
]

MODEL = "world/model"
STATES = "world/model/state"
CURRENT = "world/model/current"
LEGEND = "world/model/legend"
POSE_LINES = 32
"""Thin lines drawn from a state to at most this many of its poses (the most visited)."""

ACTION_COLORS: tuple[tuple[int, int, int], ...] = (
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
    (57, 59, 121),
    (173, 73, 74),
    (99, 121, 57),
    (140, 109, 49),
)
"""Action ``a``'s colour is ``ACTION_COLORS[a % 14]`` (matplotlib's tab10, then more)."""

ROLE_COLORS: dict[int, tuple[int, int, int]] = {
    EXACT: palette.STATE_EXACT,
    REDUNDANT: palette.STATE_REDUNDANT,
    ALIASED: palette.STATE_ALIASED,
    UNVISITED: palette.STATE_UNVISITED,
}
"""A state's colour by its role (:mod:`rsstp_replay.audits.state_roles`)."""
LABEL_ROOM = 0.09
"""A state's label is drawn when no other state lies within this fraction of the arm's reach
across, or half of it up and down (about a label's size in the default view)."""

Roles = dict[int, dict[int, int]]
"""Per model version number, the role of every state the version was in at a step (the
others are unvisited)."""

_CURRENT_COLOR = (235, 100, 0)
_POSE_COLOR = (150, 150, 150, 110)
_MAX_CLASS_ID = 1 << 16
"""Rerun's class ids are 16-bit: larger state ids are labelled by strings."""
_Floats = npt.NDArray[np.float64]


def state_path(state: int) -> str:
    return f"{STATES}/{state}"


@dataclass(frozen=True, slots=True)
class StatePlaces:
    """Where each state is drawn (world coordinates), its poses' tips and the drawing scale."""

    places: dict[int, tuple[float, float]]
    poses: dict[int, _Floats]
    scale: float


def state_places(
    steps: pd.DataFrame,
    versions: Sequence[ModelRecord],
    *,
    columns: tuple[str, str],
    pose_columns: Sequence[str],
    reach: float,
) -> StatePlaces:
    """The place of every state of every version (see the module docstring): the mean of the
    steps table's ``columns`` (an arm's last tip, a rover's position) while it was current;
    ``pose_columns`` (integers) tell its poses apart; ``reach`` (the arm's length) sets the
    offsets."""
    tips = steps[list(columns)].to_numpy(np.float64)
    states = steps["internal_state"].to_numpy(np.int64)
    # A state means what the last version that was in it says: its steps in that version
    # place it (the same id stood for more before a split; the last version it belongs to
    # may have been in force for a few steps, and its earlier steps would draw a learned
    # state of a long run at the mean of everything it once stood for).
    in_force = version_index(versions, steps.index.to_numpy(np.int64))
    ids, where = np.unique(states, return_inverse=True)
    # Versions only grow with the steps: a state's latest is the one at its last step.
    by_state = np.argsort(where, kind="stable")
    ends = np.r_[np.flatnonzero(np.diff(where[by_state])), len(by_state) - 1]
    latest = in_force[by_state[ends]] if len(states) else np.empty(0, np.int64)
    chosen = in_force == latest[where]
    kept_states, kept_tips = states[chosen], tips[chosen]
    sums = np.zeros((len(ids), 2))
    where = np.searchsorted(ids, kept_states)
    np.add.at(sums, where, kept_tips)
    counts = np.bincount(where, minlength=len(ids))
    places = {
        int(s): (float(x), float(y))
        for s, (x, y) in zip(ids.tolist(), (sums / counts[:, None]).tolist(), strict=True)
    }
    scale = reach / 40.0
    for record in version_heads(versions):  # states never current: beside their origin
        for operation in record.operations:
            if operation.kind == "split" and operation.result is not None:
                child = int(operation.result)
                if child not in places:
                    x, y = places.get(int(operation.args[0]), (0.0, 0.0))
                    angle = 2.399963 * child  # golden angle: neighbours do not pile up
                    places[child] = (
                        x + 3 * scale * math.cos(angle),
                        y + 3 * scale * math.sin(angle),
                    )
    for state in set(version_state_ids(versions)) - places.keys():
        places[int(state)] = (0.0, 0.0)
    poses = steps[list(pose_columns)].to_numpy(np.int64)[chosen]
    return StatePlaces(places, _poses(kept_states, poses, kept_tips), scale)


def roles_by_version(
    step_versions: npt.NDArray[np.int64],
    step_states: npt.NDArray[np.int64],
    step_classes: npt.NDArray[np.int64],
) -> Roles:
    """The role of every (version, state) pair seen at a step, by version."""
    if not len(step_states):
        return {}
    width = int(step_states.max()) + 1
    pairs = distinct(step_versions * width + step_states)
    versions, states = pairs // width, pairs % width
    roles = state_roles(step_versions, step_states, step_classes, versions=versions, states=states)
    found: Roles = {}
    for version, state, role in zip(
        versions.tolist(), states.tolist(), roles.tolist(), strict=True
    ):
        found.setdefault(version, {})[state] = role
    return found


def labelled_states(places: dict[int, tuple[float, float]], *, room: float) -> set[int]:
    """The states whose label fits: no other state within ``room`` across and ``room / 2``
    up and down (places are fixed, so one answer holds for every version)."""
    ids = np.array(sorted(places), np.int64)
    if len(ids) < 2:
        return set(ids.tolist())
    xy = np.array([places[s] for s in ids.tolist()], np.float64)
    fits = np.ones(len(ids), np.bool_)
    for begin in range(0, len(ids), 1024):  # blocks: memory stays at 1,024 x N
        block = xy[begin : begin + 1024, None, :] - xy[None, :, :]
        near = (np.abs(block[..., 0]) < room) & (np.abs(block[..., 1]) < room / 2)
        fits[begin : begin + 1024] = near.sum(axis=1) == 1  # itself only
    return set(ids[fits].tolist())


def _poses(
    states: npt.NDArray[np.int64], values: npt.NDArray[np.int64], tips: _Floats
) -> dict[int, _Floats]:
    """For every state seen at several poses (told apart by ``values``, non-negative integers
    a pose), the tips of its :data:`POSE_LINES` most visited poses."""
    if not len(states):
        return {}
    radix = values.max(axis=0) + 1
    place = np.concatenate([[1], np.cumprod(radix[:-1])]).astype(np.int64)
    codes = np.unique(values @ place, return_inverse=True)[1]
    ids, inverse = np.unique(states, return_inverse=True)
    n_codes = int(codes.max(initial=0)) + 1
    pairs, first, seen = np.unique(
        inverse.astype(np.int64) * n_codes + codes, return_index=True, return_counts=True
    )
    owner = pairs // n_codes
    order = np.lexsort((-seen, owner))  # by state, the most visited pose first
    owner, first = owner[order], first[order]
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    sizes = np.diff(np.r_[starts, len(owner)])
    poses: dict[int, _Floats] = {}
    for start, size in zip(starts.tolist(), sizes.tolist(), strict=True):
        if size > 1:
            poses[int(ids[owner[start]])] = tips[first[start : start + min(size, POSE_LINES)]]
    return poses


def _touched(model: TransitionSystem, record: ModelRecord) -> set[int]:
    """Apply ``record``'s operations to ``model``; the states whose transitions out changed,
    or that appeared or disappeared."""
    touched: set[int] = set()
    for operation in record.operations:
        if not operation.changed:
            continue
        args = [int(a) for a in operation.args]
        if operation.kind in ("add", "delete"):
            touched.add(args[0])
        elif operation.kind == "split":
            s = args[0]
            touched |= {s, *model.predecessors(s)}
        elif operation.kind == "merge":
            s, t = args[:2]
            touched |= {s, t, *model.predecessors(t)}
        model.apply(operation.to_operation())
        if operation.kind == "split" and operation.result is not None:
            touched.add(int(operation.result))
    model.drain_operations()
    return touched


_Row = tuple[int, tuple[tuple[int, int], ...] | None, int | None]
"""A state's row: the step, its transitions out (None: deleted), its role (None: unknown)."""


def log_model(
    stream: rr.RecordingStream,
    versions: Sequence[ModelRecord],
    steps: Sequence[int],
    places: StatePlaces,
    *,
    roles: Roles | None = None,
    labelled: set[int] | None = None,
) -> dict[str, int]:
    """Every state of ``versions[0]`` at ``steps[0]``, then each later version's changes (and
    role changes, with ``roles``: a state keeps the role of the last version that was in it,
    unvisited until one was) at its step, an entity per state; labels on the ``labelled``
    states (default: all). Returns rows per entity path (the per-state paths summed under
    :data:`STATES`). (A large model is :mod:`~rsstp_replay.viewer._large`'s.)"""
    rows = state_rows(versions, steps, roles=roles, arrows=True)
    count = 0
    ids = np.array(sorted(places.places), np.int64)
    xy = np.array([places.places[s] for s in ids.tolist()], np.float64).reshape(-1, 2)
    for state, changes in sorted(rows.items()):
        count += _log_state(
            stream,
            state,
            changes,
            places,
            (ids, xy),
            labelled=labelled is None or state in labelled,
        )
    return {STATES: count}


def state_rows(
    versions: Sequence[ModelRecord],
    steps: Sequence[int],
    *,
    roles: Roles | None,
    arrows: bool,
) -> dict[int, list[_Row]]:
    """Each state's rows: at ``steps[0]`` every state of ``versions[0]``, then at each later
    version's step the states whose transitions out changed (with ``arrows``; else only those
    that appeared or went), whose role changed, and a row with no transitions (None) where one
    was deleted."""
    rows: dict[int, list[_Row]] = defaultdict(list)
    model = TransitionSystem.from_snapshot(versions[0].snapshot(), version=versions[0].version)
    # A state's role is what it stood for in the last version that was in it: a version of a
    # few hundred steps visits few of a thousand states, and "unvisited" in each would make
    # every state flicker (a row each time) without telling anything new.
    known: dict[int, int] = {} if roles is None else dict(roles.get(versions[0].version, {}))
    for state in model.states:
        rows[state].append((steps[0], _outs(model, state), _role(roles, known, state)))
    for record, step in zip(versions[1:], steps[1:], strict=True):
        touched = _touched(model, record)
        if not arrows:  # a state's transitions are not drawn: only its coming and going
            touched = {s for s in touched if s not in model or s not in rows}
        candidates = touched
        if roles is not None:  # and the states whose role changed
            seen = roles.get(record.version, {})
            changed = {s for s, role in seen.items() if known.get(s, UNVISITED) != role}
            known.update(seen)
            candidates = touched | changed
        for state in sorted(candidates):
            if state in model:
                # A state whose role alone changed keeps its transitions: the last row's.
                outs = _outs(model, state) if state in touched else rows[state][-1][1]
                rows[state].append((step, outs, _role(roles, known, state)))
            elif state in touched:
                rows[state].append((step, None, None))
    return rows


def _role(roles: Roles | None, known: dict[int, int], state: int) -> int | None:
    return None if roles is None else known.get(state, UNVISITED)


def log_legend(
    stream: rr.RecordingStream, *, reach: float, center: tuple[float, float] = (0.0, 0.0)
) -> None:
    """The role colours named, as static points in the top left corner of a view of half-side
    ``reach`` around ``center`` (world coordinates, y up)."""
    order = (EXACT, REDUNDANT, ALIASED, UNVISITED)
    cx, cy = center
    stream.log(
        LEGEND,
        rr.Points2D(
            [(cx - 0.92 * reach, cy + (0.92 - 0.12 * k) * reach) for k in range(len(order))],
            colors=[ROLE_COLORS[r] for r in order],
            labels=[f"{ROLE_NAMES[r]} state" for r in order],
            radii=rr.Radius.ui_points(5.0),
            draw_order=30.0,
        ),
        static=True,
    )


def _outs(model: TransitionSystem, state: int) -> tuple[tuple[int, int], ...]:
    """``(action, target)`` of every transition out of ``state``, sorted."""
    return tuple(model.transitions_from(state))


def _log_state(
    stream: rr.RecordingStream,
    state: int,
    changes: list[_Row],
    places: StatePlaces,
    place_table: tuple[npt.NDArray[np.int64], _Floats],
    *,
    labelled: bool,
) -> int:
    """The rows of one state's entity, a clear where it was deleted; ``place_table`` is
    every state id, sorted, and its place."""
    path = state_path(state)
    x, y = places.places[state]
    alive = [(step, outs, role) for step, outs, role in changes if outs is not None]
    if alive:
        times = np.array([step for step, _, _ in alive], np.int64)
        state_colors = np.array(
            [palette.STATE if role is None else ROLE_COLORS[role] for _, _, role in alive],
            np.uint8,
        )
        drawn = _drawn_transitions(state, [outs for _, outs, _ in alive], places, place_table)
        index = [rr.TimeColumn(TIMELINE, sequence=times)]
        stream.send_columns(
            path,
            indexes=index,
            columns=[
                *rr.Points2D.columns(
                    positions=np.tile([x, y], (len(times), 1)),
                    colors=state_colors,
                    labels=[str(state)] * len(times) if labelled else None,
                ),
                *rr.Arrows2D.columns(
                    origins=drawn.origins, vectors=drawn.vectors, colors=drawn.colors
                ).partition(drawn.counts),
            ],
        )
        poses = places.poses.get(state)
        if poses is not None:  # in the state's entity too, once: a path less per state
            strips = np.stack([np.broadcast_to([x, y], poses.shape), poses], axis=1)
            stream.send_columns(
                path,
                indexes=[rr.TimeColumn(TIMELINE, sequence=times[:1])],
                columns=rr.LineStrips2D.columns(
                    strips=strips,
                    colors=np.tile(_POSE_COLOR, (len(strips), 1)).astype(np.uint8),
                    radii=np.full(len(strips), -0.5, np.float32),  # ui points
                ).partition([len(strips)]),
            )
    for step, gone, _ in changes:
        if gone is None:
            stream.set_time(TIMELINE, sequence=step)
            stream.log(path, rr.Clear(recursive=True))
    return len(changes)


@dataclass(frozen=True, slots=True)
class _Drawn:
    """The arrows of a state's rows, flat: each one's origin, vector and colour, and how
    many belong to each row."""

    origins: _Floats
    vectors: _Floats
    colors: npt.NDArray[np.uint8]
    counts: npt.NDArray[np.int64]


LOOP_LENGTH = 1.5
"""A self-loop's stub arrow, in units of the drawing scale (a fortieth of the arm's reach)."""


def _drawn_transitions(
    state: int,
    rows: list[tuple[tuple[int, int], ...]],
    places: StatePlaces,
    place_table: tuple[npt.NDArray[np.int64], _Floats],
) -> _Drawn:
    """For each row's transitions out of ``state``, in order: an arrow per transition to
    another state (:func:`_arrows`), and per self-loop a short stub arrow from the state in
    the direction of its action's slot on the colour wheel."""
    x, y = places.places[state]
    scale = places.scale
    per_row = np.fromiter(map(len, rows), np.int64, len(rows))
    flat = np.fromiter(chain.from_iterable(chain.from_iterable(rows)), np.int64).reshape(-1, 2)
    row_of = np.repeat(np.arange(len(rows)), per_row)
    actions, targets = flat[:, 0], flat[:, 1]
    colors = np.array(ACTION_COLORS, np.uint8)[actions % len(ACTION_COLORS)]
    loop = targets == state
    origins = np.tile([x, y], (len(flat), 1)).astype(np.float64)
    vectors = np.zeros((len(flat), 2))
    angle = 2 * np.pi * (actions[loop] % len(ACTION_COLORS)) / len(ACTION_COLORS)
    vectors[loop] = LOOP_LENGTH * scale * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    # Arrows: each row's k-th arrow to another state in slot k of that row's arrows.
    ids, xy = place_table
    arrow_rows = row_of[~loop]
    counts = np.bincount(arrow_rows, minlength=len(rows))
    firsts = np.cumsum(counts) - counts
    slot = np.arange(len(arrow_rows)) - firsts[arrow_rows]
    origins[~loop], vectors[~loop] = _arrows(
        (x, y), xy[np.searchsorted(ids, targets[~loop])], slot, counts[arrow_rows], scale
    )
    return _Drawn(origins, vectors, colors, per_row)


def _arrows(
    source: tuple[float, float] | _Floats,
    targets: _Floats,
    slot: npt.NDArray[np.int64],
    slots: npt.NDArray[np.int64],
    scale: float,
) -> tuple[_Floats, _Floats]:
    """Arrows from ``source`` (one place, or one per arrow) towards each of ``targets``,
    shortened at both ends, shifted sideways by their slot so that arrows of several actions
    (and the way back) stay apart; an arrow between two states at one place is a short one to
    the right."""
    sources = np.broadcast_to(np.asarray(source, np.float64), targets.shape)
    x0, y0 = sources[:, 0], sources[:, 1]
    delta = targets - sources
    length = np.hypot(delta[:, 0], delta[:, 1])
    apart = length > 0.0
    unit = np.divide(delta, length[:, None], out=np.zeros_like(delta), where=apart[:, None])
    side = 0.35 * scale * (slot - (slots - 1) / 2) + 0.25 * scale
    gap = np.minimum(1.2 * scale, 0.3 * length)
    origins = np.stack(
        [x0 + unit[:, 0] * gap - unit[:, 1] * side, y0 + unit[:, 1] * gap + unit[:, 0] * side],
        axis=1,
    )
    vectors = delta - 2 * unit * gap[:, None]
    origins[~apart] = sources[~apart]
    vectors[~apart] = (2 * scale, 0.0)
    return origins, vectors


def log_current_state(
    stream: rr.RecordingStream,
    times: npt.NDArray[np.int64],
    internal_states: npt.NDArray[np.int64],
    places: StatePlaces,
) -> int:
    """The current state as a ring at its place, a row at the first step and at every step it
    changes; returns the rows logged."""
    if not len(times):
        return 0
    change = np.flatnonzero(np.r_[True, internal_states[1:] != internal_states[:-1]])
    states = internal_states[change]
    ids = np.array(sorted(places.places), np.int64)
    xy = np.array([places.places[s] for s in ids.tolist()], np.float64).reshape(-1, 2)
    positions = xy[np.searchsorted(ids, states)]
    stream.log(
        CURRENT,
        rr.Points2D.from_fields(
            radii=rr.Radius.ui_points(9.0), colors=_CURRENT_COLOR, draw_order=20.0
        ),
        static=True,
    )
    if int(ids[-1]) < _MAX_CLASS_ID:
        # The label "now: {id}" by class id (2 bytes a row) from an annotation context,
        # rather than a string in every row: a million steps, a third of the file less.
        stream.log(
            CURRENT,
            rr.AnnotationContext(
                [rr.ClassDescription(info=(s, f"now: {s}")) for s in ids.tolist()]
            ),
            static=True,
        )
        classes = states.astype(np.uint16)
        return send_rows(
            stream,
            CURRENT,
            times[change],
            lambda rows: rr.Points2D.columns(positions=positions[rows], class_ids=classes[rows]),
        )
    labels = np.array([f"now: {s}" for s in states.tolist()], np.object_)
    return send_rows(
        stream,
        CURRENT,
        times[change],
        lambda rows: rr.Points2D.columns(positions=positions[rows], labels=labels[rows].tolist()),
    )
