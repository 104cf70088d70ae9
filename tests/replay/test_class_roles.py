"""The role of each true class per model version, on histories small enough to work out by
hand (the viewer's map colours by it: test_viewer_map.py checks it against a brute force)."""

from __future__ import annotations

import numpy as np

from rsstp_replay.audits.class_roles import (
    class_role_changes,
    model_class_roles,
    model_state_roles,
)
from rsstp_replay.audits.state_roles import ALIASED, EXACT, REDUNDANT
from rsstp_sim import load_scenario
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth, compute_truth


def test_class_roles_of_a_tiny_history_computed_by_hand() -> None:
    """Version 0: state 0 stands for classes 0 and 1 (both aliased). Version 1: states 0 and
    1 both for class 0 (redundant), state 2 for class 1 alone (exact). Version 2: state 1
    alone for class 0 (exact); class 1 unvisited keeps its colour. Version 3: the same again
    (no change)."""
    history = [  # (version, state, class)
        (0, 0, 0), (0, 0, 1), (0, 0, 0),
        (1, 0, 0), (1, 1, 0), (1, 2, 1),
        (2, 1, 0), (2, 1, 0),
        (3, 1, 0),
    ]  # fmt: skip
    versions, states, classes = (np.array(column) for column in zip(*history, strict=True))
    changes = class_role_changes(versions, states, classes)
    assert list(
        zip(
            changes.versions.tolist(), changes.classes.tolist(), changes.roles.tolist(), strict=True
        )
    ) == [
        (0, 0, ALIASED),
        (0, 1, ALIASED),
        (1, 0, REDUNDANT),
        (1, 1, EXACT),
        (2, 0, EXACT),
    ]


def test_a_class_stood_for_by_an_aliased_and_an_exact_looking_state_is_aliased() -> None:
    """Class 0 is stood for by state 0 (only class 0: redundant, as class 0 has two states)
    and by state 1 (classes 0 and 1: aliased): the worst, aliased. Class 1: aliased too."""
    changes = class_role_changes([0, 0, 0], [0, 1, 1], [0, 0, 1])
    assert changes.roles.tolist() == [ALIASED, ALIASED]


def _truth() -> GroundTruth:
    return compute_truth(load_scenario("two-joint-30"))


def test_the_truths_own_model_gives_every_class_exact() -> None:
    truth = _truth()
    reached, roles = model_class_roles(truth.minimal_model(), truth, 0, 0)
    assert reached.tolist() == list(range(truth.n_classes))
    assert set(roles.tolist()) == {EXACT}


def test_a_split_state_makes_its_class_redundant_and_one_state_aliases_them_all() -> None:
    truth = _truth()
    model = truth.minimal_model()
    copy = model.split(5)  # state 5 and its copy stand for class 5, the rest as before:
    for u, a in model.transitions_into(5):  # one way into the copy, the others into 5
        if u not in (5, copy):
            model.delete(u, copy, a)
    u, a = next((u, a) for u, a in model.transitions_into(5) if u not in (5, copy))
    model.delete(u, 5, a)
    model.add(u, copy, a)
    for s in (5, copy):  # a blocked move (a self-loop on 5) stays one on each
        for a in model.actions:
            if set(model.successors(s, a)) == {5, copy}:
                model.delete(s, copy if s == 5 else 5, a)
    assert model.is_deterministic()
    states = model_state_roles(model, truth, 0, 0)
    assert states == {s: REDUNDANT if s in (5, copy) else EXACT for s in model.states}
    reached, roles = model_class_roles(model, truth, 0, 0)
    assert dict(zip(reached.tolist(), roles.tolist(), strict=True)) == {
        c: REDUNDANT if c == 5 else EXACT for c in range(truth.n_classes)
    }
    one_state = TransitionSystem.universal(truth.actions)
    reached, roles = model_class_roles(one_state, truth, 0, 0)
    assert len(reached) == truth.n_classes and set(roles.tolist()) == {ALIASED}


def test_the_final_version_colours_classes_it_never_visited() -> None:
    """Class 1 was last visited (aliased) in version 0; the final version, version 1, is the
    truth's model: the map ends with class 1 exact, not with its stale colour."""
    changes = class_role_changes(
        [0, 0, 1], [0, 0, 0], [0, 1, 0], final=(1, np.array([0, 1]), np.array([EXACT, EXACT]))
    )
    last = {c: r for c, r in zip(changes.classes.tolist(), changes.roles.tolist(), strict=True)}
    assert last == {0: EXACT, 1: EXACT}
    assert changes.versions.tolist() == sorted(changes.versions.tolist())


def test_the_states_roles_by_the_model_itself() -> None:
    truth = _truth()
    assert set(model_state_roles(truth.minimal_model(), truth, 0, 0).values()) == {EXACT}
    one_state = TransitionSystem.universal(truth.actions)
    assert model_state_roles(one_state, truth, 0, 0) == {0: ALIASED}
