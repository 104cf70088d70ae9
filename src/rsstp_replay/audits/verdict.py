"""The verdict of a learning run: did it learn the world, from which step, and if not, why not.

A model state *behaves as* a true class when no action sequence tells them apart: after every
sequence the model has a single successor and predicts the sensation the world gives (each
state labelled with the sensation last seen in it, up to the last step its version was in
force: a transition system has no labels of its own; the memory gives them).

- **learned** means two things: the final model has a state that behaves as the start pose,
  and its current state behaves as the arm's pose at the end. In a world the arm can always
  return through, the second gives the first; in a one-way world it does not, and a model
  that knows only the part the arm ended in is *not* learned.
- **equivalent** (one model version, the ``equivalent`` column of the truth audit): some state
  of the version behaves as the start pose, and at every step the version was in force, the
  step's internal state behaves as the step's true class. ``learned_at_step`` is the first step
  from which every version in force is equivalent, so it agrees with that column by
  construction; a run is learned exactly when its final version is equivalent.
- **not learned**: the verdict gives the model's size against the true classes, how fast it
  was still growing (states a step over the last half of the run), and the shortest action
  sequence that tells the final model from the truth, from the last step whose internal state
  does not behave as its true class: the states the model goes through, the sensation it
  predicts after each action and the sensation the world gives, and the last step at which any
  transition on that path changed (where to look in the recording).
- **confined**: when the arm ends where no action sequence leads back to the start pose's
  class, the verdict names the step (and the move) that left the start's part of the world for
  good, how many classes the arm can still reach, and whether the model is equivalent on that
  part (``learned_reachable``).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from rsstp_format.records import ModelRecord
from rsstp_replay.audits._equivalence import ModelTable, closure, equivalent_classes
from rsstp_replay.reader import model_history, version_heads, version_sizes
from rsstp_sim.arrays import distinct
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth, check_equivalence
from rsstp_sim.words import counted

__all__ = ["Confinement", "Counterexample", "Verdict", "judge_versions"]

_Ints = npt.NDArray[np.int64]


@dataclass(frozen=True, slots=True)
class Counterexample:
    """The shortest action sequence on which the final model and the world disagree.

    From model state ``from_state`` at step ``from_step`` (true class ``true_class``), the
    model goes through ``model_states`` (None once it has no single successor) and predicts
    ``predicted`` after each action (None: no label, or no single successor); the world gives
    ``actual``. ``last_changed_step``: the last step at which a transition out of a state on
    that path, by the action taken there, changed (None: never since step 0).
    """

    actions: tuple[int, ...]
    from_state: int
    from_step: int
    true_class: int
    model_states: tuple[int | None, ...]
    predicted: tuple[bool | None, ...]
    actual: tuple[bool, ...]
    last_changed_step: int | None

    @property
    def disagreement(self) -> str:
        """Why the last action disagrees: a wrong sensation, or no single successor."""
        if not self.actions:
            return "the model's state is labelled with the wrong sensation already"
        last = self.model_states[-1]
        if last is None:
            return "the model has no single successor for the last action"
        if self.predicted[-1] is None:
            return "the model never saw a sensation in the state it reaches"
        return "the model predicts the wrong sensation after the last action"

    def to_text(self) -> str:
        """One line; repeated values are run-length shortened (``false x22``)."""
        changed = (
            "never changed since step 0"
            if self.last_changed_step is None
            else f"last changed at step {self.last_changed_step:,}"
        )
        states = ["-" if s is None else f"{s:,}" for s in self.model_states]
        return (
            f"counterexample: from state {self.from_state:,} at step {self.from_step:,} (true "
            f"class {self.true_class:,}), actions {_runs(map(str, self.actions))}: the model goes "
            f"through states {_runs(states)} and predicts "
            f"{_runs(map(_sensation, self.predicted))}, the world senses "
            f"{_runs(map(_sensation, self.actual))} ({self.disagreement}); the transitions on "
            f"that path {changed}"
        )

    def to_json(self) -> dict[str, Any]:
        return {
            "actions": list(self.actions),
            "from_state": self.from_state,
            "from_step": self.from_step,
            "true_class": self.true_class,
            "model_states": list(self.model_states),
            "predicted": list(self.predicted),
            "actual": list(self.actual),
            "reason": self.disagreement,
            "last_changed_step": self.last_changed_step,
        }


@dataclass(frozen=True, slots=True)
class Confinement:
    """The run left the start's part of the world for good: from ``step`` on, no action
    sequence leads back to the start pose's class. The move of that step was ``action``, from
    ``pose_before`` to ``pose_after`` (joint angles in degrees; None when the recording gives
    no angles). At the end the arm can still reach ``reachable_classes`` of the world's
    classes."""

    step: int
    action: int | None
    pose_before: tuple[int, ...] | None
    pose_after: tuple[int, ...] | None
    reachable_classes: int

    def move(self) -> str:
        """``step 120 (action 0, from pose [350, 10] to [0, 10])``."""
        if self.action is None:
            return f"step {self.step:,}"
        if self.pose_before is None or self.pose_after is None:
            return f"step {self.step:,} (action {self.action})"
        return (
            f"step {self.step:,} (action {self.action}, from pose {list(self.pose_before)} to "
            f"{list(self.pose_after)})"
        )


@dataclass(frozen=True, slots=True)
class Verdict:
    """Whether the run learned the world (see the module docstring).

    ``learned``: the final model has a state equivalent to the start pose, and its current
    state is equivalent to the arm's pose at the end. ``learned_reachable``: the second
    alone (the model is right about the part of the world the arm can still reach);
    ``has_start_state``: the first alone. ``confinement``: where the run left the start's part
    of the world for good (None when it can still return).
    """

    learned: bool
    learned_at_step: int | None
    steps: int
    final_states: int
    minimal_states: int
    growth_per_step: float
    last_change_step: int
    counterexample: Counterexample | None
    learned_reachable: bool
    has_start_state: bool
    confinement: Confinement | None
    reachable_classes: int

    def line(self) -> str:
        """One line, the first a researcher reads."""
        if self.learned:
            assert self.learned_at_step is not None
            if self.final_states == self.minimal_states:
                what = f"equivalent to the minimal model ({self.minimal_states:,} states)"
            else:
                what = (
                    f"equivalent to the truth with {self.final_states:,} states (the minimal "
                    f"model has {self.minimal_states:,})"
                )
            return f"learned: {what} from step {self.learned_at_step:,} to the end"
        if self.confinement is not None:
            part = (
                "the model is equivalent to the truth on that part"
                if self.learned_reachable
                else "the model is not equivalent to the truth even there"
            )
            return (
                f"not learned: since {self.confinement.move()} the arm cannot return to where "
                f"it started; the run is confined to {self.reachable_classes:,} of the "
                f"{counted(self.minimal_states, 'true class', 'true classes')}, {part} "
                f"({counted(self.final_states, 'state')}), and no state of the final model is "
                f"equivalent to the start pose"
            )
        head = (
            f"not learned: {counted(self.final_states, 'state')} for "
            f"{counted(self.minimal_states, 'true class', 'true classes')} after "
            f"{counted(self.steps, 'step')}; "
        )
        if self.growth_per_step > 0:
            return head + f"the model grows by about {self.growth_per_step:.2g} states a step"
        if self.growth_per_step < 0:
            return head + f"the model shrinks by about {-self.growth_per_step:.2g} states a step"
        return head + f"the model has not changed size since step {self.last_change_step:,}"

    def to_text(self) -> str:
        lines = [f"verdict: {self.line()}"]
        if self.counterexample is not None:
            lines.append(f"  {self.counterexample.to_text()}")
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        confinement = self.confinement
        return {
            "learned": self.learned,
            "text": self.line(),
            "learned_at_step": self.learned_at_step,
            "learned_reachable": self.learned_reachable,
            "has_start_state": self.has_start_state,
            "confined_since_step": None if confinement is None else confinement.step,
            "confining_move": None
            if confinement is None
            else {
                "action": confinement.action,
                "pose_before": None
                if confinement.pose_before is None
                else list(confinement.pose_before),
                "pose_after": None
                if confinement.pose_after is None
                else list(confinement.pose_after),
            },
            "reachable_classes": self.reachable_classes,
            "steps": self.steps,
            "final_states": self.final_states,
            "minimal_states": self.minimal_states,
            "growth_per_step": self.growth_per_step,
            "last_change_step": self.last_change_step,
        }


@dataclass(frozen=True, slots=True)
class _Labels:
    """The sensation last seen in each state up to a step, for any state and step."""

    keys: _Ints
    sensations: npt.NDArray[np.bool_]
    width: int

    @classmethod
    def of(cls, states: _Ints, sensations: npt.NDArray[np.bool_]) -> _Labels:
        width = len(states)
        keys = states * width + np.arange(width, dtype=np.int64)
        order = np.argsort(keys, kind="stable")
        return cls(keys[order], sensations[order], width)

    def at(self, states: Sequence[int], step: int) -> dict[int, bool]:
        wanted = np.asarray(states, np.int64)
        position, found = self._last_seen(wanted, step)
        return dict(
            zip(
                wanted[found].tolist(),
                self.sensations[position[found]].tolist(),
                strict=True,
            )
        )

    def column(self, states: _Ints, step: int) -> _Ints:
        """:meth:`at` as a column over ``states``: 1 or 0, -1 where none was seen."""
        position, found = self._last_seen(states, step)
        label = np.full(len(states), -1, np.int64)
        label[found] = self.sensations[position[found]]
        return label

    def _last_seen(self, wanted: _Ints, step: int) -> tuple[_Ints, npt.NDArray[np.bool_]]:
        position = np.searchsorted(self.keys, wanted * self.width + step, side="right") - 1
        found = (position >= 0) & (self.keys[np.maximum(position, 0)] // self.width == wanted)
        return position, found


@dataclass(frozen=True, slots=True)
class _Visits:
    """The distinct (internal state, true class) pairs of the steps each version was in
    force, sorted by version, state and class."""

    state: _Ints
    true_class: _Ints
    bounds: _Ints

    @classmethod
    def of(cls, index: _Ints, states: _Ints, true_class: _Ints, n_versions: int) -> _Visits:
        keep = index >= 0
        width_state = int(states.max(initial=0)) + 1
        width_class = int(true_class.max(initial=0)) + 1
        if (
            int(states.min(initial=0)) >= 0
            and int(true_class.min(initial=0)) >= 0
            and n_versions * width_state * width_class < 2**62
        ):  # one integer per triple: one sort of plain integers, not a lexsort
            packed = (index[keep] * width_state + states[keep]) * width_class + true_class[keep]
            seen = distinct(packed)
            del packed
            rest, c = np.divmod(seen, width_class)
            v, s = np.divmod(rest, width_state)
            return cls(s, c, np.searchsorted(v, np.arange(n_versions + 1, dtype=np.int64)))
        order = np.lexsort((true_class[keep], states[keep], index[keep]))
        v, s, c = index[keep][order], states[keep][order], true_class[keep][order]
        first = np.ones(len(v), np.bool_)
        first[1:] = (v[1:] != v[:-1]) | (s[1:] != s[:-1]) | (c[1:] != c[:-1])
        v, s, c = v[first], s[first], c[first]
        return cls(s, c, np.searchsorted(v, np.arange(n_versions + 1, dtype=np.int64)))

    def of_version(self, k: int) -> tuple[_Ints, _Ints]:
        lo, hi = self.bounds[k], self.bounds[k + 1]
        return self.state[lo:hi], self.true_class[lo:hi]


def _judge(
    table: ModelTable,
    truth: GroundTruth,
    states: _Ints,
    classes: _Ints,
    *,
    always: bool,
) -> tuple[bool, bool]:
    """(the model's state at every pair behaves as the pair's class, some state of the model
    behaves as the start pose's class 0). The second is decided only when the first holds,
    or ``always`` (else it is False: the version is not equivalent either way)."""
    rows = np.minimum(table.rows(states), len(table.states) - 1)
    if (table.states[rows] != states).any():
        return False, False  # the contract is broken: a step's state is not in its version
    phi = closure(table, truth, rows, classes)
    if phi is not None and (phi == 0).any():
        return True, True
    if len(table.states) < truth.n_classes or (phi is None and not always):
        return phi is not None, False  # a state for each class is needed to behave as class 0
    return phi is not None, bool((equivalent_classes(table, truth) == 0).any())


def judge_versions(
    versions: Sequence[ModelRecord],
    *,
    truth: GroundTruth,
    states: _Ints,
    sensations: npt.NDArray[np.bool_],
    true_class: _Ints,
    actions: npt.NDArray[np.integer[Any]] | None = None,
    angles: npt.NDArray[np.integer[Any]] | None = None,
) -> tuple[Verdict, npt.NDArray[np.bool_]]:
    """The verdict, and whether each version was equivalent to the truth.

    A version is equivalent when some state of it behaves as the start pose (class 0) and,
    at every step it was in force, the step's internal state behaves as the step's true
    class (a version replaced within its own step: its own current state, with the class of
    that step). Each state is labelled with the sensation last seen in it up to the last
    step the version was in force. ``states``, ``sensations``, ``true_class`` (and
    ``actions``, ``angles`` to name the move that confined the run) are per step
    (``0 .. T``).
    """
    # Each message's head; a version's transitions only where it is judged, from the
    # history's arrays (most versions are left out before: too few states, or aliasing).
    history = model_history(versions)
    versions = history.heads
    n_states = history.sizes()[0]
    steps = len(states) - 1
    labels = _Labels.of(states, sensations)
    starts = np.fromiter((record.step for record in versions), np.int64, len(versions))
    ends = np.r_[starts[1:], steps + 1]
    index = np.searchsorted(starts, np.arange(steps + 1, dtype=np.int64), side="right") - 1
    visits = _Visits.of(index, states, true_class, len(versions))
    n_classes = truth.n_classes

    equivalent = np.zeros(len(versions), np.bool_)
    final_judged = (False, False)
    for k, record in enumerate(versions):
        is_final = k == len(versions) - 1
        if n_states[k] < n_classes and not is_final:
            continue  # a state for each class is needed to behave as the start pose
        pair_states, pair_classes = visits.of_version(k)
        if not len(pair_states):
            start = min(int(record.step), steps)
            pair_states = np.array([record.current], np.int64)
            pair_classes = true_class[start : start + 1]
        if len(pair_states) > 1 and (pair_states[1:] == pair_states[:-1]).any() and not is_final:
            continue  # a state stood for two classes
        bound = min(max(int(record.step), int(ends[k]) - 1), steps)
        model_states, transitions = history.arrays(k)
        label = labels.column(model_states, bound)
        judged = _judge(
            ModelTable.of_arrays(model_states, transitions, label, truth.actions),
            truth,
            pair_states,
            pair_classes,
            always=is_final,
        )
        equivalent[k] = judged[0] and judged[1]
        if is_final:
            final_judged = judged

    model = history.model(len(versions) - 1)
    final = versions[-1]
    final_labels = labels.at(model.states, steps)
    learned_reachable, has_start_state = final_judged
    learned = learned_reachable and has_start_state
    counterexample = None
    if not learned_reachable:
        counterexample = _counterexample(
            versions, model, final_labels, truth, states, true_class, int(starts[-1])
        )

    learned_at: int | None = None
    if learned:
        bad = np.flatnonzero(~equivalent[index])
        learned_at = int(bad[-1]) + 1 if len(bad) else 0

    returning = truth.classes_returning_to(0)
    confinement = None
    if not returning[true_class[-1]]:
        step = int(np.flatnonzero(returning[true_class])[-1]) + 1
        confinement = Confinement(
            step=step,
            action=None if actions is None else int(actions[step]),
            pose_before=None if angles is None else tuple(angles[step - 1].tolist()),
            pose_after=None if angles is None else tuple(angles[step].tolist()),
            reachable_classes=int(truth.classes_reached_from(int(true_class[-1])).sum()),
        )
    return (
        Verdict(
            learned=learned,
            learned_at_step=learned_at,
            steps=steps,
            final_states=len(model),
            minimal_states=n_classes,
            growth_per_step=_growth(history, steps),
            last_change_step=final.step,
            counterexample=counterexample,
            learned_reachable=learned_reachable,
            has_start_state=has_start_state,
            confinement=confinement,
            reachable_classes=n_classes if confinement is None else confinement.reachable_classes,
        ),
        equivalent,
    )


def _counterexample(
    versions: Sequence[ModelRecord],
    model: TransitionSystem,
    labels: dict[int, bool],
    truth: GroundTruth,
    states: _Ints,
    true_class: _Ints,
    first_step: int,
) -> Counterexample | None:
    """The shortest sequence that tells the final model from the truth, from the last step
    of the final version's steps whose internal state does not behave as its true class.

    The last step is tried first (where the run ended: nearly always the one); then the
    distinct (state, class) pairs of the version's earlier steps, latest first, up to
    :data:`_PAIRS_TRIED` of them (None when none of those tells them apart).
    """
    tried: set[tuple[int, int]] = set()
    for step in range(len(states) - 1, first_step - 1, -1):
        pair = (int(states[step]), int(true_class[step]))
        if pair in tried:
            continue
        if len(tried) == _PAIRS_TRIED:
            return None
        tried.add(pair)
        state, cls = pair
        if state not in model:
            continue
        sequence = check_equivalence(model, labels, truth, start_state=state, start_class=cls)
        if sequence is None:
            continue
        watched, model_states, predicted, actual = _walk(model, labels, truth, sequence, state, cls)
        return Counterexample(
            actions=sequence,
            from_state=state,
            from_step=step,
            true_class=cls,
            model_states=model_states,
            predicted=predicted,
            actual=actual,
            last_changed_step=_last_changed(versions, watched),
        )
    return None


_PAIRS_TRIED = 64
"""Distinct (state, class) pairs of the final version searched for a counterexample."""


def _last_changed(versions: Sequence[ModelRecord], watched: list[tuple[int, int]]) -> int | None:
    """The last step at which the successors of any of the ``watched`` (state, action) pairs
    changed (None: never since step 0)."""
    if not watched:
        return None
    changed_at: int | None = None
    seen: tuple[tuple[int, ...] | None, ...] | None = None
    model: TransitionSystem | None = None
    for record in versions:
        if model is None:
            model = TransitionSystem.from_snapshot(record.snapshot(), version=record.version)
        else:
            for operation in record.operations:
                model.apply(operation.to_operation())
            model.drain_operations()
        now = tuple(model.successors(s, a) if s in model else None for s, a in watched)
        if seen is not None and now != seen:
            changed_at = record.step
        seen = now
    return changed_at


def _walk(
    model: TransitionSystem,
    labels: dict[int, bool],
    truth: GroundTruth,
    sequence: tuple[int, ...],
    state: int,
    true_class: int,
) -> tuple[
    list[tuple[int, int]], tuple[int | None, ...], tuple[bool | None, ...], tuple[bool, ...]
]:
    """Follow ``sequence`` in the model and in the truth: the (state, action) pairs taken, the
    model's states, its predicted sensations and the true ones."""
    column = {action: k for k, action in enumerate(truth.actions)}
    pairs: list[tuple[int, int]] = []
    model_states: list[int | None] = []
    predicted: list[bool | None] = []
    actual: list[bool] = []
    current: int | None = state
    c = true_class
    for action in sequence:
        if current is not None:
            pairs.append((current, action))
            successors = model.successors(current, action)
            current = successors[0] if len(successors) == 1 else None
        model_states.append(current)
        predicted.append(None if current is None else labels.get(current))
        c = int(truth.class_next[c, column[action]])
        actual.append(bool(truth.class_sensation[c]))
    return pairs, tuple(model_states), tuple(predicted), tuple(actual)


def _growth(versions: Sequence[ModelRecord], steps: int) -> float:
    """States gained a step over the last half of the run (0 with fewer than 2 steps)."""
    if steps < 2:
        return 0.0
    middle = steps // 2
    heads = version_heads(versions)
    at = np.fromiter((record.step for record in heads), np.int64, len(heads))
    sizes = version_sizes(versions)[0]
    size_middle = int(sizes[int(np.searchsorted(at, middle, side="right")) - 1])
    return round((int(sizes[-1]) - size_middle) / (steps - middle), 4)


def _runs(values: Iterable[str]) -> str:
    """``[a x3, b]``: consecutive repeats folded."""
    runs: list[list[Any]] = []
    for value in values:
        if runs and runs[-1][0] == value:
            runs[-1][1] += 1
        else:
            runs.append([value, 1])
    return "[" + ", ".join(v if n == 1 else f"{v} x{n}" for v, n in runs) + "]"


def _sensation(value: bool | None) -> str:
    return "?" if value is None else str(value).lower()
