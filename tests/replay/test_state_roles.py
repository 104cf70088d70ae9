"""State roles (exact, redundant, aliased, unvisited) against a brute force over the steps."""

from __future__ import annotations

from collections import defaultdict

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_replay.audits.state_roles import (
    ALIASED,
    EXACT,
    REDUNDANT,
    ROLE_NAMES,
    UNVISITED,
    state_roles,
)
from rsstp_sim.errors import MemoryRangeError


def brute_force(steps: list[tuple[int, int, int]], queries: list[tuple[int, int]]) -> list[str]:
    """The role of each (version, state) query, by the definitions, with sets."""
    classes: dict[tuple[int, int], set[int]] = defaultdict(set)
    for version, state, true_class in steps:
        classes[version, state].add(true_class)
    names = []
    for version, state in queries:
        mine = classes.get((version, state), set())
        if not mine:
            names.append("unvisited")
        elif len(mine) > 1:
            names.append("aliased")
        else:
            (only,) = mine
            others = [
                s for (v, s), cs in classes.items() if v == version and s != state and only in cs
            ]
            names.append("redundant" if others else "exact")
    return names


small = st.integers(min_value=0, max_value=4)


@settings(max_examples=300, deadline=None)
@given(
    steps=st.lists(st.tuples(small, st.integers(0, 6), small), max_size=40),
    queries=st.lists(st.tuples(st.integers(0, 5), st.integers(0, 7)), max_size=20),
)
def test_roles_match_a_brute_force(
    steps: list[tuple[int, int, int]], queries: list[tuple[int, int]]
) -> None:
    array = np.array(steps, np.int64).reshape(-1, 3)
    roles = state_roles(
        array[:, 0],
        array[:, 1] * 1000,  # state ids need not be small or dense
        array[:, 2] - 7,
        versions=[v for v, _ in queries],
        states=[s * 1000 for _, s in queries],
    )
    assert [ROLE_NAMES[r] for r in roles] == brute_force(steps, queries)


def test_a_worked_example() -> None:
    # Version 1: state 10 at classes 5 and 6 (aliased); states 11 and 12 both at class 7
    # (redundant); state 13 alone at class 8 (exact); state 14 never visited. In version 2,
    # state 11 alone at class 7: exact there.
    versions = [1, 1, 1, 1, 1, 2, 2]
    states = [10, 10, 11, 12, 13, 11, 10]
    classes = [5, 6, 7, 7, 8, 7, 5]
    roles = state_roles(
        versions,
        states,
        classes,
        versions=[1, 1, 1, 1, 1, 2, 2],
        states=[10, 11, 12, 13, 14, 11, 12],
    )
    assert roles.tolist() == [ALIASED, REDUNDANT, REDUNDANT, EXACT, UNVISITED, EXACT, UNVISITED]


def test_arrays_of_different_lengths_are_an_error() -> None:
    with pytest.raises(MemoryRangeError, match="different lengths: 2, 1, 1"):
        state_roles([1, 2], [1], [1], versions=[], states=[])
    with pytest.raises(MemoryRangeError, match="2 versions for 1 states"):
        state_roles([1], [1], [1], versions=[1, 2], states=[1])
