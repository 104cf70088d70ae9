"""The agent's memory: storage, views, growth, compare (thesis 4.2), conversions."""

from __future__ import annotations

import doctest

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rsstp_sim.memory
from rsstp_sim.errors import MemoryRangeError
from rsstp_sim.memory import NO_ACTION, CompareKind, CompareResult, Memory, MemoryEntry


def build(entries: list[tuple[int, int, bool]], *, start: tuple[int, bool] = (0, False)) -> Memory:
    """A memory from a reset ``(state, sensation)`` and steps ``(action, state, sensation)``."""
    memory = Memory(capacity=2)
    memory.reset(start[0], start[1], 0.0)
    for t, (action, state, sensation) in enumerate(entries, start=1):
        memory.append(action, state, sensation, t / (t + 1))
    return memory


def figure_11() -> Memory:
    """The thesis's Figure 11: six entries, compare(2, 0) differs in sensation at offset 2."""
    return build([(1, 0, True), (0, 0, False), (1, 0, True), (0, 0, True), (1, 0, True)])


# -- storage -----------------------------------------------------------------------------------


def test_empty_memory() -> None:
    memory = Memory()
    assert len(memory) == 0
    assert memory.steps == -1
    assert memory.actions.shape == (0,)
    assert memory.actions.dtype == np.int32
    with pytest.raises(MemoryRangeError, match=r"memory index 0 out of range: .*empty"):
        memory[0]


def test_reset_and_append() -> None:
    memory = Memory()
    memory.reset(7, True, 0.25)
    memory.append(3, 8, False, 0.5)
    memory.append(0, 7, True, 1.0)
    assert len(memory) == 3
    assert memory.steps == 2
    assert memory[0] == MemoryEntry(action=None, internal_state=7, sensation=True, feedback=0.25)
    assert memory[1] == MemoryEntry(action=3, internal_state=8, sensation=False, feedback=0.5)
    assert memory[-1] == MemoryEntry(action=0, internal_state=7, sensation=True, feedback=1.0)
    assert memory[-3] == memory[0]
    assert memory.actions.tolist() == [NO_ACTION, 3, 0]
    assert memory.internal_states.tolist() == [7, 8, 7]
    assert memory.sensations.tolist() == [True, False, True]
    assert memory.feedback.tolist() == [0.25, 0.5, 1.0]
    assert [entry.action for entry in memory] == [None, 3, 0]
    entry = memory[2]
    assert type(entry.action) is int and type(entry.internal_state) is int
    assert type(entry.sensation) is bool and type(entry.feedback) is float


def test_last_entry_without_a_view() -> None:
    memory = Memory(capacity=1)
    for name in ("last_state", "last_sensation", "last_feedback"):
        with pytest.raises(MemoryRangeError, match=f"{name} of an empty memory"):
            getattr(memory, name)
    memory.reset(7, True, 0.25)
    assert (memory.last_state, memory.last_sensation, memory.last_feedback) == (7, True, 0.25)
    memory.append(3, 8, False, 0.5)  # (past the capacity: the buffers grew)
    assert (memory.last_state, memory.last_sensation, memory.last_feedback) == (8, False, 0.5)
    assert type(memory.last_sensation) is bool and type(memory.last_feedback) is float


def test_column_dtypes() -> None:
    memory = build([(1, 2, True)])
    assert memory.actions.dtype == np.int32
    assert memory.internal_states.dtype == np.int64
    assert memory.sensations.dtype == np.bool_
    assert memory.feedback.dtype == np.float64


def test_reset_twice_is_refused() -> None:
    memory = build([])
    with pytest.raises(MemoryRangeError, match="reset writes entry 0 of an empty memory"):
        memory.reset(0, False, 0.0)


def test_append_before_reset_is_refused() -> None:
    memory = Memory()
    with pytest.raises(MemoryRangeError, match=r"append before reset"):
        memory.append(0, 0, False, 0.0)
    assert len(memory) == 0


@pytest.mark.parametrize("capacity", [0, -3])
def test_capacity_must_be_positive(capacity: int) -> None:
    with pytest.raises(MemoryRangeError, match=f"capacity must be at least 1, got {capacity}"):
        Memory(capacity=capacity)


@pytest.mark.parametrize("index", [3, -4, 100])
def test_getitem_out_of_range(index: int) -> None:
    memory = build([(0, 0, False), (1, 0, True)])
    with pytest.raises(MemoryRangeError, match=rf"index {index} out of range: .*0 \.\. 2 or -3"):
        memory[index]


def test_views_are_read_only() -> None:
    memory = build([(0, 1, True)])
    for column in (memory.actions, memory.internal_states, memory.sensations, memory.feedback):
        with pytest.raises(ValueError, match="read-only"):
            column[0] = 1
    assert memory.internal_states.tolist() == [0, 1]


def test_growth_past_capacity_keeps_every_entry() -> None:
    memory = Memory(capacity=1)
    memory.reset(0, False, 0.0)
    early_view = memory.internal_states
    for t in range(1, 1000):
        memory.append(t % 4, t, t % 3 == 0, t / 1000)
    assert len(memory) == 1000
    assert memory.internal_states.tolist() == list(range(1000))
    assert memory.actions.tolist() == [NO_ACTION] + [t % 4 for t in range(1, 1000)]
    assert memory.sensations.tolist() == [False] + [t % 3 == 0 for t in range(1, 1000)]
    assert memory.feedback[1:].tolist() == [t / 1000 for t in range(1, 1000)]
    assert early_view.tolist() == [0]  # a view shows what it covered, not later appends


def test_instances_do_not_share_entries() -> None:
    """Defect 6: the original memory was one class-level list shared by every arm."""
    first, second = Memory(), Memory()
    first.reset(1, True, 1.0)
    first.append(0, 2, False, 0.5)
    assert len(second) == 0
    second.reset(5, False, 0.0)
    assert len(first) == 2
    assert first.internal_states.tolist() == [1, 2]
    assert second.internal_states.tolist() == [5]


def test_equality() -> None:
    assert figure_11() == figure_11()
    assert build([(0, 1, True)]) != build([(0, 1, False)])
    assert build([(0, 1, True)]) != build([(0, 1, True), (0, 1, True)])
    assert Memory() == Memory()
    assert figure_11() != "memory"
    other = build([(0, 1, True)])
    same = Memory.from_arrays(
        other.actions,
        other.internal_states,
        other.sensations,
        other.feedback.copy() + np.r_[0.0, 1e-12],
    )
    assert other != same  # feedback is compared exactly


# -- compare -----------------------------------------------------------------------------------


def test_compare_figure_11() -> None:
    assert figure_11().compare(2, 0) == CompareResult(
        CompareKind.DIFFERENT_SENSATION, offset=2, length=4, n=2, m=0
    )
    assert figure_11().compare(0, 2) == CompareResult(
        CompareKind.DIFFERENT_SENSATION, offset=2, length=4, n=0, m=2
    )


def test_compare_unknown_when_actions_differ() -> None:
    memory = build([(0, 0, False), (1, 0, True), (1, 0, False)])
    assert memory.compare(0, 1) == CompareResult(CompareKind.UNKNOWN, 1, 3, 0, 1)


def test_compare_different_state() -> None:
    memory = build([(0, 1, False), (0, 2, False), (0, 1, False)])
    # entries 1 and 3: same state 1; then entry 2 (state 2) vs nothing: length 1 only.
    assert memory.compare(1, 3) == CompareResult(CompareKind.IDENTICAL, 1, 1, 1, 3)
    # entries 0 and 1: states 0 and 1 differ at offset 0.
    assert memory.compare(0, 1) == CompareResult(CompareKind.DIFFERENT_STATE, 0, 3, 0, 1)
    # entries 1, 2 vs 2, 3: states 1 vs 2 at offset 0.
    assert memory.compare(1, 2).kind is CompareKind.DIFFERENT_STATE


def test_compare_state_is_checked_before_sensation() -> None:
    memory = build([(0, 0, False), (0, 1, True), (0, 0, False), (0, 2, False)])
    # offset 1: entries 2 and 4: same action 0, states 1 vs 2 and sensations True vs False.
    assert memory.compare(1, 3) == CompareResult(CompareKind.DIFFERENT_STATE, 1, 2, 1, 3)


def test_compare_identical_offset_is_length() -> None:
    memory = build([(0, 0, False), (0, 0, False), (0, 0, False), (0, 0, False)])
    assert memory.compare(0, 2) == CompareResult(CompareKind.IDENTICAL, 3, 3, 0, 2)
    assert memory.compare(4, 3) == CompareResult(CompareKind.IDENTICAL, 1, 1, 4, 3)


def test_compare_ignores_actions_at_offset_zero() -> None:
    """The action of the starting entry led there: it is outside the sub-memory."""
    memory = build([(0, 5, True), (1, 5, True), (2, 5, True), (1, 5, True)])
    # Entries 1 and 3 were reached by actions 0 and 2, then both take action 1.
    assert memory.compare(1, 3) == CompareResult(CompareKind.IDENTICAL, 2, 2, 1, 3)
    # The reset's missing action is no difference either.
    start = build([(3, 0, False), (3, 0, False)], start=(0, False))
    assert start.compare(0, 1) == CompareResult(CompareKind.IDENTICAL, 2, 2, 0, 1)


def test_compare_ignores_feedback() -> None:
    memory = build([(0, 0, False), (0, 0, False)])  # feedback differs at every entry
    assert memory.compare(0, 1).kind is CompareKind.IDENTICAL


@pytest.mark.parametrize(
    ("n", "m", "message"),
    [
        (1, 1, r"compare\(1, 1\): the starts must differ"),
        (-1, 0, r"compare\(-1, 0\): both starts must be in 0 \.\. 5 \(the memory has 6 entries\)"),
        (0, 6, r"compare\(0, 6\): both starts must be in 0 \.\. 5"),
        (9, 9, r"compare\(9, 9\): both starts must be in 0 \.\. 5"),
    ],
)
def test_compare_errors(n: int, m: int, message: str) -> None:
    with pytest.raises(MemoryRangeError, match=message):
        figure_11().compare(n, m)


def test_compare_on_empty_memory() -> None:
    with pytest.raises(
        MemoryRangeError, match=r"both starts must be in none \(the memory is empty"
    ):
        Memory().compare(0, 1)


def reference_compare(memory: Memory, n: int, m: int) -> tuple[CompareKind, int]:
    length = len(memory) - max(n, m)
    for offset in range(length):
        first, second = memory[n + offset], memory[m + offset]
        if offset > 0 and first.action != second.action:
            return CompareKind.UNKNOWN, offset
        if first.internal_state != second.internal_state:
            return CompareKind.DIFFERENT_STATE, offset
        if first.sensation != second.sensation:
            return CompareKind.DIFFERENT_SENSATION, offset
    return CompareKind.IDENTICAL, length


small_steps = st.lists(
    st.tuples(st.integers(0, 2), st.integers(0, 2), st.booleans()), min_size=1, max_size=25
)


@settings(max_examples=300, deadline=None)
@given(steps=small_steps, data=st.data())
def test_compare_matches_reference(steps: list[tuple[int, int, bool]], data: st.DataObject) -> None:
    memory = build(steps)
    n = data.draw(st.integers(0, memory.steps))
    m = data.draw(st.integers(0, memory.steps).filter(lambda x: x != n))
    result = memory.compare(n, m)
    assert (result.kind, result.offset) == reference_compare(memory, n, m)
    assert result.length == len(memory) - max(n, m)
    assert (result.n, result.m) == (n, m)


# -- conversions -------------------------------------------------------------------------------


def test_to_dataframe() -> None:
    frame = figure_11().to_dataframe()
    assert list(frame.columns) == ["action", "internal_state", "sensation", "feedback"]
    assert frame.dtypes.astype(str).tolist() == ["Int64", "int64", "bool", "float64"]
    assert frame.index.name == "step" and frame.index.tolist() == list(range(6))
    assert frame["action"].isna().tolist() == [True] + [False] * 5
    assert frame["action"].iloc[1:].tolist() == [1, 0, 1, 0, 1]
    assert frame["sensation"].tolist() == [False, True, False, True, True, True]


def test_to_dataframe_is_a_copy() -> None:
    memory = figure_11()
    frame = memory.to_dataframe()
    memory.append(0, 9, False, 0.0)
    frame.loc[0, "internal_state"] = 42
    assert len(frame) == 6
    assert memory.internal_states[0] == 0


def test_to_dataframe_of_empty_memory() -> None:
    frame = Memory().to_dataframe()
    assert len(frame) == 0
    assert frame.dtypes.astype(str).tolist() == ["Int64", "int64", "bool", "float64"]


def test_until_is_the_memory_at_the_end_of_a_step() -> None:
    memory = figure_11()
    earlier = memory.until(2)
    assert len(earlier) == 3 and list(earlier) == list(memory)[:3]
    assert memory.until(len(memory) - 1) == memory
    earlier.append(0, 7, False, 0.0)  # a copy: the memory it came from does not change
    assert len(memory) == 6
    for step in (-1, 6):
        with pytest.raises(MemoryRangeError, match=rf"until: step {step} is not in 0\.\.5"):
            memory.until(step)


@settings(max_examples=100, deadline=None)
@given(steps=small_steps)
def test_from_arrays_round_trip(steps: list[tuple[int, int, bool]]) -> None:
    memory = build(steps)
    rebuilt = Memory.from_arrays(
        memory.actions, memory.internal_states, memory.sensations, memory.feedback
    )
    assert rebuilt == memory
    frame = memory.to_dataframe()
    from_frame = Memory.from_arrays(
        frame["action"].fillna(NO_ACTION).to_numpy(dtype=np.int64),
        frame["internal_state"].to_numpy(),
        frame["sensation"].to_numpy(),
        frame["feedback"].to_numpy(),
    )
    assert from_frame == memory
    rebuilt.append(0, 0, True, 0.5)  # a rebuilt memory keeps growing
    assert len(rebuilt) == len(memory) + 1


def test_from_arrays_accepts_lists_and_empty_columns() -> None:
    memory = Memory.from_arrays([-1, 2], [0, 1], [False, True], [0.0, 1.0])
    assert memory[1] == MemoryEntry(2, 1, True, 1.0)
    assert len(Memory.from_arrays([], [], [], [])) == 0


@pytest.mark.parametrize(
    ("columns", "message"),
    [
        (([-1, 0], [0], [False, True], [0.0, 0.0]), "the columns must have the same length"),
        (([[-1, 0]], [[0, 0]], [[False, True]], [[0.0, 0.0]]), "actions: expected a one-dim"),
        (([-1.0, 0.0], [0, 0], [False, True], [0.0, 0.0]), "actions: expected an integer dtype"),
        (([-1, 0], [0.5, 0], [False, True], [0.0, 0.0]), "internal_states: expected an integer"),
        (([-1, 0], [0, 0], [0, 1], [0.0, 0.0]), "sensations: expected a bool dtype, got int64"),
        (([-1, 0], [0, 0], [False, True], ["a", "b"]), "feedback: expected a real dtype"),
        (([0, 0], [0, 0], [False, True], [0.0, 0.0]), r"actions\[0\] must be -1 .*got 0"),
        (([-1, 0, -2], [0, 0, 0], [False, True, True], [0.0] * 3), r"actions\[2\] = -2"),
        (([-1, 2**31], [0, 0], [False, True], [0.0, 0.0]), r"actions\[1\] = 2147483648"),
        (([-1, 0], [0, 0], [False, True], [0.0, 1.5]), r"feedback\[1\] = 1.5 is outside"),
        (([-1, 0], [0, 0], [False, True], [np.nan, 0.5]), r"feedback\[0\] = nan is outside"),
    ],
)
def test_from_arrays_validation(columns: tuple[object, ...], message: str) -> None:
    with pytest.raises(MemoryRangeError, match=message):
        Memory.from_arrays(*columns)  # type: ignore[arg-type]


def test_docstring_examples() -> None:
    results = doctest.testmod(rsstp_sim.memory)
    assert results.attempted > 0
    assert results.failed == 0


def test_dataframe_type() -> None:
    assert isinstance(figure_11().to_dataframe(), pd.DataFrame)
