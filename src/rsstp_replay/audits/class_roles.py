"""What the model stood for, per true class: the role of the states that stood for each class.

Over the steps a version was in force, the states that stood for a true class (the version's
states current at a pose of that class) give the class a role: the worst of theirs
(:mod:`rsstp_replay.audits.state_roles`), **aliased** over **redundant** over **exact**. So a
class stood for by one state that stood for it alone is exact; by several states, none of
them for another class too, redundant; by a state that stood for another class too, aliased.
The viewer's model map colours each pose by its class's role
(:mod:`rsstp_replay.viewer._map`), a class keeping the role of the last version that visited
it (:func:`class_role_changes`); in the final version, every class its model reaches has the
role the model gives it, visited or not (:func:`model_class_roles`), so a run that ends with
the truth's model ends with every class exact.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rsstp_replay.audits.state_roles import ALIASED, EXACT, REDUNDANT, state_roles
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth

__all__ = [
    "RoleChanges",
    "class_role_changes",
    "class_roles",
    "model_class_roles",
    "model_state_roles",
]

_Ints = npt.NDArray[np.int64]


def class_roles(
    step_versions: npt.ArrayLike,
    step_states: npt.ArrayLike,
    step_classes: npt.ArrayLike,
    *,
    roles: Mapping[int, Mapping[int, int]] | None = None,
) -> tuple[_Ints, _Ints, npt.NDArray[np.int8]]:
    """Every ``(version, class)`` pair seen at a step, and the class's role in that version:
    the worst role (aliased over redundant over exact) of the version's states that stood for
    the class (:func:`~rsstp_replay.audits.state_roles.state_roles`; ``roles``: those roles
    already at hand, per version and state). Sorted by version, then class."""
    v = np.asarray(step_versions, np.int64).ravel()
    s = np.asarray(step_states, np.int64).ravel()
    c = np.asarray(step_classes, np.int64).ravel()
    if not len(v):
        empty = np.empty(0, np.int64)
        return empty, empty, np.empty(0, np.int8)
    order = np.lexsort((s, c, v))  # by version, class, state
    tv, tc, ts = v[order], c[order], s[order]
    pair_starts = np.r_[True, (tv[1:] != tv[:-1]) | (tc[1:] != tc[:-1])]
    distinct = pair_starts | np.r_[True, ts[1:] != ts[:-1]]
    tv, tc, ts, pair_starts = tv[distinct], tc[distinct], ts[distinct], pair_starts[distinct]
    if roles is None:
        found = state_roles(v, s, c, versions=tv, states=ts)
    else:
        found = np.array(
            [roles[a][b] for a, b in zip(tv.tolist(), ts.tolist(), strict=True)], np.int8
        )
    starts = np.flatnonzero(pair_starts)
    worst = np.maximum.reduceat(found, starts)
    return tv[starts], tc[starts], worst.astype(np.int8)


@dataclass(frozen=True, slots=True)
class RoleChanges:
    """Where a class's colour changes: at version ``versions[k]``, class ``classes[k]`` takes
    role ``roles[k]`` (sorted by version). A class keeps its role until it changes."""

    versions: _Ints
    classes: _Ints
    roles: npt.NDArray[np.int8]


def model_class_roles(
    model: TransitionSystem, truth: GroundTruth, state: int, true_class: int
) -> tuple[_Ints, npt.NDArray[np.int8]]:
    """The classes the ``model`` reaches from ``state`` standing for ``true_class`` (walking
    both together, each action of the truth's), and each one's role by the model: aliased
    when a state that stands for it stands for another class too, redundant when several
    states stand for it, else exact. A move the model lacks, or has several successors for,
    ends that branch of the walk."""
    states, classes = _walked(model, truth, state, true_class)
    shared = _how_many(states) > 1
    order = np.argsort(classes, kind="stable")
    reached, starts, per_class = np.unique(classes[order], return_index=True, return_counts=True)
    aliased = np.maximum.reduceat(shared[order].astype(np.int8), starts).astype(bool)
    roles = np.where(aliased, ALIASED, np.where(per_class > 1, REDUNDANT, EXACT))
    return reached.astype(np.int64), roles.astype(np.int8)


def model_state_roles(
    model: TransitionSystem, truth: GroundTruth, state: int, true_class: int
) -> dict[int, int]:
    """The states the ``model`` reaches, walked as :func:`model_class_roles` walks, and each
    one's role by the model: aliased when it stands for several classes, redundant when its
    class has other states, else exact."""
    states, classes = _walked(model, truth, state, true_class)
    shared = _how_many(states) > 1
    crowded = _how_many(classes) > 1
    roles = np.where(shared, ALIASED, np.where(crowded, REDUNDANT, EXACT))
    found: dict[int, int] = {}
    for s, role in zip(states.tolist(), roles.tolist(), strict=True):
        found[s] = max(found.get(s, EXACT), role)
    return found


def _walked(
    model: TransitionSystem, truth: GroundTruth, state: int, true_class: int
) -> tuple[_Ints, _Ints]:
    """Every (state, class) pair met walking the model and the truth together from
    (``state``, ``true_class``), as two columns, sorted."""
    actions = truth.actions
    seen = {(state, true_class)}
    frontier = [(state, true_class)]
    while frontier:
        found = []
        for s, c in frontier:
            for k, a in enumerate(actions):
                targets = model.successors(s, a) if s in model else ()
                if len(targets) != 1:
                    continue
                pair = (targets[0], int(truth.class_next[c, k]))
                if pair not in seen:
                    seen.add(pair)
                    found.append(pair)
        frontier = found
    pairs = np.array(sorted(seen), np.int64).reshape(-1, 2)
    return pairs[:, 0], pairs[:, 1]


def _how_many(values: _Ints) -> _Ints:
    """For each element, how many elements have its value."""
    _, where, counts = np.unique(values, return_inverse=True, return_counts=True)
    return counts[where]


def class_role_changes(
    step_versions: npt.ArrayLike,
    step_states: npt.ArrayLike,
    step_classes: npt.ArrayLike,
    *,
    state_roles: Mapping[int, Mapping[int, int]] | None = None,
    final: tuple[int, _Ints, npt.NDArray[np.int8]] | None = None,
) -> RoleChanges:
    """The changes of :func:`class_roles` over versions, a class keeping the role of the last
    version that visited it (unvisited before). ``final``: (the final version, the classes
    its model reaches, their roles: :func:`model_class_roles`), which hold in that version
    whether visited or not."""
    versions, classes, roles = class_roles(
        step_versions, step_states, step_classes, roles=state_roles
    )
    if final is not None:
        version, reached, given = final
        keep = ~((versions == version) & np.isin(classes, reached))
        versions = np.r_[versions[keep], np.full(len(reached), version, np.int64)]
        classes = np.r_[classes[keep], reached]
        roles = np.r_[roles[keep], given].astype(np.int8)
        order = np.lexsort((classes, versions))
        versions, classes, roles = versions[order], classes[order], roles[order]
    order = np.lexsort((versions, classes))  # by class, then version
    c, r = classes[order], roles[order]  # every role is a visit's (never unvisited)
    changed = np.r_[True, c[1:] != c[:-1]] | np.r_[True, r[1:] != r[:-1]]
    keep = np.sort(order[changed])  # back to (version, class) order
    return RoleChanges(versions[keep], classes[keep], roles[keep])
