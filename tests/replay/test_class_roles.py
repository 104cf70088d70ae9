"""The role of each true class per model version, on histories small enough to work out by
hand (the viewer's map colours by it: test_viewer_map.py checks it against a brute force)."""

from __future__ import annotations

import numpy as np

from rsstp_replay.audits.class_roles import class_role_changes
from rsstp_replay.audits.state_roles import ALIASED, EXACT, REDUNDANT


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
