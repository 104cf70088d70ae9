"""A model version against the ground truth, on arrays: which state behaves as which true class.

A model state ``s`` (labelled with the sensation last seen in it) is *equivalent* to a true
class ``c`` when no action sequence tells them apart: after every sequence the model has a
single successor and predicts the sensation the world gives. That is the relation
:func:`rsstp_sim.truth.check_equivalence` searches one pair at a time; here it is decided for
many pairs at once, in numpy:

- :func:`closure` starts from pairs known to go together (a step's internal state and its true
  class) and follows every action from all of them at once, level by level. It fails at the
  first state that meets two classes, a wrong or missing label, or a (state, action) without a
  single successor; else every pair it reached is equivalent (a state met with one class only,
  and every successor agreeing, is a bisimulation).
- :func:`equivalent_classes` gives every state of the model its class, or -1, by minimising the
  model and the truth as one Moore machine (:func:`rsstp_sim.moore.moore_classes`): the answer
  for states no step visited.

>>> from rsstp_sim.scenario import load_scenario
>>> from rsstp_sim.truth import compute_truth
>>> truth = compute_truth(load_scenario("thesis-roulette"))
>>> table = ModelTable.of(truth.minimal_model(), truth.class_labels(), truth.actions)
>>> closure(table, truth, np.array([0]), np.array([0])).tolist()
[0, 1, 2, 3]
>>> equivalent_classes(table, truth).tolist()
[0, 1, 2, 3]
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rsstp_sim.moore import moore_classes
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth

__all__ = ["NONE", "SEVERAL", "ModelTable", "closure", "equivalent_classes"]

_Ints = npt.NDArray[np.int64]

NONE = -1
"""A (state, action) without a successor, in :attr:`ModelTable.successor`."""
SEVERAL = -2
"""A (state, action) with several successors, in :attr:`ModelTable.successor`."""


@dataclass(frozen=True, slots=True)
class ModelTable:
    """A model as arrays over the truth's actions.

    ``states``: the state ids, sorted; row ``i`` is state ``states[i]``. ``successor[i, k]``:
    the row of the single successor of row ``i`` under ``actions[k]``, or :data:`NONE` or
    :data:`SEVERAL`. ``label[i]``: 1 or 0, the sensation the model predicts there, -1 when
    none was ever seen.
    """

    states: _Ints
    successor: _Ints
    label: _Ints

    @classmethod
    def of(
        cls, model: TransitionSystem, labels: Mapping[int, bool], actions: Sequence[int]
    ) -> ModelTable:
        states = np.asarray(model.states, np.int64)
        triples = np.asarray(model.transitions(), np.int64).reshape(-1, 3)
        label = np.fromiter((int(labels.get(s, -1)) for s in model.states), np.int64, len(states))
        return cls.of_arrays(states, triples, label, actions)

    @classmethod
    def of_arrays(
        cls, states: _Ints, triples: _Ints, label: _Ints, actions: Sequence[int]
    ) -> ModelTable:
        """From the sorted ``states``, the ``(source, action, target)`` rows and the labels;
        transitions by actions the truth does not have are left out."""
        wanted = np.asarray(actions, np.int64)
        order = np.argsort(wanted)
        column = np.searchsorted(wanted[order], triples[:, 1])
        column = np.minimum(column, len(wanted) - 1)
        known = wanted[order][column] == triples[:, 1]
        source = np.searchsorted(states, triples[known, 0])
        target = np.searchsorted(states, triples[known, 2])
        key = source * len(wanted) + order[column[known]]
        counts = np.bincount(key, minlength=len(states) * len(wanted))
        successor = np.full(len(states) * len(wanted), NONE, np.int64)
        successor[counts > 1] = SEVERAL
        single = counts[key] == 1
        successor[key[single]] = target[single]
        return cls(states, successor.reshape(len(states), len(wanted)), label)

    def rows(self, state_ids: _Ints) -> _Ints:
        """The rows of these state ids (each must be a state of the model)."""
        return np.searchsorted(self.states, state_ids)


def closure(table: ModelTable, truth: GroundTruth, rows: _Ints, classes: _Ints) -> _Ints | None:
    """Whether every pair ``(rows[i], classes[i])`` is equivalent; if so, the class of every
    row the pairs reach (-1 for the others), else None.

    Follows all pairs level by level: each level's rows must have a single successor under
    every action, each reached row must meet one class only, and its label must be that
    class's sensation.
    """
    phi = np.full(len(table.states), -1, np.int64)
    frontier, found = _assign(phi, table, truth, rows, classes)
    if not found:
        return None
    while len(frontier):
        successor = table.successor[frontier]
        if (successor < 0).any():
            return None
        following = truth.class_next[phi[frontier]]
        frontier, found = _assign(phi, table, truth, successor.ravel(), following.ravel())
        if not found:
            return None
    return phi


def _assign(
    phi: _Ints, table: ModelTable, truth: GroundTruth, rows: _Ints, classes: _Ints
) -> tuple[_Ints, bool]:
    """Give ``rows`` their ``classes`` in ``phi``: the rows new to it, and False when a row
    meets a second class or its label disagrees."""
    known = phi[rows]
    if ((known >= 0) & (known != classes)).any():
        return rows[:0], False
    fresh = known < 0
    rows, classes = rows[fresh], classes[fresh]
    if not len(rows):
        return rows, True
    order = np.lexsort((classes, rows))
    rows, classes = rows[order], classes[order]
    first = np.r_[True, rows[1:] != rows[:-1]]
    if (~first & (classes != np.r_[-1, classes[:-1]])).any():
        return rows[:0], False
    rows, classes = rows[first], classes[first]
    if (table.label[rows] != truth.class_sensation[classes]).any():
        return rows[:0], False
    phi[rows] = classes
    return rows, True


def equivalent_classes(table: ModelTable, truth: GroundTruth) -> _Ints:
    """For every row of ``table``, the true class it is equivalent to, or -1.

    The model's rows and the truth's classes are minimised as one Moore machine. A
    (state, action) without a single successor goes to a sink the truth never reaches, and a
    state with no label shows what no class shows, so neither is equivalent to any class.
    """
    n_rows, n_classes = len(table.states), truth.n_classes
    sink = n_rows + n_classes
    model_next = np.where(table.successor >= 0, table.successor, sink)
    joined = np.concatenate(
        [
            model_next,
            np.asarray(truth.class_next, np.int64) + n_rows,
            np.full((1, len(truth.actions)), sink, np.int64),
        ]
    )
    output = np.concatenate(
        [
            np.where(table.label >= 0, table.label, 2),
            np.asarray(truth.class_sensation, np.int64),
            [3],
        ]
    )
    block = moore_classes(joined, output)
    class_of_block = np.full(int(block.max()) + 1, -1, np.int64)
    class_of_block[block[n_rows:sink]] = np.arange(n_classes, dtype=np.int64)
    return class_of_block[block[:n_rows]]
