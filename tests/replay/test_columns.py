"""Per-step columns reduced without sorting (:mod:`rsstp_replay.audits._columns`), against
numpy's sorting answers."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from rsstp_replay.audits._columns import factorized

columns = st.one_of(
    hnp.arrays(st.sampled_from([np.int8, np.int16, np.int32, np.int64]), st.integers(0, 60),
               elements=st.integers(0, 100)),  # small ids: the table
    hnp.arrays(np.int64, st.integers(0, 60), elements=st.integers(-(2**40), 2**40)),  # sorted
    hnp.arrays(np.int64, st.integers(1, 60), elements=st.integers(2**16, 2**16 + 300)),
)  # fmt: skip


@settings(max_examples=300, deadline=None)
@given(columns)
def test_factorized_is_numpys_unique_with_the_inverse(values: np.ndarray) -> None:
    distinct, inverse = factorized(values)
    expected_distinct, expected_inverse = np.unique(values, return_inverse=True)
    assert distinct.dtype == values.dtype
    assert distinct.tolist() == expected_distinct.tolist()
    assert inverse.tolist() == expected_inverse.tolist()
    assert (distinct[inverse] == values).all()
