"""The arrows of a large model: only around the current state.

A model of a thousand states drawn with every transition is a grey tangle (four thousand
arrows over the arm's workspace). Over :data:`ALL_ARROWS_MAX_STATES` states, the states stay
points (:mod:`~rsstp_replay.viewer._model`) and one entity, ``world/model/near``, draws the
transitions out of the current state and out of every state reached from it in fewer than
:data:`NEAR_STEPS` steps, in the model version in force: the model's next moves, where the
eye already is (the current state's orange ring). The arrows look as on a small model
(coloured by action, self-loops as stubs in the action's direction).

A row at the first step, where the current state changes (at the steps the current state is
shown: an overview shows one step in k) and at each version's step.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import numpy.typing as npt
import rerun as rr

from rsstp_format.records import ModelRecord
from rsstp_replay.viewer._chunks import send_rows
from rsstp_replay.viewer._model import (
    ACTION_COLORS,
    LOOP_LENGTH,
    StatePlaces,
    _arrows,
    _touched,
)
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["ALL_ARROWS_MAX_STATES", "NEAR", "NEAR_STEPS", "log_near", "neighbourhood"]

NEAR = "world/model/near"
NEAR_STEPS = 2
"""The transitions out of the current state and out of the states it reaches in fewer than
this many steps are drawn."""
ALL_ARROWS_MAX_STATES = 300
"""Every transition is drawn (on each state's entity) when no version shown has more states
than this; else only the current state's neighbourhood (:data:`NEAR`)."""

_Ints = npt.NDArray[np.int64]


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
    found: list[tuple[int, int, int]] = []
    counts = np.zeros(len(row_times), np.int64)
    for k, (step, state) in enumerate(zip(row_times.tolist(), row_states.tolist(), strict=True)):
        while at + 1 < len(versions) and version_steps[at + 1] <= step:
            at += 1
            for touched in _touched(model, versions[at]):
                outs.pop(touched, None)
        near = neighbourhood(outs_of, state, depth)
        counts[k] = len(near)
        found += near
    origins, vectors, colors = _geometry(np.array(found, np.int64).reshape(-1, 3), counts, places)
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
