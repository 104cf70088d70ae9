"""``distinct``: the sorted distinct values of an integer array, as ``np.unique`` gives them."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from rsstp_sim.arrays import distinct


@settings(max_examples=200, deadline=None)
@given(
    hnp.arrays(
        st.sampled_from([np.int64, np.int32, np.uint8]),
        hnp.array_shapes(min_dims=1, max_dims=2, min_side=0, max_side=40),
    )
)
def test_distinct_is_the_sorted_set_of_the_values(values: np.ndarray) -> None:
    expected = sorted({int(v) for v in values.ravel().tolist()})
    found = distinct(values)
    assert found.dtype == values.dtype
    assert found.tolist() == expected


def test_distinct_of_values_near_the_int64_ends() -> None:
    values = np.array([2**63 - 1, -(2**63), 0, 2**63 - 1, -1, -(2**63)], np.int64)
    assert distinct(values).tolist() == [-(2**63), -1, 0, 2**63 - 1]
