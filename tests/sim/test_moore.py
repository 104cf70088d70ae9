"""The one minimisation (:mod:`rsstp_sim.moore`) against table filling on random machines."""

from __future__ import annotations

import doctest
import itertools
from collections.abc import Sequence

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_sim import moore
from rsstp_sim.moore import moore_classes


def naive_equivalence(next_state: Sequence[Sequence[int]], labels: Sequence[bool]) -> list[int]:
    """Equivalence of the states of a Moore machine by table filling (class = least member)."""
    n = len(labels)
    apart = {(p, q) for p in range(n) for q in range(n) if labels[p] != labels[q]}
    changed = True
    while changed:
        changed = False
        for p, q in itertools.product(range(n), repeat=2):
            if (p, q) not in apart and any(
                (row_p, row_q) in apart
                for row_p, row_q in zip(next_state[p], next_state[q], strict=True)
            ):
                apart.add((p, q))
                changed = True
    return [min(q for q in range(n) if (p, q) not in apart) for p in range(n)]


def test_doctests() -> None:
    assert doctest.testmod(moore).failed == 0


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_refinement_matches_table_filling(data: st.DataObject) -> None:
    n = data.draw(st.integers(1, 8))
    n_actions = data.draw(st.integers(1, 3))
    next_state = data.draw(
        st.lists(
            st.lists(st.integers(0, n - 1), min_size=n_actions, max_size=n_actions),
            min_size=n,
            max_size=n,
        )
    )
    labels = data.draw(st.lists(st.booleans(), min_size=n, max_size=n))
    classes = moore_classes(np.array(next_state, dtype=np.int64), np.array(labels))
    expected = naive_equivalence(next_state, labels)
    for p, q in itertools.product(range(n), repeat=2):
        assert (classes[p] == classes[q]) == (expected[p] == expected[q])
