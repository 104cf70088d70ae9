"""The consistency audit: which internal states does the memory itself prove wrong?

A *contradiction* for internal state ``s`` is two times ``i < j`` with ``s_i == s_j == s`` and a
``k >= 1`` such that the actions ``a_{i+1..i+k} == a_{j+1..j+k}``, the sensations
``o_{i+1..i+k-1} == o_{j+1..j+k-1}`` and ``o_{i+k} != o_{j+k}`` (with ``j + k <= T``). No
deterministic model that labels those times with ``s`` can be right. The sensations at ``i`` and
``j`` themselves are not compared.

The thesis compared sub-memories pair by pair (``O(T^2)`` pairs, minutes at 100k steps). Here the
memory after each time is a suffix of the string ``y_t = (a_t, o_t)``, ``t = 1..T``, and:

- two times contradict iff their suffixes, after a common prefix of length ``l``, both go on with
  the same action and (necessarily) different sensations; then ``k = l + 1``;
- sorting all suffixes (prefix doubling) and, per state, reading its times in suffix order, the
  contradicting pairs are exactly those between two *sibling* groups ``(a, false)`` and
  ``(a, true)`` of a node of the (virtual) suffix tree of that state's times. Such siblings are
  adjacent in suffix order, separated by one boundary whose LCP is the node's depth.

So every contradicting pair of groups is one boundary between neighbours; its earliest end is
``max(first time in the left group, first time in the right group) + k``, and its best witness is
those two first times. The whole audit is ``O(T log T)`` numpy work.

Two things keep a long memory (tens of millions of steps) within seconds and a bounded memory:

- a memory whose sensation never changes over ``1 .. T`` has no contradiction at all (the two
  sensations at ``i + k`` and ``j + k`` must differ): that is decided exactly, without sorting
  (a learner that never sensed its target);
- otherwise, past ``max_steps`` steps only the last ``max_steps`` are audited, and the findings
  say so (:attr:`ConsistencyFindings.sample`): every contradiction found there is one of the
  whole memory (its witness holds as given), but contradictions with a time before the sample
  are missed, and a state's ``first_step`` and ``pairs`` are counted inside the sample.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from rsstp_replay.audits._columns import factorized
from rsstp_replay.audits._suffixes import (
    RangeMin,
    common_prefix_lengths,
    index_type,
    nearest_at_most,
    suffix_ranks,
)
from rsstp_sim.errors import MemoryRangeError
from rsstp_sim.memory import Memory
from rsstp_sim.words import counted

__all__ = [
    "MAX_STEPS",
    "ConsistencyFindings",
    "Sample",
    "StateContradiction",
    "Witness",
    "audit_consistency",
    "audit_consistency_both",
    "audit_consistency_by_version",
    "find_contradictions",
]

_IntArray = npt.NDArray[np.int64]

MAX_STEPS = 1 << 21
"""The steps the audits judge for consistency by default (2,097,152): the last ones of a longer
memory (``rsstp-replay audit --consistency-steps``). Ranking that many suffixes takes a few
seconds and under 300 MiB."""


@dataclass(frozen=True, slots=True)
class Witness:
    """Two times ``i < j`` in the same internal state; the ``k`` actions after each are
    ``actions``, the sensations agree until the last of them and differ after it."""

    i: int
    j: int
    actions: tuple[int, ...]

    @property
    def k(self) -> int:
        """The number of actions, ``k >= 1``: the sensations differ at ``i + k`` and ``j + k``."""
        return len(self.actions)


@dataclass(frozen=True, slots=True)
class StateContradiction:
    """One internal state the memory proves wrong.

    ``witness`` is the shortest (smallest ``k``; ties: smallest ``j + k``, then smallest ``i``).
    ``first_step`` is the first step ``t`` such that the memory prefix ``0..t`` already contains
    a contradiction for this state (the minimum of ``j + k`` over all contradicting pairs).
    ``pairs`` counts the contradicting pairs ``(i, j)`` (each has exactly one ``k``).
    ``version``: the model version both times were in, when judged within versions
    (:func:`audit_consistency_by_version`); None over the whole history.
    """

    state: int
    witness: Witness
    first_step: int
    pairs: int
    version: int | None = None


@dataclass(frozen=True, slots=True)
class Sample:
    """The part of a memory the consistency audit judged: both times of a pair and the
    continuation after them in steps ``first_step .. last_step`` (the memory's last steps)."""

    first_step: int
    last_step: int

    @property
    def steps(self) -> int:
        """The steps judged: ``last_step - first_step``."""
        return self.last_step - self.first_step

    def to_text(self) -> str:
        return (
            f"sampled: only the last {counted(self.steps, 'step')} (steps "
            f"{self.first_step:,}..{self.last_step:,}) were judged; a contradiction with a time "
            f"before step {self.first_step:,} is not seen"
        )


@dataclass(frozen=True, slots=True)
class ConsistencyFindings:
    """The result of the consistency audit over a memory of ``steps`` steps (``T``).

    ``sample``: None when every time was judged; else the last steps, which alone were (see
    the module docstring)."""

    contradictions: tuple[StateContradiction, ...]
    steps: int
    sample: Sample | None = None

    @property
    def consistent(self) -> bool:
        """True when no internal state is contradicted (in the :attr:`sample`, if any)."""
        return not self.contradictions

    @property
    def exact(self) -> bool:
        """True when every time of the memory was judged (no :attr:`sample`)."""
        return self.sample is None

    @property
    def first_contradiction_step(self) -> int | None:
        """The first step at which the memory contains any contradiction; None if consistent."""
        if not self.contradictions:
            return None
        return min(found.first_step for found in self.contradictions)

    def to_text(self) -> str:
        """Human readable: one line per contradicted state, or one line saying it is consistent."""
        if not self.contradictions:
            if self.sample is not None:
                return f"consistent in the sample: no contradiction; {self.sample.to_text()}"
            return f"consistent: no contradiction in {counted(self.steps, 'step')}"
        lines = [] if self.sample is None else [self.sample.to_text()]
        for found in self.contradictions:
            witness = found.witness
            version = "" if found.version is None else f" of version {found.version}"
            lines.append(
                f"state {found.state}{version}: contradictory from step {found.first_step}; "
                f"shortest witness: steps {witness.i} and {witness.j} then actions "
                f"{list(witness.actions)} (k={witness.k}); "
                f"{counted(found.pairs, 'contradicting pair')}"
            )
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (plain ints, bools, lists)."""
        sample = self.sample
        return {
            "steps": self.steps,
            "exact": self.exact,
            "sample": None
            if sample is None
            else {"first_step": sample.first_step, "last_step": sample.last_step},
            "consistent": self.consistent,
            "first_contradiction_step": self.first_contradiction_step,
            "contradictions": [
                {
                    "state": found.state,
                    **({} if found.version is None else {"version": found.version}),
                    "first_step": found.first_step,
                    "pairs": found.pairs,
                    "witness": {
                        "i": found.witness.i,
                        "j": found.witness.j,
                        "k": found.witness.k,
                        "actions": list(found.witness.actions),
                    },
                }
                for found in self.contradictions
            ],
        }


def audit_consistency(memory: Memory, *, max_steps: int | None = None) -> ConsistencyFindings:
    """Find every internal state the memory contradicts (see the module docstring); past
    ``max_steps`` steps (None: no limit), in the last ``max_steps`` only."""
    return find_contradictions(
        memory.actions, memory.internal_states, memory.sensations, max_steps=max_steps
    )


def audit_consistency_by_version(
    memory: Memory, model_versions: npt.ArrayLike, *, max_steps: int | None = None
) -> ConsistencyFindings:
    """Contradictions judged inside the model version in force at each step.

    ``model_versions[t]`` is the version of entry ``t`` (a recording's ``model_version``
    column). Two times contradict only when they are in the same internal state *of the same
    version*: a state id means what its version says, and a state that a later version split
    or merged is another state. (The continuations after the two times may run through any
    versions: they are what the world did.) Each finding names its version.
    """
    keys = _VersionStates(memory, model_versions)
    (found,) = _contradictions(memory.actions, [keys.codes], memory.sensations, max_steps)
    return keys.named(found)


def audit_consistency_both(
    memory: Memory, model_versions: npt.ArrayLike, *, max_steps: int | None = None
) -> tuple[ConsistencyFindings, ConsistencyFindings]:
    """:func:`audit_consistency` and :func:`audit_consistency_by_version`, the memory's
    suffixes ranked once for both."""
    keys = _VersionStates(memory, model_versions)
    whole, found = _contradictions(
        memory.actions, [memory.internal_states, keys.codes], memory.sensations, max_steps
    )
    return whole, keys.named(found)


class _VersionStates:
    """Each time's (model version, internal state) as one integer code."""

    def __init__(self, memory: Memory, model_versions: npt.ArrayLike) -> None:
        versions = np.asarray(model_versions, dtype=np.int64)
        states = memory.internal_states
        if len(versions) != len(states):
            raise MemoryRangeError(
                f"model_versions has {len(versions)} entries, the memory {len(states)}"
            )
        self.version_ids, version_codes = factorized(versions)
        self.state_ids, state_codes = factorized(np.asarray(states))
        self.width = max(len(self.state_ids), 1)
        self.codes = version_codes.astype(np.int64) * self.width + state_codes

    def named(self, found: ConsistencyFindings) -> ConsistencyFindings:
        """``found`` over the codes, as findings over states, each naming its version."""
        return ConsistencyFindings(
            tuple(
                replace(
                    item,
                    state=int(self.state_ids[item.state % self.width]),
                    version=int(self.version_ids[item.state // self.width]),
                )
                for item in found.contradictions
            ),
            found.steps,
            found.sample,
        )


def find_contradictions(
    actions: npt.ArrayLike,
    states: npt.ArrayLike,
    sensations: npt.ArrayLike,
    *,
    max_steps: int | None = None,
) -> ConsistencyFindings:
    """The consistency audit over memory columns, as in :class:`~rsstp_sim.memory.Memory`.

    ``actions[0]`` (the reset's, -1 in a memory) is ignored; actions and states may be any
    integers, sensations must be booleans. ``O(T log T)`` time, ``O(T log T)`` memory.
    Raises :class:`MemoryRangeError` for columns of different lengths, of the wrong kind, or
    empty (the audit needs at least the reset entry), and for a ``max_steps`` below 2. Past
    ``max_steps`` steps (None: no limit) only the last ``max_steps`` are judged, and the
    findings say so (:attr:`ConsistencyFindings.sample`).
    """
    return _contradictions(actions, [states], sensations, max_steps)[0]


def _contradictions(
    actions: npt.ArrayLike,
    labellings: list[npt.ArrayLike],
    sensations: npt.ArrayLike,
    max_steps: int | None = None,
) -> list[ConsistencyFindings]:
    """:func:`find_contradictions` of each labelling of one memory's times (internal states,
    or states of a version), its suffixes ranked once."""
    if max_steps is not None and max_steps < 2:
        raise MemoryRangeError(f"max_steps: expected at least 2 steps to judge, got {max_steps}")
    checked = [_validated(actions, states, sensations) for states in labellings]
    action_column, _, sensation_column = checked[0]
    steps = len(action_column) - 1
    if steps < 2:  # a contradiction needs i < j and j + k <= T with k >= 1
        return [ConsistencyFindings((), steps) for _ in labellings]
    if not (sensation_column[1:] != sensation_column[1]).any():
        # o_{i+k} != o_{j+k} is impossible: decided exactly, whatever the memory's length.
        return [ConsistencyFindings((), steps) for _ in labellings]
    if max_steps is not None and steps > max_steps:
        first = steps - max_steps
        window = _contradictions(
            action_column[first:],
            [np.asarray(states)[first:] for states in labellings],
            sensation_column[first:] != 0,
        )
        return [_shifted(found, first, steps) for found in window]
    # Columns of one value per step in int32 where they fit (positions, ranks, codes): the
    # audit of ten million steps is bounded by its memory.
    positions = index_type(steps + 1)
    # The string y_p = (a_{p+1}, o_{p+1}), p = 0..T-1: the suffix at p is the memory after time p.
    action_codes = factorized(action_column[1:])[1].astype(positions)
    symbols = 2 * action_codes + sensation_column[1:]
    ranked = [suffix_ranks(symbols)]
    del symbols, checked
    found = []
    for index, states in enumerate(labellings):
        last = index == len(labellings) - 1
        column = np.asarray(states)
        found.append(_contradictions_of(column, action_column, action_codes, ranked, last))
    return found


def _contradictions_of(
    state_column: npt.NDArray[Any],
    action_column: npt.NDArray[np.integer[Any]],
    action_codes: npt.NDArray[np.integer[Any]],
    ranked: list[list[Any]],
    last: bool,
) -> ConsistencyFindings:
    """One labelling's contradictions, from the ranked suffixes (``ranked[0]``, emptied once
    the ``last`` labelling no longer needs it: the ranks are the audit's largest arrays)."""
    rank_levels = ranked[0]
    steps = len(action_column) - 1
    positions = index_type(steps + 1)
    # Every time p = 0..T-1 (time T has nothing after it), sorted by (state, suffix rank).
    state_ids, state_codes = factorized(state_column[:steps])
    state_codes = state_codes.astype(positions)
    # One int64 key per time (the suffix ranks are distinct and below ``steps``): one sort,
    # a third of the time of a lexsort over the two columns, the same order.
    key = state_codes.astype(np.int64)
    key *= steps
    key += rank_levels[-1]
    order = np.argsort(key).astype(positions)
    del key
    sorted_codes = state_codes[order]
    del state_codes
    same_state = sorted_codes[1:] == sorted_codes[:-1]
    left, right = order[:-1][same_state], order[1:][same_state]
    lcp = common_prefix_lengths(left, right, rank_levels)
    del rank_levels
    if last:
        ranked.clear()
    # A pair of neighbours with common prefix l contradicts iff both go on and the next
    # actions agree (the sensations then differ, or the common prefix would be longer).
    left += lcp
    right += lcp
    contradicts = (left < steps) & (right < steps)
    contradicts[contradicts] = action_codes[left[contradicts]] == action_codes[right[contradicts]]
    del left, right
    if not contradicts.any():
        return ConsistencyFindings((), steps)
    # boundary_lcp[b]: common prefix of sorted neighbours b-1 and b; -1 between states and at
    # both ends, so the groups found below never cross a state.
    size = len(order)
    boundary_lcp = np.full(size + 1, -1, dtype=positions)
    boundary_lcp[1:size][same_state] = lcp
    del lcp
    boundaries = (np.flatnonzero(same_state) + 1)[contradicts]
    del same_state, contradicts
    depth = boundary_lcp[boundaries].astype(np.int64)
    group_start, group_end = _sibling_groups(boundary_lcp, boundaries)
    del boundary_lcp
    first_times = RangeMin(order)
    first_left = first_times.query(group_start, boundaries - 1)
    first_right = first_times.query(boundaries, group_end - 1)
    witness_i = np.minimum(first_left, first_right)
    witness_j = np.maximum(first_left, first_right)
    k = depth + 1
    pairs = (boundaries - group_start) * (group_end - boundaries)
    boundary_state = sorted_codes[boundaries]
    return ConsistencyFindings(
        _per_state(state_ids, boundary_state, witness_i, witness_j, k, pairs, action_column),
        steps,
    )


def _shifted(found: ConsistencyFindings, first: int, steps: int) -> ConsistencyFindings:
    """Findings over the memory's entries ``first ..`` as findings over the whole memory of
    ``steps`` steps, judged in that sample."""
    return ConsistencyFindings(
        tuple(
            replace(
                item,
                witness=replace(item.witness, i=item.witness.i + first, j=item.witness.j + first),
                first_step=item.first_step + first,
            )
            for item in found.contradictions
        ),
        steps,
        Sample(first, steps),
    )


def _validated(
    actions: npt.ArrayLike, states: npt.ArrayLike, sensations: npt.ArrayLike
) -> tuple[npt.NDArray[np.integer[Any]], npt.NDArray[Any], npt.NDArray[np.int8]]:
    columns = {
        "actions": np.asarray(actions),
        "states": np.asarray(states),
        "sensations": np.asarray(sensations),
    }
    for name, column in columns.items():
        if column.ndim != 1:
            raise MemoryRangeError(f"{name}: expected a one-dimensional array, got {column.shape}")
    lengths = {name: len(column) for name, column in columns.items()}
    if len(set(lengths.values())) != 1:
        raise MemoryRangeError(f"the columns must have the same length, got {lengths}")
    if lengths["actions"] == 0:
        raise MemoryRangeError("the audit needs at least entry 0 (the reset); the memory is empty")
    if columns["actions"].dtype.kind not in "iu":
        raise MemoryRangeError(f"actions: expected integers, got {columns['actions'].dtype}")
    if columns["sensations"].dtype.kind != "b":
        raise MemoryRangeError(f"sensations: expected booleans, got {columns['sensations'].dtype}")
    return columns["actions"], columns["states"], columns["sensations"].view(np.int8)


def _sibling_groups(
    boundary_lcp: npt.NDArray[np.integer[Any]], boundaries: _IntArray
) -> tuple[_IntArray, _IntArray]:
    """For each boundary ``b`` of depth ``d``: the sibling groups it separates are the sorted
    entries ``[start, b)`` and ``[b, end)``, bounded by the nearest boundaries of depth ``<= d``
    (``boundary_lcp`` is -1 at both ends, so there always is one)."""
    return (
        nearest_at_most(boundary_lcp, boundaries, step=-1),
        nearest_at_most(boundary_lcp, boundaries, step=1),
    )


def _per_state(
    state_ids: npt.NDArray[Any],
    boundary_state: _IntArray,
    witness_i: _IntArray,
    witness_j: _IntArray,
    k: _IntArray,
    pairs: _IntArray,
    action_column: npt.NDArray[np.integer[Any]],
) -> tuple[StateContradiction, ...]:
    """Reduce the contradicting boundaries to one finding per state."""
    best = np.lexsort((witness_i, witness_j, k, boundary_state))
    states_in_order = boundary_state[best]
    starts = np.flatnonzero(np.r_[True, states_in_order[1:] != states_in_order[:-1]])
    first_step = np.minimum.reduceat((witness_j + k)[best], starts)
    pair_total = np.add.reduceat(pairs[best], starts)
    chosen = best[starts]
    # Plain ints, a column at a time (not a numpy scalar per value: a witness runs to
    # hundreds of actions, and a long run has thousands of states).
    columns = zip(
        witness_i[chosen].tolist(),
        witness_j[chosen].tolist(),
        k[chosen].tolist(),
        state_ids[states_in_order[starts]].tolist(),
        first_step.tolist(),
        pair_total.tolist(),
        strict=True,
    )
    return tuple(
        StateContradiction(
            state=int(state),
            witness=Witness(i, j, tuple(action_column[i + 1 : i + length + 1].tolist())),
            first_step=first,
            pairs=pairs,
        )
        for i, j, length, state, first, pairs in columns
    )
