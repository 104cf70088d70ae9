"""What an operation changes, used twice: the model chain's fast check (the previous snapshot
with the touched states' rows replaced is the model the operations make) and the truth audit's
tracked successor table (kept through the touched states, equal to one built afresh)."""

from __future__ import annotations

import pytest
from fakes import FakeRecording, RandomRefiner
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_format.records import TransitionsRecord
from rsstp_replay.audits._equivalence import ModelTable, TrackedTable
from rsstp_replay.audits.determinism import audit_determinism
from rsstp_replay.reader._models import _patched
from rsstp_sim import load_scenario
from rsstp_sim.transition_system import TransitionSystem


def as_record(model: TransitionSystem) -> TransitionsRecord:
    triples = model.transitions()
    return TransitionsRecord(
        source=tuple(s for s, _, _ in triples),
        action=tuple(a for _, a, _ in triples),
        target=tuple(t for _, _, t in triples),
    )


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(st.data())
def test_touched_rows_patched_onto_the_previous_snapshot_give_the_new_model(
    data: st.DataObject,
) -> None:
    model = TransitionSystem(data.draw(st.integers(1, 4)), actions=(0, 1))
    for _ in range(data.draw(st.integers(0, 12))):  # some transitions to start from
        states = model.states
        model.add(data.draw(st.sampled_from(states)), data.draw(st.sampled_from(states)),
                  data.draw(st.sampled_from((0, 1))))  # fmt: skip
    tracked = TrackedTable(model, (0, 1))
    for _ in range(data.draw(st.integers(1, 6))):  # one version: several operations
        before = as_record(model)
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
        after = as_record(model)
        patched = _patched(before, model, touched)
        columns = (patched.source, patched.action, patched.target)
        assert tuple(map(tuple, columns)) == (after.source, after.action, after.target)
        assert patched.holds(after)
        assert all(column.itemsize == 2 for column in columns)  # type: ignore[attr-defined]
        tracked.update(model, touched)
        labels = {s: bool(s % 2) for s in model.states}
        fresh, kept = ModelTable.of(model, labels, (0, 1)), tracked.table(labels)
        assert fresh.states.tolist() == kept.states.tolist()
        assert fresh.successor.tolist() == kept.successor.tolist()
        assert fresh.label.tolist() == kept.label.tolist()


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


def test_a_version_that_outgrows_two_byte_ids_is_patched_whole() -> None:
    """Columns of 2-byte ids carried into a version whose new state needs 4 bytes: the patch
    holds every transition, the new state's included, in the wider type."""
    first = TransitionSystem.from_snapshot(
        {
            "states": [0, 32_766],
            "next_id": 32_767,
            "current": 0,
            "actions": [0, 1],
            "transitions": [[0, 0, 32_766], [32_766, 1, 0], [32_766, 0, 32_766]],
        }
    )
    narrow = _patched(as_record(first), first, set())  # the previous version, compacted
    assert narrow.source.itemsize == 2  # type: ignore[attr-defined]
    touched = first.sources_changed_by("split", (32_766,))
    created = first.split(32_766)
    assert created == 32_767
    wide = _patched(narrow, first, touched)
    after = as_record(first)
    assert (tuple(wide.source), tuple(wide.action), tuple(wide.target)) == (
        after.source,
        after.action,
        after.target,
    )
    assert wide.holds(after)
    assert wide.source.itemsize == 4  # type: ignore[attr-defined]
