"""What each state of each model version stood for, by the ground truth: its *role*.

Over the steps a version was in force (``step_versions[t]``), with ``step_states[t]`` the
step's internal state and ``step_classes[t]`` the true class of its pose
(:func:`rsstp_replay.audits.truth.step_true_classes`), a state of that version is:

- **aliased** (:data:`ALIASED`): it stood for two or more true classes;
- **redundant** (:data:`REDUNDANT`): it stood for one class, and two or more states of the
  version stood for that class (the others aliased or not);
- **exact** (:data:`EXACT`): it stood for one class that no other state of the version stood
  for;
- **unvisited** (:data:`UNVISITED`): the version was never in that state at a step.

A version equivalent to the truth (:mod:`rsstp_replay.audits.verdict`) has no aliased state on
the steps it was in force; a redundant one is allowed (a correct model need not be minimal).
The viewer colours the model's states by role (:mod:`rsstp_replay.viewer._model`).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rsstp_sim.arrays import distinct
from rsstp_sim.errors import MemoryRangeError

__all__ = ["ALIASED", "EXACT", "REDUNDANT", "ROLE_NAMES", "UNVISITED", "state_roles"]

UNVISITED = 0
EXACT = 1
REDUNDANT = 2
ALIASED = 3
ROLE_NAMES: tuple[str, ...] = ("unvisited", "exact", "redundant", "aliased")
"""``ROLE_NAMES[role]``: the name of a role code."""

_Ints = npt.NDArray[np.int64]


def state_roles(
    step_versions: npt.ArrayLike,
    step_states: npt.ArrayLike,
    step_classes: npt.ArrayLike,
    *,
    versions: npt.ArrayLike,
    states: npt.ArrayLike,
) -> npt.NDArray[np.int8]:
    """The role code of state ``states[k]`` in version ``versions[k]``, for every ``k``, over
    the steps described by the three equal-length ``step_*`` arrays (see the module
    docstring). Raises :class:`~rsstp_sim.errors.MemoryRangeError` when the arrays differ in
    length."""
    step_v, step_s, step_c = (
        np.asarray(a, np.int64).ravel() for a in (step_versions, step_states, step_classes)
    )
    if not len(step_v) == len(step_s) == len(step_c):
        raise MemoryRangeError(
            f"step arrays of different lengths: {len(step_v)}, {len(step_s)}, {len(step_c)}"
        )
    query_v, query_s = np.asarray(versions, np.int64).ravel(), np.asarray(states, np.int64).ravel()
    if len(query_v) != len(query_s):
        raise MemoryRangeError(f"{len(query_v)} versions for {len(query_s)} states")
    roles = np.full(len(query_v), UNVISITED, np.int8)
    if not len(step_v) or not len(query_v):
        return roles
    # Every distinct (version, state, class) triple, as codes, then counts per pair.
    v_ids, v_codes = np.unique(step_v, return_inverse=True)
    s_ids, s_codes = np.unique(step_s, return_inverse=True)
    c_ids, c_codes = np.unique(step_c, return_inverse=True)
    n_s, n_c = len(s_ids), len(c_ids)
    triples = distinct((v_codes * n_s + s_codes) * n_c + c_codes)
    vs = triples // n_c  # (version, state) code of each triple
    vc = (triples // (n_s * n_c)) * n_c + triples % n_c  # (version, class) code
    pairs, classes_per_pair = np.unique(vs, return_counts=True)
    class_pairs, states_per_class = np.unique(vc, return_counts=True)
    # A pair with one class: is that class shared by several states of the version?
    single = classes_per_pair == 1
    first_triple = np.searchsorted(vs, pairs)  # the pair's (only, when single) class
    shared = states_per_class[np.searchsorted(class_pairs, vc[first_triple])] > 1
    pair_roles = np.where(~single, ALIASED, np.where(shared, REDUNDANT, EXACT)).astype(np.int8)
    # Look the queries up: known versions and states only, then the pair.
    v_at = np.clip(np.searchsorted(v_ids, query_v), 0, len(v_ids) - 1)
    s_at = np.clip(np.searchsorted(s_ids, query_s), 0, n_s - 1)
    known = (v_ids[v_at] == query_v) & (s_ids[s_at] == query_s)
    keys = v_at * n_s + s_at
    at = np.clip(np.searchsorted(pairs, keys), 0, len(pairs) - 1)
    found = known & (pairs[at] == keys)
    roles[found] = pair_roles[at[found]]
    return roles
