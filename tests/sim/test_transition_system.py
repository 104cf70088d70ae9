"""Tests for the internal model: operations, views, formats, op log and invariants."""

from __future__ import annotations

import doctest
import json
from collections.abc import Callable

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_sim import transition_system
from rsstp_sim.errors import ModelError
from rsstp_sim.transition_system import DeterminismReport, Operation, TransitionSystem

FIGURE_16 = [
    [[0], [0, 1], [], []],
    [[0], [0], [0, 1], []],
    [[1], [], [], [0]],
    [[1], [0], [0, 1], []],
]


def test_docstring_examples_run() -> None:
    result = doctest.testmod(transition_system)
    assert result.attempted > 0
    assert result.failed == 0


# ------------------------------------------------------------ construction


def test_new_model_has_states_and_no_transitions() -> None:
    model = TransitionSystem(3, actions=[2, 0])
    assert model.states == (0, 1, 2)
    assert len(model) == 3
    assert 2 in model and 3 not in model and "0" not in model
    assert model.actions == (0, 2)
    assert model.transitions() == []
    assert model.current == 0
    assert model.version == 0
    assert model.next_id == 3
    assert model.drain_operations() == []


@pytest.mark.parametrize("n", [0, -1])
def test_new_model_needs_a_state(n: int) -> None:
    with pytest.raises(ModelError, match=f"n_states >= 1, got {n}"):
        TransitionSystem(n)


def test_new_model_refuses_negative_actions() -> None:
    with pytest.raises(ModelError, match=r"action must be an integer >= 0, got -1"):
        TransitionSystem(actions=[-1])


def test_universal_model_knows_nothing() -> None:
    model = TransitionSystem.universal([1, 0, 3])
    assert model.states == (0,)
    assert model.actions == (0, 1, 3)
    assert model.transitions() == [(0, 0, 0), (0, 1, 0), (0, 3, 0)]
    assert model.version == 0
    assert model.drain_operations() == []
    assert model.determinism_report().complete


def test_unknown_state_message_stays_short_on_big_models() -> None:
    with pytest.raises(ModelError, match=r"split: unknown state 99 \(30 states\)$"):
        TransitionSystem(30).split(99)


def test_current_setter_checks_the_state() -> None:
    model = TransitionSystem(2)
    model.current = 1
    assert model.current == 1
    with pytest.raises(ModelError, match=r"set current: unknown state 5"):
        model.current = 5
    assert model.current == 1


def test_repr_summarises() -> None:
    model = TransitionSystem.universal([0, 1])
    assert repr(model) == (
        "TransitionSystem(states=1, transitions=2, actions=(0, 1), current=0, version=0)"
    )


# -------------------------------------------------------------- add/delete


def test_add_and_delete_report_changes_and_log_only_changes() -> None:
    model = TransitionSystem(2)
    assert model.add(0, 1, 4) is True
    assert model.add(0, 1, 4) is False
    assert model.actions == (4,)
    assert model.successors(0, 4) == (1,)
    assert model.version == 1
    assert model.delete(0, 1, 4) is True
    assert model.delete(0, 1, 4) is False
    assert model.delete(0, 1, 7) is False
    assert model.successors(0, 4) == ()
    assert model.actions == (4,)  # the alphabet does not shrink
    assert model.version == 2
    assert model.drain_operations() == [
        Operation("add", (0, 1, 4), None),
        Operation("delete", (0, 1, 4), None),
    ]
    assert model.drain_operations() == []


def test_successors_are_sorted() -> None:
    model = TransitionSystem(4)
    for t in (3, 1, 2):
        model.add(0, t, 0)
    assert model.successors(0, 0) == (1, 2, 3)
    assert model.successors(0, 1) == ()
    assert model.successors(1, 0) == ()


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda m: m.successors(9, 0), r"successors: unknown state 9"),
        (lambda m: m.add(9, 0, 0), r"add: unknown state 9"),
        (lambda m: m.add(0, 9, 0), r"add: unknown state 9"),
        (lambda m: m.add(0, 1, -2), r"add: action must be an integer >= 0, got -2"),
        (lambda m: m.add(0, 1, 1.5), r"add: action must be an integer, got 1.5"),
        (lambda m: m.add(0, 1, True), r"add: action must be an integer, got True"),
        (lambda m: m.delete(9, 0, 0), r"delete: unknown state 9"),
        (lambda m: m.delete(0, 9, 0), r"delete: unknown state 9"),
        (lambda m: m.split(9), r"split: unknown state 9 \(states: \[0, 1\]\)"),
        (lambda m: m.merge(9, 0), r"merge: unknown state 9"),
        (lambda m: m.merge(0, 9), r"merge: unknown state 9"),
        (lambda m: m.merge(1, 1), r"merge: cannot merge state 1 with itself"),
        (lambda m: m.index_of(9), r"index_of: unknown state 9"),
        (lambda m: m.state_at(2), r"state_at: index 2 is not in range 0..1"),
        (lambda m: m.state_at(-1), r"state_at: index -1 is not in range 0..1"),
    ],
)
def test_bad_arguments_name_the_state_and_the_operation(
    call: Callable[[TransitionSystem], object], message: str
) -> None:
    model = TransitionSystem(2)
    before = model.copy()
    with pytest.raises(ModelError, match=message):
        call(model)
    assert model == before
    assert model.version == 0


# ------------------------------------------------------------- split/merge


def test_split_copies_transitions_in_and_out() -> None:
    model = TransitionSystem(3)
    model.add(0, 1, 0)
    model.add(2, 1, 1)
    model.add(1, 2, 0)
    new = model.split(1)
    assert new == 3
    assert model.next_id == 4
    assert model.transitions() == [
        (0, 0, 1),
        (0, 0, 3),
        (1, 0, 2),
        (2, 1, 1),
        (2, 1, 3),
        (3, 0, 2),
    ]
    assert model.drain_operations()[-1] == Operation("split", (1,), 3)


def test_split_of_a_self_loop_gives_four_transitions() -> None:
    model = TransitionSystem(1)
    model.add(0, 0, 0)
    model.drain_operations()
    assert model.split(0) == 1
    assert model.transitions() == [(0, 0, 0), (0, 0, 1), (1, 0, 0), (1, 0, 1)]
    assert model.to_matrix() == [[[0], [0]], [[0], [0]]]  # thesis: duplicate row and column
    assert model.current == 0
    assert model.drain_operations() == [Operation("split", (0,), 1)]


def test_split_ids_are_never_reused() -> None:
    model = TransitionSystem(2)
    assert model.split(1) == 2
    model.merge(0, 2)
    assert model.split(0) == 3
    assert model.states == (0, 1, 3)


def test_merge_unions_and_redirects() -> None:
    model = TransitionSystem(3)
    model.add(0, 1, 0)
    model.add(1, 1, 1)  # self-loop on t
    model.add(1, 0, 0)  # t -> s becomes s -> s
    model.add(1, 2, 1)
    model.add(2, 1, 0)
    model.add(0, 2, 1)
    assert model.merge(0, 1) == 0
    assert model.states == (0, 2)
    assert 1 not in model
    assert model.transitions() == [(0, 0, 0), (0, 1, 0), (0, 1, 2), (2, 0, 0)]
    assert model.drain_operations()[-1] == Operation("merge", (0, 1), 0)


def test_merge_moves_a_current_state_that_disappears() -> None:
    # Regression for defect 9: the original platform's merge left the current
    # state pointing past the end of the matrix.
    model = TransitionSystem(3)
    model.current = 2
    model.merge(1, 2)
    assert model.current == 1
    assert model.current in model
    assert model.successors(model.current, 0) == ()
    other = TransitionSystem(3)
    other.current = 2
    other.merge(2, 0)
    assert other.current == 2


def test_figure_9_split_then_merge() -> None:
    # Thesis Figure 9: node 0 is split, then nodes 0 and 2 are merged.
    model = TransitionSystem.from_matrix([[[0, 1], [1]], [[0], [0, 1]]])
    assert model.split(0) == 2
    assert model.to_matrix() == [
        [[0, 1], [1], [0, 1]],
        [[0], [0, 1], [0]],
        [[0, 1], [1], [0, 1]],
    ]
    model.merge(0, 2)
    assert model == TransitionSystem.from_matrix([[[0, 1], [1]], [[0], [0, 1]]])


# ---------------------------------------------------------- determinism


def test_determinism_report_on_a_nondeterministic_model() -> None:
    model = TransitionSystem.from_matrix(FIGURE_16)
    report = model.determinism_report()
    assert report == DeterminismReport(
        nondeterministic=((0, 0, (0, 1)), (1, 0, (0, 1, 2)), (3, 0, (1, 2)), (3, 1, (0, 2))),
        empty=(),
    )
    assert not report.deterministic
    assert not report.complete
    assert not model.is_deterministic()


def test_determinism_report_lists_empty_pairs_over_the_alphabet() -> None:
    model = TransitionSystem(2, actions=[0, 1, 2])
    model.add(0, 1, 0)
    model.add(1, 0, 1)
    report = model.determinism_report()
    assert report.nondeterministic == ()
    assert report.empty == ((0, 1), (0, 2), (1, 0), (1, 2))
    assert report.deterministic
    assert not report.complete
    assert model.is_deterministic()


def test_duplicated_label_in_one_cell_is_not_nondeterminism() -> None:
    # Regression for defect 10: from_matrix de-duplicates a label repeated in a cell.
    model = TransitionSystem.from_matrix([[[0, 0], [1]], [[1, 0, 1], []]])
    assert model.to_matrix() == [[[0], [1]], [[0, 1], []]]
    assert model.is_deterministic()
    assert model.determinism_report().complete


def test_is_deterministic_follows_every_operation() -> None:
    model = TransitionSystem(2)
    model.add(0, 0, 0)
    assert model.is_deterministic()
    model.add(0, 1, 0)
    assert not model.is_deterministic()
    model.delete(0, 0, 0)
    assert model.is_deterministic()
    model.add(1, 1, 0)
    model.split(1)  # 0 -0-> {1, 2}, 1 -0-> {1, 2}, 2 -0-> {1, 2}
    assert [r[:2] for r in model.determinism_report().nondeterministic] == [(0, 0), (1, 0), (2, 0)]
    assert not model.is_deterministic()
    model.merge(1, 2)
    assert model.is_deterministic()


# ---------------------------------------------------------------- matrix


def test_figure_16_matrix_round_trip() -> None:
    model = TransitionSystem.from_matrix(FIGURE_16)
    assert model.states == (0, 1, 2, 3)
    assert model.actions == (0, 1)
    assert model.to_matrix() == FIGURE_16
    assert (0, 1, 1) in model.transitions()
    assert TransitionSystem.from_matrix(model.to_matrix()) == model


def test_matrix_uses_the_dense_index_of_sparse_ids() -> None:
    model = TransitionSystem(3)
    model.add(2, 0, 1)
    model.merge(0, 1)
    assert model.states == (0, 2)
    assert model.index_of(2) == 1
    assert model.state_at(1) == 2
    assert model.to_matrix() == [[[], []], [[1], []]]


def test_from_matrix_keeps_given_actions_and_accepts_numpy_ints() -> None:
    np = pytest.importorskip("numpy")
    model = TransitionSystem.from_matrix([[[np.int64(1)]]], actions=[0, 3])
    assert model.actions == (0, 1, 3)
    assert model.transitions() == [(0, 1, 0)]
    assert type(model.transitions()[0][1]) is int


@pytest.mark.parametrize(
    ("matrix", "message"),
    [
        ([], r"the matrix is empty"),
        ([[[0], []]], r"row 0 must have 1 cells \(square matrix\)"),
        ([[[0], []], [[1]]], r"row 1 must have 2 cells"),
        ([[5]], r"cell \[0\]\[0\] must be a list, got 5"),
        ([["01"]], r"cell \[0\]\[0\] must be a list, got '01'"),
        ([[[-1]]], r"action in cell \[0\]\[0\] must be an integer >= 0, got -1"),
        ([[[0.5]]], r"action in cell \[0\]\[0\] must be an integer, got 0.5"),
    ],
)
def test_from_matrix_validates(matrix: object, message: str) -> None:
    with pytest.raises(ModelError, match=message):
        TransitionSystem.from_matrix(matrix)  # type: ignore[arg-type]


# ---------------------------------------------------------- copy and eq


def test_copy_is_deep_and_keeps_counters_but_not_the_log() -> None:
    model = TransitionSystem.universal([0, 1])
    model.split(0)
    model.current = 1
    clone = model.copy()
    assert clone == model
    assert (clone.version, clone.next_id, clone.current) == (1, 2, 1)
    assert clone.drain_operations() == []
    clone.delete(0, 1, 0)
    clone.add(0, 0, 5)
    assert clone != model
    assert model.successors(0, 0) == (0, 1)
    assert model.actions == (0, 1)
    assert len(model.drain_operations()) == 1


def test_equality_ignores_version_and_next_id_but_not_current() -> None:
    a = TransitionSystem(2, actions=[0])
    b = TransitionSystem(2)
    b.add(0, 1, 0)
    b.delete(0, 1, 0)
    assert a == b and a.version != b.version
    b.current = 1
    assert a != b
    assert TransitionSystem(1, actions=[0]) != TransitionSystem(1)
    assert a != "not a model"
    with pytest.raises(TypeError):
        hash(a)


# --------------------------------------------------------- op log/apply


def assert_replays_to(
    start: TransitionSystem, ops: list[Operation], model: TransitionSystem
) -> None:
    """Applying ``ops`` to ``start`` gives ``model`` (its current state set by hand): equal,
    with the same version and the same next id."""
    for op in ops:
        start.apply(op)
    start.current = model.current  # setting current is not an operation
    assert start == model
    assert start.version == model.version
    assert start.next_id == model.next_id


def test_apply_replays_the_log_to_an_equal_model() -> None:
    model = TransitionSystem.universal([0, 1])
    start = model.copy()
    s1 = model.split(0)
    model.delete(0, s1, 1)
    model.add(s1, s1, 2)
    s2 = model.split(s1)
    model.current = s2
    model.merge(s1, s2)
    ops = model.drain_operations()
    assert [op.kind for op in ops] == ["split", "delete", "add", "split", "merge"]
    assert model.version == 5
    assert_replays_to(start, ops, model)
    assert start.drain_operations() == ops


def test_apply_of_a_no_op_changes_nothing() -> None:
    model = TransitionSystem(2)
    model.add(0, 1, 0)
    model.drain_operations()
    model.apply(Operation("add", (0, 1, 0), None, changed=False))
    model.apply(Operation("delete", (1, 0, 0), None, changed=False))
    assert model.version == 1
    assert model.drain_operations() == []


@pytest.mark.parametrize(
    ("op", "message"),
    [
        (
            Operation("split", (0,), 5),
            r"split of state 0 recorded new state 5, .*next id here is 2",
        ),
        (Operation("split", (0, 1), 2), r"split takes 1 arguments"),
        (Operation("merge", (0, 1), 1), r"merge\(0, 1\) recorded result 1, not 0"),
        (Operation("merge", (0,), 0), r"merge takes 2 arguments"),
        (Operation("add", (0, 1, 0), None), r"add\(0, 1, 0\) recorded changed=True, .*exists"),
        (Operation("add", (1, 1, 0), None, False), r"changed=False, .*does not exist"),
        (Operation("delete", (1, 0, 0), None), r"delete\(1, 0, 0\) .* does not exist"),
        (Operation("delete", (0, 1, 0), None, False), r"changed=False, .*already exists"),
        (Operation("add", (0, 7, 0), None), r"apply add: unknown state 7"),
        (Operation("split", (7,), 2), r"apply split: unknown state 7"),
        (Operation("merge", (0, 7), 0), r"apply merge: unknown state 7"),
        (Operation("rename", (0,), None), r"unknown operation kind 'rename'"),  # type: ignore[arg-type]
    ],
)
def test_apply_refuses_inconsistent_operations(op: Operation, message: str) -> None:
    model = TransitionSystem(2)
    model.add(0, 1, 0)
    before = model.copy()
    with pytest.raises(ModelError, match=message):
        model.apply(op)
    assert model == before
    assert model.version == before.version


# -------------------------------------------------------------- snapshot


def test_snapshot_is_json_ready_and_round_trips() -> None:
    model = TransitionSystem.from_matrix(FIGURE_16, actions=[0, 1, 2])
    model.merge(0, 1)
    model.split(2)
    model.current = 4
    data = model.snapshot()
    assert data == {
        "states": [0, 2, 3, 4],
        "next_id": 5,
        "current": 4,
        "actions": [0, 1, 2],
        "transitions": [[s, a, t] for s, a, t in model.transitions()],
    }
    again = TransitionSystem.from_snapshot(json.loads(json.dumps(data)), version=7)
    assert again == model
    assert again.version == 7
    assert again.next_id == 5
    assert again.is_deterministic() == model.is_deterministic()
    assert again.split(0) == 5


def _snapshot(**changes: object) -> dict[str, object]:
    data: dict[str, object] = {
        "states": [0, 2],
        "next_id": 3,
        "current": 2,
        "actions": [0],
        "transitions": [[0, 0, 2]],
    }
    data.update(changes)
    return {k: v for k, v in data.items() if v is not None}


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (_snapshot(states=None), r"missing key 'states'"),
        (_snapshot(states=[]), r"states must be distinct non-negative ids"),
        (_snapshot(states=[0, 0]), r"states must be distinct"),
        (_snapshot(states="02"), r"states must be a list, got '02'"),
        (_snapshot(next_id=2), r"next_id 2 must exceed every state id"),
        (_snapshot(current=1), r"current 1 is not one of the states"),
        (_snapshot(actions=[-1]), r"actions\[\] must be an integer >= 0"),
        (_snapshot(transitions=[[0, 0]]), r"transitions\[0\] must be \[source, action, target\]"),
        (_snapshot(transitions=[[0, 0, 1]]), r"transitions\[0\] refers to an unknown state"),
        (_snapshot(transitions=[[0, 3, 2]]), r"transitions\[0\] uses action 3, not in actions"),
        (_snapshot(transitions=[[0, "a", 2]]), r"transitions\[0\] action must be an integer"),
    ],
)
def test_from_snapshot_validates(data: dict[str, object], message: str) -> None:
    with pytest.raises(ModelError, match=message):
        TransitionSystem.from_snapshot(data)


# ------------------------------------------------------- property tests


@st.composite
def models(draw: st.DrawFn, max_states: int = 4) -> TransitionSystem:
    n = draw(st.integers(1, max_states))
    model = TransitionSystem(n, actions=[0, 1])
    edges = draw(
        st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1), st.integers(0, 2)))
    )
    for s, t, a in edges:
        model.add(s, t, a)
    model.current = draw(st.integers(0, n - 1))
    model.drain_operations()
    return model


# Each op picks its states by position in the current state list, so every
# drawn sequence is valid whatever the model looks like when it runs.
_ops = st.lists(
    st.tuples(
        st.sampled_from(["add", "delete", "split", "merge", "current"]),
        st.integers(0, 50),
        st.integers(0, 50),
        st.integers(0, 2),
    ),
    max_size=25,
)


def _run(model: TransitionSystem, ops: list[tuple[str, int, int, int]]) -> None:
    for kind, i, j, a in ops:
        states = model.states
        s, t = states[i % len(states)], states[j % len(states)]
        if kind == "add":
            model.add(s, t, a)
        elif kind == "delete":
            model.delete(s, t, a)
        elif kind == "split":
            if len(model) < 8:
                model.split(s)
        elif kind == "merge":
            if s != t:
                model.merge(s, t)
        else:
            model.current = s
        assert model.is_deterministic() == model.determinism_report().deterministic
        assert model.current in model


@settings(max_examples=150, deadline=None)
@given(models(), _ops)
def test_replaying_drained_operations_rebuilds_the_model(
    model: TransitionSystem, ops: list[tuple[str, int, int, int]]
) -> None:
    before = model.copy()
    version = model.version
    _run(model, ops)
    logged = model.drain_operations()
    assert model.version == version + len(logged)
    assert all(op.changed for op in logged)
    assert_replays_to(before, logged, model)
    assert before.snapshot() == model.snapshot()


@settings(max_examples=150, deadline=None)
@given(models(), _ops)
def test_transition_columns_follow_every_operation(
    model: TransitionSystem, ops: list[tuple[str, int, int, int]]
) -> None:
    # The columns a model message is built from, kept per state between changes, are at every
    # moment the model's transitions read afresh from its successors, sorted; a copy keeps them.
    for op in ops:
        model.transition_columns()  # (kept before the change)
        _run(model, [op])
        if op[1] % 5 == 0:
            model = model.copy()
        expected = sorted(
            (u, b, v) for u in model.states for b in model.actions for v in model.successors(u, b)
        )
        assert list(zip(*model.transition_columns(), strict=True)) == expected


@settings(max_examples=150, deadline=None)
@given(models(), _ops, st.integers(0, 25))
def test_predecessors_follow_every_operation_of_a_copy(
    model: TransitionSystem, ops: list[tuple[str, int, int, int]], asked_after: int
) -> None:
    # A copy (and a model from columns) builds its predecessors only when first asked: the
    # changes made before and after that must all show, and the original must not move.
    original = model.snapshot()
    copy = model.copy()
    for k, op in enumerate(ops):
        if k == asked_after:
            copy.predecessors(copy.states[0])
        _run(copy, [op])
    transitions = [
        (u, b, v) for u in copy.states for b in copy.actions for v in copy.successors(u, b)
    ]
    for state in copy.states:
        assert copy.predecessors(state) == {u for u, _, v in transitions if v == state}
        assert copy.transitions_into(state) == sorted(
            (u, b) for u, b, v in transitions if v == state
        )
    assert model.snapshot() == original


@settings(max_examples=150, deadline=None)
@given(models(), _ops)
def test_incremental_determinism_matches_the_report(
    model: TransitionSystem, ops: list[tuple[str, int, int, int]]
) -> None:
    _run(model, ops)
    report = model.determinism_report()
    pairs = {(s, a): model.successors(s, a) for s in model.states for a in model.actions}
    assert report.deterministic == all(len(v) <= 1 for v in pairs.values())
    assert report.empty == tuple(sorted(k for k, v in pairs.items() if not v))


@settings(max_examples=150, deadline=None)
@given(models(), st.data())
def test_split_then_merge_gives_back_the_original(
    model: TransitionSystem, data: st.DataObject
) -> None:
    s = data.draw(st.sampled_from(model.states))
    original = model.copy()
    new = model.split(s)
    assert model.current == original.current
    for a in model.actions:
        expected = set(original.successors(s, a))
        if s in expected:
            expected.add(new)
        assert set(model.successors(new, a)) == expected
        assert set(model.successors(s, a)) == expected
    assert model.merge(s, new) == s
    assert model == original
    assert model.is_deterministic() == original.is_deterministic()


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.sampled_from(["split", "merge", "add", "delete"]), st.integers(0, 50)),
        max_size=40,
    )
)
def test_from_columns_is_from_snapshot_without_the_checks(steps: list[tuple[str, int]]) -> None:
    """A model built from its checked columns behaves as the one rebuilt from its snapshot:
    the same snapshot, determinism, predecessors, and the same answers to further changes."""
    model = TransitionSystem.universal((0, 1, 2))
    for kind, seed in steps:
        states = model.states
        s, t = states[seed % len(states)], states[(seed // 7) % len(states)]
        if kind == "split":
            model.split(s)
        elif kind == "merge" and s != t:
            model.merge(s, t)
        elif kind == "add":
            model.add(s, t, seed % 3)
        elif kind == "delete":
            model.delete(s, t, seed % 3)
    checked = TransitionSystem.from_snapshot(model.snapshot(), version=model.version)
    fast = TransitionSystem.from_columns(
        model.states,
        model.actions,
        model.transition_columns(),
        next_id=model.next_id,
        current=model.current,
        version=model.version,
    )
    assert fast.snapshot() == checked.snapshot()
    assert fast.version == checked.version
    assert fast.nondeterministic_pairs == checked.nondeterministic_pairs
    for state in model.states:
        assert fast.predecessors(state) == checked.predecessors(state)
    for built in (fast, checked):
        new = built.split(model.states[0])
        built.add(new, model.states[-1], 1)
    assert fast.snapshot() == checked.snapshot()
