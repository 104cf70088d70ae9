"""A large model on the world: its states as points in blocks, its arrows only around the
current state.

A model of a thousand states drawn as on a small one (an entity per state with its arrows,
:mod:`~rsstp_replay.viewer._model`) is a grey tangle of four thousand arrows, and a thousand
entity paths of one point each: the web viewer took minutes to load them, and drew points
where none was logged (a thousand one-point entities, synthetic, drew points outside the
circle they were all on; the same points in one entity did not; issue 32). Over
:data:`ALL_ARROWS_MAX_STATES` states in a version shown:

- **The states**, ``world/model/states/{block}``: the state ids, sorted, in blocks of
  :func:`block_size` (at most :data:`MAX_BLOCKS` blocks). A block's places are static (a
  state never moves); its rows, at the first step and where a state of the block appeared,
  changed role or went, hold every member's colour (its role's, as on a small model), radius
  (:data:`STATE_RADIUS_UI`; 0 while it is not in the model: a transparent colour alone was
  drawn black) and class id (its label, from a static
  annotation context, for the states whose label fits). No lines to the poses.
- **The arrows**, ``world/model/near``: the transitions out of the current state (and out of
  every state reached from it in fewer than :data:`NEAR_STEPS` steps), in the version in
  force: the model's next moves, where the eye already is (the current state's orange ring).
  They look as on a small model (coloured by action, self-loops as stubs in the action's
  direction). A row at the first step, where the current state changes (at the steps the
  current state is shown: an overview shows one step in k) and at each version's step.
"""

from __future__ import annotations

from array import array
from collections.abc import Callable, Sequence
from itertools import chain

import numpy as np
import numpy.typing as npt
import rerun as rr

from rsstp_format.records import ModelRecord
from rsstp_replay.viewer._chunks import latest_rows, send_rows
from rsstp_replay.viewer._model import (
    ACTION_COLORS,
    LOOP_LENGTH,
    ROLE_COLORS,
    Roles,
    StatePlaces,
    _arrows,
    _touched,
    state_rows,
)
from rsstp_sim import palette
from rsstp_sim.transition_system import TransitionSystem

__all__ = [
    "ALL_ARROWS_MAX_STATES",
    "MAX_BLOCKS",
    "NEAR",
    "NEAR_STEPS",
    "STATE_BLOCKS",
    "block_size",
    "log_large_model",
    "log_near",
    "neighbourhood",
]

STATE_BLOCKS = "world/model/states"
MAX_BLOCKS = 128
"""At most this many entities hold a large model's states."""
STATE_RADIUS_UI = 2.5
"""A state's point, in UI points (a small model's states have Rerun's default size)."""
NEAR = "world/model/near"
NEAR_STEPS = 1
"""The transitions out of the current state and out of the states it reaches in fewer than
this many steps are drawn: 1, the current state's own (an arrow to each successor). (2 drew
about 20 arrows a row: on the 643,244-step learner run 39 MB of the viewer's 79, where 1 draws
4.)"""
ALL_ARROWS_MAX_STATES = 300
"""Every transition is drawn (on each state's entity) when no version shown has more states
than this; else only the current state's neighbourhood (:data:`NEAR`)."""

_Ints = npt.NDArray[np.int64]


def block_size(n_states: int) -> int:
    """States per block: 16, or more to keep at most :data:`MAX_BLOCKS` blocks."""
    return max(16, -(-n_states // MAX_BLOCKS))


def block_path(block: int) -> str:
    return f"{STATE_BLOCKS}/{block}"


_ABSENT = -1
_NO_ROLE = -2
_MAX_CLASS_ID = 1 << 16


def _packed(color: tuple[int, int, int]) -> int:
    r, g, b = color
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


def log_large_model(
    stream: rr.RecordingStream,
    versions: Sequence[ModelRecord],
    steps: Sequence[int],
    places: StatePlaces,
    *,
    roles: Roles | None = None,
    labelled: set[int] | None = None,
) -> dict[str, int]:
    """The states of ``versions`` (each shown from its step in ``steps``) in blocks (see the
    module docstring), labels on the ``labelled`` ones (default: all). Returns rows per
    entity path (the blocks summed under :data:`STATE_BLOCKS`)."""
    rows = state_rows(versions, steps, roles=roles, arrows=False)
    ids = np.array(sorted(places.places), np.int64)
    xy = np.array([places.places[s] for s in ids.tolist()], np.float64).reshape(-1, 2)
    # Every change, flat: (step, index of the state among ids, value).
    changes = [
        (step, state, _ABSENT if outs is None else _NO_ROLE if role is None else role)
        for state, changes in rows.items()
        for step, outs, role in changes
    ]
    flat = np.array(changes, np.int64).reshape(-1, 3)
    flat = flat[np.lexsort((flat[:, 1], flat[:, 0]))]  # by step: the last change wins
    where = np.searchsorted(ids, flat[:, 1])
    # A value's colour: a role's, dark grey without the truth, transparent when absent.
    table = {_ABSENT: 0, _NO_ROLE: _packed(palette.STATE)}
    table |= {role: _packed(color) for role, color in ROLE_COLORS.items()}
    codes = np.array(sorted(table), np.int64)
    colours = np.array([table[c] for c in codes.tolist()], np.uint32)
    size = block_size(len(ids))
    first = int(steps[0])
    count = 0
    shown = labelled if labelled is not None else set(ids.tolist())
    for block, begin in enumerate(range(0, len(ids), size)):
        members = ids[begin : begin + size]
        path = block_path(block)
        mine = (where >= begin) & (where < begin + size)
        values, times = latest_rows(
            where[mine] - begin,
            flat[mine, 0],
            flat[mine, 2],
            width=len(members),
            first=first,
            initial=_ABSENT,
        )
        named = [s for s in members.tolist() if s in shown and s < _MAX_CLASS_ID - 1]
        stream.log(
            path,
            rr.Points2D(xy[begin : begin + size], draw_order=10.0),
            rr.AnnotationContext([rr.ClassDescription(info=(s, str(s))) for s in named]),
            static=True,
        )
        labels = np.isin(members, named)
        classes = np.where(labels & (values != _ABSENT), members, _MAX_CLASS_ID - 1)
        packed = colours[np.searchsorted(codes, values)]
        # An absent state: radius 0 (a transparent colour alone is drawn black).
        radii = np.where(values == _ABSENT, 0.0, -STATE_RADIUS_UI).astype(np.float32)
        count += send_rows(
            stream, path, times, _block_columns(packed, classes.astype(np.uint16), radii)
        )
    return {STATE_BLOCKS: count}


def _block_columns(
    colours: npt.NDArray[np.uint32],
    classes: npt.NDArray[np.uint16],
    radii: npt.NDArray[np.float32],
) -> Callable[[slice], rr.ComponentColumnList]:
    def columns(rows: slice) -> rr.ComponentColumnList:
        chosen = colours[rows]
        return rr.Points2D.columns(
            colors=chosen.ravel(), class_ids=classes[rows].ravel(), radii=radii[rows].ravel()
        ).partition(np.full(len(chosen), chosen.shape[1]))

    return columns


def neighbourhood(
    outs_of: Callable[[int], tuple[tuple[int, int], ...]], state: int, depth: int
) -> list[tuple[int, int, int]]:
    """``(source, action, target)`` of every transition out of ``state`` and out of each
    state it reaches in fewer than ``depth`` steps (breadth first, each source once);
    ``outs_of(s)``: the ``(action, target)`` pairs out of ``s``."""
    found: list[tuple[int, int, int]] = []
    frontier, seen = [state], {state}
    for _ in range(depth):
        following: list[int] = []
        for source in frontier:
            for action, target in outs_of(source):
                found.append((source, action, target))
                if target not in seen:
                    seen.add(target)
                    following.append(target)
        frontier = following
    return found


def log_near(
    stream: rr.RecordingStream,
    versions: Sequence[ModelRecord],
    version_steps: Sequence[int],
    times: _Ints,
    states: _Ints,
    places: StatePlaces,
    *,
    depth: int = NEAR_STEPS,
) -> int:
    """The neighbourhood arrows at ``times`` (ascending; the current state ``states`` at
    each), a row at the first, where the state changes and at each version's step
    (``version_steps``, of ``versions``). Returns the rows logged."""
    if not len(times):
        return 0
    rows = _row_times(times, states, np.asarray(version_steps, np.int64))
    row_times, row_states = times[rows], states[rows]
    model = TransitionSystem.from_snapshot(versions[0].snapshot(), version=versions[0].version)
    outs: dict[int, tuple[tuple[int, int], ...]] = {}

    def outs_of(state: int) -> tuple[tuple[int, int], ...]:
        known = outs.get(state)
        if known is None:
            known = outs[state] = tuple(model.transitions_from(state)) if state in model else ()
        return known

    at = 0  # the version in force
    found = array("q")  # (source, action, target) flat: 24 bytes an arrow, not a tuple's 100
    counts = np.zeros(len(row_times), np.int64)
    for k, (step, state) in enumerate(zip(row_times.tolist(), row_states.tolist(), strict=True)):
        while at + 1 < len(versions) and version_steps[at + 1] <= step:
            at += 1
            for touched in _touched(model, versions[at]):
                outs.pop(touched, None)
        near = neighbourhood(outs_of, state, depth)
        counts[k] = len(near)
        found.extend(chain.from_iterable(near))
    flat = np.frombuffer(found, np.int64).reshape(-1, 3) if found else np.empty((0, 3), np.int64)
    origins, vectors, colors = _geometry(flat, counts, places)
    ends = np.cumsum(counts)

    def columns(rows: slice) -> rr.ComponentColumnList:
        chosen = counts[rows]
        begin = int(ends[rows][0] - chosen[0]) if len(chosen) else 0
        end = begin + int(chosen.sum())
        return rr.Arrows2D.columns(
            origins=origins[begin:end], vectors=vectors[begin:end], colors=colors[begin:end]
        ).partition(chosen)

    return send_rows(stream, NEAR, row_times, columns)


def _row_times(times: _Ints, states: _Ints, version_steps: _Ints) -> _Ints:
    """The indexes of ``times`` that get a row: the first, where the state changed, and the
    last at or before each version's step."""
    change = np.r_[True, states[1:] != states[:-1]]
    at_version = np.searchsorted(times, version_steps, side="right") - 1
    change[at_version[at_version >= 0]] = True
    return np.flatnonzero(change)


def _geometry(
    found: _Ints, counts: _Ints, places: StatePlaces
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint8]]:
    """Each ``(source, action, target)`` row of ``found`` as an arrow: as on a small model, an
    arrow towards another state (side by side with the source's other arrows of the same row),
    a stub in the action's direction for a self-loop."""
    ids = np.array(sorted(places.places), np.int64)
    xy = np.array([places.places[s] for s in ids.tolist()], np.float64).reshape(-1, 2)
    sources, actions, targets = found[:, 0], found[:, 1], found[:, 2]
    colors = np.array(ACTION_COLORS, np.uint8)[actions % len(ACTION_COLORS)]
    source_xy = xy[np.searchsorted(ids, sources)]
    origins = source_xy.copy()
    vectors = np.zeros_like(origins)
    loop = sources == targets
    angle = 2 * np.pi * (actions[loop] % len(ACTION_COLORS)) / len(ACTION_COLORS)
    vectors[loop] = LOOP_LENGTH * places.scale * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    # A group: one row's arrows out of one source (each source's arrows are contiguous).
    row = np.repeat(np.arange(len(counts)), counts)
    key = row[~loop] * (int(ids.max(initial=0)) + 1) + sources[~loop]
    start = np.r_[True, key[1:] != key[:-1]] if len(key) else np.zeros(0, np.bool_)
    group = np.cumsum(start) - 1
    firsts = np.flatnonzero(start)
    sizes = np.diff(np.r_[firsts, len(key)])
    slot = np.arange(len(key)) - firsts[group]
    origins[~loop], vectors[~loop] = _arrows(
        source_xy[~loop], xy[np.searchsorted(ids, targets[~loop])], slot, sizes[group], places.scale
    )
    return origins, vectors, colors
