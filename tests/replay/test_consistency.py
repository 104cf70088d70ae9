"""The consistency audit against a brute-force reference, planted and consistent memories."""

from __future__ import annotations

import json
from unittest import mock

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_replay.audits import (
    ConsistencyFindings,
    StateContradiction,
    Witness,
    audit_consistency,
    find_contradictions,
)
from rsstp_sim.errors import MemoryRangeError
from rsstp_sim.memory import Memory

Columns = tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.bool_]]


def reference(
    actions: npt.NDArray[np.int64], states: npt.NDArray[np.int64], sensations: npt.NDArray[np.bool_]
) -> dict[int, tuple[int, int, int, int, int]]:
    """O(T^3) definition: state -> (i, j, k of the shortest witness, first_step, pairs)."""
    steps = len(actions) - 1
    found: dict[int, list[tuple[int, int, int, int]]] = {}
    for i in range(steps + 1):
        for j in range(i + 1, steps + 1):
            if states[i] != states[j]:
                continue
            k = 1
            while j + k <= steps and actions[i + k] == actions[j + k]:
                if sensations[i + k] != sensations[j + k]:
                    found.setdefault(int(states[i]), []).append((k, j + k, i, j))
                    break
                k += 1
    result = {}
    for state, witnesses in found.items():
        k, _, i, j = min(witnesses)  # smallest k, then smallest j + k, then smallest i
        first_step = min(end for _, end, _, _ in witnesses)
        result[state] = (i, j, k, first_step, len(witnesses))
    return result


def is_witness(columns: Columns, witness: Witness) -> bool:
    actions, states, sensations = columns
    i, j, k = witness.i, witness.j, witness.k
    return (
        0 <= i < j
        and k >= 1
        and j + k < len(actions)
        and states[i] == states[j]
        and tuple(actions[i + 1 : i + k + 1]) == witness.actions
        and tuple(actions[j + 1 : j + k + 1]) == witness.actions
        and np.array_equal(sensations[i + 1 : i + k], sensations[j + 1 : j + k])
        and sensations[i + k] != sensations[j + k]
    )


def check_against_reference(columns: Columns) -> ConsistencyFindings:
    findings = find_contradictions(*columns)
    expected = reference(*columns)
    assert findings.steps == len(columns[0]) - 1
    assert [found.state for found in findings.contradictions] == sorted(expected)
    for found in findings.contradictions:
        assert is_witness(columns, found.witness)
        i, j, k, first_step, pairs = expected[found.state]
        assert (found.witness.i, found.witness.j, found.witness.k) == (i, j, k)
        assert found.first_step == first_step
        assert found.pairs == pairs
    assert findings.consistent == (not expected)
    assert findings.first_contradiction_step == min(
        (value[3] for value in expected.values()), default=None
    )
    return findings


@st.composite
def random_columns(draw: st.DrawFn) -> Columns:
    """Independent random actions, states and sensations (short alphabets)."""
    steps = draw(st.integers(0, 40))
    action_count = draw(st.integers(1, 3))
    state_count = draw(st.integers(1, 4))
    actions = draw(st.lists(st.integers(0, action_count - 1), min_size=steps, max_size=steps))
    states = draw(st.lists(st.integers(0, state_count - 1), min_size=steps + 1, max_size=steps + 1))
    sensations = draw(st.lists(st.booleans(), min_size=steps + 1, max_size=steps + 1))
    return np.array([-1, *actions]), np.array(states), np.array(sensations, dtype=np.bool_)


@st.composite
def hidden_system_columns(draw: st.DrawFn) -> Columns:
    """A walk on a hidden deterministic cycle, its positions labelled by aliased states.

    Long shared histories (long common prefixes) are frequent here, unlike in independent noise.
    """
    steps = draw(st.integers(0, 40))
    positions = draw(st.integers(1, 6))
    moves = draw(st.lists(st.sampled_from([1, -1, 0, 2]), min_size=1, max_size=3, unique=True))
    actions = draw(st.lists(st.integers(0, len(moves) - 1), min_size=steps, max_size=steps))
    goal = draw(st.integers(0, positions - 1))
    state_count = draw(st.integers(1, 4))
    position, walk = 0, [0]
    for action in actions:
        position = (position + moves[action]) % positions
        walk.append(position)
    where = np.array(walk)
    return np.array([-1, *actions]), where % state_count, where == goal


@pytest.mark.slow
@settings(max_examples=400, deadline=None)
@given(columns=random_columns())
def test_random_memories_match_reference(columns: Columns) -> None:
    check_against_reference(columns)


@pytest.mark.slow
@settings(max_examples=400, deadline=None)
@given(columns=hidden_system_columns())
def test_hidden_system_memories_match_reference(columns: Columns) -> None:
    check_against_reference(columns)


def test_large_state_ids_and_action_values() -> None:
    actions = np.array([-1, 7, 9, 7, 9, 7, 7])
    states = np.array([10**12, 3, 10**12, 3, 10**12, 3, 10**12])
    sensations = np.array([False, False, True, False, False, True, False])
    findings = check_against_reference((actions, states, sensations))
    assert not findings.consistent


def one_state_cycle(steps: int) -> Memory:
    """A one-state model of a 4-position cycle walked forward: the sensation is at position 0."""
    memory = Memory()
    memory.reset(0, True, 1.0)
    for t in range(1, steps + 1):
        memory.append(0, 0, t % 4 == 0, 1.0 if t % 4 == 0 else 0.0)
    return memory


def test_planted_one_state_cycle() -> None:
    findings = audit_consistency(one_state_cycle(12))
    assert findings.contradictions == (
        StateContradiction(state=0, witness=Witness(0, 3, (0,)), first_step=4, pairs=54),
    )
    assert findings.first_contradiction_step == 4
    assert not findings.consistent
    # Before step 4 the sensation never came back: nothing to contradict.
    assert audit_consistency(one_state_cycle(3)).consistent


def test_first_step_is_not_the_shortest_witness_end() -> None:
    """The shortest witness (k=1, ends at 4) ends after the first contradiction (k=2, at 3)."""
    actions = np.array([-1, 0, 0, 0, 0])
    states = np.array([1, 1, 0, 1, 0])
    sensations = np.array([False, False, False, True, True])
    findings = check_against_reference((actions, states, sensations))
    assert findings.contradictions == (
        StateContradiction(state=1, witness=Witness(0, 3, (0,)), first_step=3, pairs=3),
    )


def test_consistent_when_states_are_true_positions() -> None:
    rng = np.random.default_rng(5)
    moves = np.array([1, -1, 2])
    actions = rng.integers(0, 3, 2001)
    actions[0] = -1
    positions = np.cumsum(np.r_[0, moves[actions[1:]]]) % 7
    findings = find_contradictions(actions, positions, positions == 3)
    assert findings.consistent
    assert findings.first_contradiction_step is None
    assert findings.contradictions == ()
    assert findings.to_text() == "consistent: no contradiction in 2,000 steps"
    aliased = find_contradictions(actions, positions % 3, positions == 3)
    assert not aliased.consistent


@pytest.mark.parametrize("steps", [0, 1])
def test_too_short_to_contradict(steps: int) -> None:
    findings = audit_consistency(one_state_cycle(steps))
    assert findings.consistent
    assert findings.steps == steps


def test_to_text_and_to_json() -> None:
    findings = ConsistencyFindings(
        (
            StateContradiction(3, Witness(12, 40, (0, 1)), first_step=57, pairs=1),
            StateContradiction(5, Witness(2, 9, (2,)), first_step=10, pairs=4),
        ),
        steps=80,
    )
    assert findings.to_text() == (
        "state 3: contradictory from step 57; shortest witness: steps 12 and 40 then actions"
        " [0, 1] (k=2); 1 contradicting pair\n"
        "state 5: contradictory from step 10; shortest witness: steps 2 and 9 then actions"
        " [2] (k=1); 4 contradicting pairs"
    )
    document = findings.to_json()
    assert json.loads(json.dumps(document)) == document
    assert document == {
        "steps": 80,
        "exact": True,
        "sample": None,
        "consistent": False,
        "first_contradiction_step": 10,
        "contradictions": [
            {
                "state": 3,
                "first_step": 57,
                "pairs": 1,
                "witness": {"i": 12, "j": 40, "k": 2, "actions": [0, 1]},
            },
            {
                "state": 5,
                "first_step": 10,
                "pairs": 4,
                "witness": {"i": 2, "j": 9, "k": 1, "actions": [2]},
            },
        ],
    }


def test_found_values_are_plain_python() -> None:
    findings = audit_consistency(one_state_cycle(12))
    document = findings.to_json()
    json.dumps(document)
    (found,) = findings.contradictions
    assert type(found.state) is int and type(found.first_step) is int
    assert all(type(action) is int for action in found.witness.actions)


def test_audit_of_memory_equals_columns() -> None:
    memory = one_state_cycle(30)
    assert audit_consistency(memory) == find_contradictions(
        memory.actions, memory.internal_states, memory.sensations
    )


@pytest.mark.parametrize(
    ("columns", "message"),
    [
        (([], [], []), r"needs at least entry 0 \(the reset\)"),
        (([-1, 0], [0], [True, False]), "the columns must have the same length"),
        (([-1, 0], [0, 0], [1, 0]), "sensations: expected booleans, got int64"),
        (([-1.0, 0.5], [0, 0], [True, False]), "actions: expected integers, got float64"),
        (([[-1, 0]], [[0, 0]], [[True, False]]), "actions: expected a one-dimensional array"),
    ],
)
def test_bad_columns(columns: tuple[object, object, object], message: str) -> None:
    with pytest.raises(MemoryRangeError, match=message):
        find_contradictions(*columns)  # type: ignore[arg-type]


@settings(max_examples=60, deadline=None)
@given(
    values=st.lists(st.integers(-1, 40), min_size=1, max_size=2000),
    seed=st.integers(0, 2**32 - 1),
)
def test_range_minima_and_nearest_smaller_against_brute_force(values: list[int], seed: int):
    """The O(n)-memory range minima (blocks of 16) and the pointer-jumping nearest position
    with a value at most one's own, against plain Python."""
    from rsstp_replay.audits._suffixes import RangeMin, nearest_at_most

    array = np.array(values, dtype=np.int64)
    rng = np.random.default_rng(seed)
    first = rng.integers(0, len(array), 300)
    last = np.minimum(first + rng.integers(0, 1200, 300), len(array) - 1)
    found = RangeMin(array).query(first, last)
    assert found.tolist() == [min(values[f : e + 1]) for f, e in zip(first, last, strict=True)]
    fenced = np.array([-1, *values, -1], dtype=np.int64)  # as boundary_lcp: -1 at both ends
    inner = np.arange(1, len(fenced) - 1)
    before = nearest_at_most(fenced, inner, step=-1)
    after = nearest_at_most(fenced, inner, step=1)
    for p, b, a in zip(inner.tolist(), before.tolist(), after.tolist(), strict=True):
        assert b == max(c for c in range(p) if fenced[c] <= fenced[p])
        assert a == min(c for c in range(p + 1, len(fenced)) if fenced[c] <= fenced[p])


@settings(max_examples=40, deadline=None)
@given(
    period=st.lists(st.integers(0, 5), min_size=1, max_size=40),
    repeats=st.integers(2, 30),
    changes=st.lists(st.tuples(st.integers(0, 2000), st.integers(0, 5)), max_size=4),
    counted=st.sampled_from([0, 1, 1000]),
)
def test_suffix_order_of_repetitive_walks_against_plain_sorting(
    period: list[int], repeats: int, changes: list[tuple[int, int]], counted: int
) -> None:
    """A walk that repeats one loop, with a few changes, keeps long groups of suffixes
    together for many rounds: the ranks of every level, whether its round counted the pairs,
    sorted every suffix or only those still sharing a rank, are those of the prefixes
    sorted by plain Python; the last level orders the suffixes as Python's sort does."""
    from rsstp_replay.audits import _suffixes

    symbols = period * repeats
    for at, value in changes:
        symbols[at % len(symbols)] = value
    with mock.patch.object(_suffixes, "_COUNTED_PAIRS", counted):
        levels = _suffixes.suffix_ranks(np.array(symbols, dtype=np.int64))
    for level, ranks in enumerate(levels):
        prefixes = [tuple(symbols[p : p + 2**level]) for p in range(len(symbols))]
        rank_of = {prefix: rank for rank, prefix in enumerate(sorted(set(prefixes)))}
        assert ranks.tolist() == [rank_of[prefix] for prefix in prefixes]
    distinct = [len(set(ranks.tolist())) for ranks in levels]
    assert distinct[-1] == len(symbols) and all(d < len(symbols) for d in distinct[:-1])
    suffix_order = sorted(range(len(symbols)), key=lambda p: symbols[p:])
    assert np.argsort(levels[-1]).tolist() == suffix_order


@settings(max_examples=40, deadline=None)
@given(
    symbols=st.lists(st.integers(0, 3), min_size=2, max_size=600)
    | st.lists(st.integers(0, 700), min_size=2, max_size=600),
    seed=st.integers(0, 2**32 - 1),
)
def test_suffix_ranks_and_common_prefixes_against_brute_force(
    symbols: list[int], seed: int
) -> None:
    """The doubling levels, each in the narrowest type of its ranks (a byte, two, int32),
    order the prefixes as plain Python does; the common prefixes, a few pairs at a time,
    are the plain ones."""
    from rsstp_replay.audits import _suffixes

    levels = _suffixes.suffix_ranks(np.array(symbols, dtype=np.int64))
    for level, ranks in enumerate(levels):
        assert ranks.dtype == (np.uint8 if ranks.max() < 2**8 else np.uint16)
        prefixes = [tuple(symbols[p : p + 2**level]) for p in range(len(symbols))]
        order = sorted(set(prefixes))
        assert ranks.tolist() == [order.index(prefix) for prefix in prefixes]
    assert len(set(levels[-1].tolist())) == len(symbols)  # the last level: the suffix order
    rng = np.random.default_rng(seed)
    left, right = rng.integers(0, len(symbols), (2, 50))
    right = np.where(left == right, (right + 1) % len(symbols), right)
    with mock.patch.object(_suffixes, "_PAIRS_AT_ONCE", 7):
        found = _suffixes.common_prefix_lengths(left, right, levels)

    def common(p: int, q: int) -> int:
        length = 0
        while max(p, q) + length < len(symbols) and symbols[p + length] == symbols[q + length]:
            length += 1
        return length

    pairs = zip(left.tolist(), right.tolist(), strict=True)
    assert found.tolist() == [common(p, q) for p, q in pairs]
