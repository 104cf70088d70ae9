"""The words of the recording contract that both packages speak: why a move was blocked (and
how a steps table and a label say it), how feedback is read, how collisions are checked, and
the model's operations. A body with a blocker kind of its own adds one line to each table.

Every other module takes them from here, the schemas included (they are generated from the
records, which use these types).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Literal, get_args

__all__ = [
    "BLOCKED_COLUMNS",
    "BLOCKER_ARITY",
    "BLOCKER_KINDS",
    "BLOCKER_LABELS",
    "BlockerKind",
    "CollisionMode",
    "FeedbackMode",
    "Operation",
    "OperationKind",
    "snapshot_form",
]

FeedbackMode = Literal["bool", "float"]
"""How the agent reads its feedback: the boolean sensation alone, or the float closeness too."""

CollisionMode = Literal["swept", "endpoint"]
"""How an arm's move is checked against obstacles: the whole swept motion, or its end pose."""

BlockerKind = Literal["fold", "obstacle", "links", "room", "wall", "door"]
"""Why a move was blocked, for every body: the one definition of the blocker kinds, which the
records, the schemas generated from them and the replay side's tables take from here.

- the arm: ``fold`` (joint ``j`` would fold back onto its link: ``(j,)``), ``obstacle``
  (link ``i`` meets obstacle ``j``: ``(i, j)``), ``links`` (links ``i`` and ``j`` meet);
- the rover: ``room`` (it would leave the room by edge ``e``: ``(e,)``, 0 east, 1 north,
  2 west, 3 south), ``obstacle`` (``(0, j)``: the robot, part 0 of its body, meets obstacle
  ``j``), ``wall`` (``(w,)``), ``door`` (a one-way door ``d`` the other way: ``(d,)``)."""

BLOCKER_KINDS: tuple[BlockerKind, ...] = get_args(BlockerKind)
"""The blocker kinds in their order (the order of a steps table's ``blocked_kind``
categories)."""

BLOCKED_COLUMNS: dict[BlockerKind, tuple[str, ...]] = {
    "fold": ("blocked_joint",),
    "obstacle": ("blocked_link", "blocked_obstacle"),
    "links": ("blocked_link_i", "blocked_link_j"),
    "room": ("blocked_edge",),
    "wall": ("blocked_wall",),
    "door": ("blocked_door",),
}
"""A steps table's index columns of each blocker kind, in the order of the step message's
``truth.blocked_by.indices``: a column holds a value exactly at the steps blocked by its kind
(nullable ``Int64``, missing elsewhere)."""

BLOCKER_LABELS: dict[BlockerKind, str] = {
    "fold": "fold joint {0}",
    "obstacle": "obstacle {1} link {0}",
    "links": "links {0} {1}",
    "room": "room edge {0}",
    "wall": "wall {0}",
    "door": "door {0}",
}
"""A blocker as text (the viewer's label, ``str.format`` of its indices)."""

BLOCKER_ARITY: dict[BlockerKind, int] = {kind: len(BLOCKED_COLUMNS[kind]) for kind in BLOCKER_KINDS}
"""How many indices a blocker of each kind has."""


OperationKind = Literal["split", "merge", "add", "delete"]


@dataclass(frozen=True, slots=True)
class Operation:
    """One change applied to a transition system, as logged and replayed.

    ``args`` is ``(s,)`` for split, ``(s, t)`` for merge and ``(s, t, a)`` for
    add and delete. ``result`` is the new state's id for split, the surviving
    ``s`` for merge and ``None`` for add and delete. ``changed`` is ``False``
    only for an add of an existing or a delete of a missing transition; such
    no-ops are never logged by :class:`TransitionSystem`.
    """

    kind: OperationKind
    args: tuple[int, ...]
    result: int | None
    changed: bool = True


def snapshot_form(
    states: Iterable[int],
    next_id: int,
    current: int,
    actions: Iterable[int],
    transitions: Iterable[Iterable[int]],
) -> dict[str, object]:
    """The sparse form of a model that :meth:`TransitionSystem.from_snapshot` reads: its
    states, the next id, the current state, the actions and ``[s, a, t]`` transitions."""
    return {
        "states": list(states),
        "next_id": next_id,
        "current": current,
        "actions": list(actions),
        "transitions": [list(t) for t in transitions],
    }
