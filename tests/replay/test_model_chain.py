"""The model versions kept as changes: every version rebuilt from them, whole, as a model or
as arrays, is the model its operations made (against a replay of the operations by hand)."""

from __future__ import annotations

from pathlib import Path

import pytest
from fakes import FakeRecording, RandomRefiner
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_format.records import ModelRecord, TransitionsRecord
from rsstp_format.vocabulary import Operation
from rsstp_replay import open_recording
from rsstp_replay.audits import audit_truth, run_audits
from rsstp_replay.audits.determinism import audit_determinism
from rsstp_replay.audits.loaded import load
from rsstp_replay.reader import DeterminismPart
from rsstp_replay.reader._models import ModelHistory, model_history
from rsstp_replay.viewer import view
from rsstp_sim import load_scenario
from rsstp_sim.recording.builders import model_record
from rsstp_sim.transition_system import TransitionSystem

LEARNER = Path(__file__).resolve().parents[2] / "recordings" / "two-joint-30-learner.mcap"


def as_record(model: TransitionSystem) -> TransitionsRecord:
    triples = model.transitions()
    return TransitionsRecord(
        source=tuple(s for s, _, _ in triples),
        action=tuple(a for _, a, _ in triples),
        target=tuple(t for _, _, t in triples),
    )


def random_operations(data: st.DataObject, model: TransitionSystem) -> set[int]:
    """One to four random operations on ``model``; the states whose transitions they touched."""
    touched: set[int] = set()
    for _ in range(data.draw(st.integers(1, 4))):
        states = model.states
        kind = data.draw(st.sampled_from(["add", "delete", "split", "merge"]))
        if kind == "merge" and len(states) < 2:
            continue
        s = data.draw(st.sampled_from(states))
        if kind == "split":
            touched |= model.sources_changed_by(kind, (s,))
            model.split(s)
        elif kind == "merge":
            t = data.draw(st.sampled_from([x for x in states if x != s]))
            touched |= model.sources_changed_by(kind, (s, t))
            model.merge(s, t)
        else:
            t, a = data.draw(st.sampled_from(states)), data.draw(st.sampled_from((0, 1)))
            touched |= model.sources_changed_by(kind, (s, t, a))
            getattr(model, kind)(s, t, a)
    return touched


def start_model(data: st.DataObject) -> TransitionSystem:
    model = TransitionSystem(data.draw(st.integers(1, 4)), actions=(0, 1))
    for _ in range(data.draw(st.integers(0, 12))):  # some transitions to start from
        states = model.states
        model.add(data.draw(st.sampled_from(states)), data.draw(st.sampled_from(states)),
                  data.draw(st.sampled_from((0, 1))))  # fmt: skip
    model.drain_operations()
    return model


def same_model(rebuilt: TransitionSystem, expected: TransitionSystem) -> bool:
    """The same model: states, transitions, current state, version, next id and the count of
    pairs with several successors."""
    return (
        rebuilt == expected
        and rebuilt.states == expected.states
        and rebuilt.transitions() == expected.transitions()
        and (rebuilt.version, rebuilt.next_id) == (expected.version, expected.next_id)
        and rebuilt.nondeterministic_pairs == expected.nondeterministic_pairs
    )


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_a_history_of_changes_gives_every_version_whole_in_any_order(data: st.DataObject) -> None:
    """Each version, as a record (indexing) and as a model (:meth:`ModelHistory.model`, the
    operations applied to arrays), is the model the operations made, asked for in any order;
    the whole models kept are patched from the last one when the touched states are told
    (or not told: taken whole from the model)."""
    model = start_model(data)
    history = ModelHistory(share=data.draw(st.sampled_from([1, 8, 32])))
    told = data.draw(st.booleans())
    copies = [model.copy()]
    history.add(model_record(model, step=0, operations=()), model)
    for step in range(1, data.draw(st.integers(1, 30))):
        touched = random_operations(data, model)
        model.current = data.draw(st.sampled_from(model.states))
        change = model_record(model, step=step, operations=model.drain_operations(), keyframe=False)
        history.add(change, model, touched=touched if told else None)
        copies.append(model.copy())
    for k in data.draw(st.permutations(range(len(copies)))):
        assert same_model(history.model(k), copies[k]), f"version {k}"
    for k in data.draw(st.permutations(range(len(copies)))):
        record, expected = history[k], copies[k]
        assert record.keyframe == (k == 0)
        assert tuple(record.states) == expected.states
        assert record.triples() == tuple(expected.transitions())
        assert (record.version, record.current) == (expected.version, expected.current)
        assert history.heads[k].step == k
    states, transitions = history.sizes()
    assert states.tolist() == [len(m) for m in copies]
    assert transitions.tolist() == [len(m.transitions()) for m in copies]
    pairs = [(k, s) for k in range(len(copies)) for s in range(copies[-1].next_id + 1)]
    alive = history.alive([k for k, _ in pairs], [s for _, s in pairs])
    assert alive.tolist() == [s in copies[k] for k, s in pairs]


def replayed_by_hand(
    records: list[ModelRecord],
) -> list[tuple[list[int], list[tuple[int, int, int]]]]:
    """Every version's states and ``(source, action, target)`` transitions, sorted: the
    first message's, then each message's operations applied by hand to sets."""
    states, triples = set(records[0].states), set(records[0].triples())
    found = [(sorted(states), sorted(triples))]
    for record in records[1:]:
        for operation in record.operations:
            kind, args = operation.kind, operation.args
            if kind in ("add", "delete") and operation.changed:
                s, t, a = args
                (triples.add if kind == "add" else triples.discard)((s, a, t))
            elif kind == "split":  # the new state copies s's row and column
                s, new = args[0], operation.result
                states.add(new)
                out = {(new, a, t) for x, a, t in triples if x == s}
                loops = {(new, a, new) for x, a, t in triples if x == s and t == s}
                into = {(u, a, new) for u, a, t in triples if t == s}
                triples |= out | loops | into
            elif kind == "merge":  # t's transitions onto s, t gone
                s, t = args
                moved = {x for x in triples if t in (x[0], x[2])}
                triples -= moved
                triples |= {(s if u == t else u, a, s if v == t else v) for u, a, v in moved}
                states.discard(t)
        found.append((sorted(states), sorted(triples)))
    return found


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_every_version_as_arrays_is_the_one_its_operations_make(data: st.DataObject) -> None:
    """:meth:`ModelHistory.arrays` (the operations applied to sorted keys), asked for in any
    order, and of a plain list of messages (:func:`model_history`), against a replay of the
    messages by hand; so are the pairs with several successors and with none that
    :meth:`ModelHistory.determinism_changes` keep, added up version by version."""
    model = start_model(data)
    history = ModelHistory(share=data.draw(st.sampled_from([1, 8, 32])))
    whole = [model_record(model, step=0, operations=())]
    history.add(whole[0], model)
    for step in range(1, data.draw(st.integers(1, 30))):
        if 2 not in model.actions and data.draw(st.booleans()):  # the alphabet grows (alone:
            source = data.draw(st.sampled_from(model.states))  # see test_a_merge_beside_...)
            model.add(source, source, 2)
            touched = {source}
        else:
            touched = random_operations(data, model)
        model.current = data.draw(st.sampled_from(model.states))
        operations = model.drain_operations()
        history.add(model_record(model, step=step, operations=operations, keyframe=False), model,
                    touched=touched)  # fmt: skip
        whole.append(model_record(model, step=step, operations=operations))
    expected = replayed_by_hand(whole)
    assert len(history) == len(expected)
    for k in data.draw(st.permutations(range(len(expected)))):
        states, transitions = history.arrays(k)
        assert (states.tolist(), [tuple(row) for row in transitions.tolist()]) == expected[k]
    plain = model_history(whole)
    assert model_history(history) is history
    for k, (states_k, triples_k) in enumerate(expected):
        states, transitions = plain.arrays(k)
        assert (states.tolist(), [tuple(row) for row in transitions.tolist()]) == (
            states_k,
            triples_k,
        ), f"version {k}"
    for kept in (history, plain):  # the pairs added up over the changes, version by version
        rows: dict[int, DeterminismPart] = {}
        for k, (states_k, triples_k) in enumerate(expected):
            for state, part in kept.determinism_changes(k).items():
                if part is None:
                    rows.pop(state, None)
                else:
                    rows[state] = part
            several = [pair for state in sorted(rows) for pair in rows[state][0]]
            none = [pair for state in sorted(rows) for pair in rows[state][1]]
            assert (several, none) == pairs_by_hand(states_k, triples_k, whole[k].actions)


def pairs_by_hand(
    states: list[int], triples: list[tuple[int, int, int]], actions: tuple[int, ...]
) -> tuple[list[tuple[int, int, tuple[int, ...]]], list[tuple[int, int]]]:
    """The (state, action, successors) with several successors and the (state, action) with
    none, by state and action."""
    successors: dict[tuple[int, int], list[int]] = {}
    for s, a, t in triples:
        successors.setdefault((s, a), []).append(t)
    several = [
        (s, a, tuple(sorted(ts))) for (s, a), ts in sorted(successors.items()) if len(ts) > 1
    ]
    none = [(s, a) for s in states for a in sorted(actions) if (s, a) not in successors]
    return several, none


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), split=st.sampled_from([0.05, 0.2, 0.5]))
def test_the_determinism_audit_kept_through_touched_states_is_every_versions_own(
    seed: int, split: float
) -> None:
    """Each version's pairs with several successors and with none, kept per state through
    what the operations touched, are the ones its own model reports."""
    recording = FakeRecording(
        load_scenario("two-joint-30"), RandomRefiner(split=split, max_states=10), seed=seed,
        steps=120,
    )  # fmt: skip
    found = audit_determinism(recording)
    for record, version in zip(recording.model_versions(), found.versions, strict=True):
        own = TransitionSystem.from_snapshot(record.snapshot()).determinism_report()
        assert (version.nondeterministic, version.empty) == (own.nondeterministic, own.empty)


def test_a_version_that_outgrows_two_byte_ids_is_rebuilt_in_wider_columns() -> None:
    """A split that makes state 32,767 (no longer a 2-byte id, as the kept models' columns
    first held them): the version rebuilt holds every transition, the new state's included."""
    first = TransitionSystem.from_snapshot(
        {
            "states": [0, 32_766],
            "next_id": 32_767,
            "current": 0,
            "actions": [0, 1],
            "transitions": [[0, 0, 32_766], [32_766, 1, 0], [32_766, 0, 32_766]],
        }
    )
    history = ModelHistory(share=1)
    history.add(model_record(first, step=0, operations=()), first)
    assert history[0].triples() == tuple(first.transitions())
    assert first.split(32_766) == 32_767
    history.add(model_record(first, step=1, operations=first.drain_operations()), first)
    wide = history[1]
    assert wide.triples() == tuple(first.transitions())
    assert 32_767 in wide.states


def test_a_no_op_operation_changes_no_version() -> None:
    """An operation that changed nothing (``changed`` false: an add of a transition there, a
    delete of one missing), as a file may hold, leaves the version rebuilt as it was."""
    model = TransitionSystem.from_snapshot(
        {"states": [0, 1], "next_id": 2, "current": 0, "actions": [0, 1],
         "transitions": [[0, 0, 1], [1, 1, 0]]}
    )  # fmt: skip
    history = ModelHistory()
    history.add(model_record(model, step=0, operations=()), model)
    model.split(1)
    operations = [
        Operation("add", (0, 1, 0), None, False),
        *model.drain_operations(),
        Operation("delete", (2, 2, 1), None, False),
    ]
    model.delete(0, 2, 0)
    operations += model.drain_operations()
    history.add(model_record(model, step=1, operations=operations, keyframe=False), model)
    assert same_model(history.model(1), model)
    assert same_model(history.model(0), TransitionSystem.from_snapshot(history[0].snapshot()))


def test_a_model_with_ids_too_wide_for_the_keys_is_rebuilt_all_the_same() -> None:
    """State ids of 32 bits leave no room for a transition in a 63-bit key: the version is
    rebuilt from the model applied the operations instead."""
    wide = 1 << 32
    model = TransitionSystem.from_snapshot(
        {"states": [0, wide], "next_id": wide + 1, "current": 0, "actions": [0, 1],
         "transitions": [[0, 0, wide], [wide, 1, 0], [wide, 0, wide]]}
    )  # fmt: skip
    history = ModelHistory()
    history.add(model_record(model, step=0, operations=()), model)
    model.split(wide)
    model.delete(0, wide, 0)
    change = model_record(model, step=1, operations=model.drain_operations(), keyframe=False)
    history.add(change, model)
    assert same_model(history.model(1), model)


def test_the_audits_and_the_viewer_rebuild_the_first_and_last_versions_only(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """What makes a run of 225,379 versions of 39,232 states readable: the audits and the
    viewer read each message's head and sizes, and rebuild a version whole only at the ends
    (the first shown, the final model)."""
    rebuilt: list[int] = []
    whole, model = ModelHistory._rebuilt, ModelHistory._rebuilt_model

    def counted_whole(self: ModelHistory, k: int) -> ModelRecord:
        rebuilt.append(k)
        return whole(self, k)

    def counted_model(self: ModelHistory, k: int) -> TransitionSystem:
        rebuilt.append(k)
        return model(self, k)

    monkeypatch.setattr(ModelHistory, "_rebuilt", counted_whole)
    monkeypatch.setattr(ModelHistory, "_rebuilt_model", counted_model)
    with open_recording(LEARNER) as recording:
        versions = recording.model_versions()
        assert len(versions) > 100
        loaded = load(recording)
        report = run_audits(loaded)
        truth = audit_truth(
            loaded, truth=recording.ground_truth(), within_versions=report.within_versions
        )
        assert truth.verdict.learned
        view(recording, save=tmp_path / "v.rrd", spawn=False, serve_web=False, start=None, end=None)
    assert set(rebuilt) <= {0, len(versions) - 1}


def test_a_merge_beside_a_new_action_leaves_no_pair_of_the_state_merged_away() -> None:
    """A version that merges a state away and adds an action: every state of the new version
    is recomputed (the new action is a pair with no successor for each), and the state merged
    away, which had a pair with several successors, is cleared with them (the audit refused
    the valid history before: "has 1 pairs with several successors, the message says 0")."""
    model = TransitionSystem.from_snapshot(
        {"states": [0, 1], "next_id": 2, "current": 0, "actions": [0],
         "transitions": [[0, 0, 0], [1, 0, 0], [1, 0, 1]]}
    )  # fmt: skip
    first = model_record(model, step=0, operations=())
    model.merge(0, 1)
    model.add(0, 0, 1)
    second = model_record(model, step=1, operations=model.drain_operations())
    final = audit_determinism([first, second]).final
    own = model.determinism_report()
    assert (final.nondeterministic, final.empty) == (own.nondeterministic, own.empty)
