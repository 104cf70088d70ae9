"""The verdict of a learning run: did it learn the world, from which step, and if not, why not.

Every model version is judged against the ground truth (:func:`rsstp_sim.truth.check_equivalence`)
where it came into force: from its current state, which by the recording contract is the
internal state of the step it was written at, and from the true class of that step's pose.
Each state is labelled with the sensation last seen in it up to the last step the version was
in force (a transition system has no labels of its own; the memory gives them).

- **learned**: the final model is equivalent to the truth; ``learned_at_step`` is the step from
  which every version in force, to the end, was (the first step of the run's final stretch of
  equivalent versions).
- **not learned**: the final model is not equivalent. The verdict gives the model's size
  against the true classes, how fast it was still growing (states a step over the last half of
  the run), and the shortest action sequence that tells the final model from the truth, from
  the final state: the states the model goes through, the sensation it predicts after each
  action and the sensation the world gives, and the last step at which any transition on that
  path changed (where to look in the recording).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from rsstp_sim.recording.records import ModelRecord
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth, check_equivalence

__all__ = ["Counterexample", "Verdict", "judge_versions"]

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
        states = ["-" if s is None else str(s) for s in self.model_states]
        return (
            f"counterexample: from state {self.from_state} at step {self.from_step:,} (true "
            f"class {self.true_class}), actions {_runs(map(str, self.actions))}: the model goes "
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
class Verdict:
    """Whether the run learned the world (see the module docstring)."""

    learned: bool
    learned_at_step: int | None
    steps: int
    final_states: int
    minimal_states: int
    growth_per_step: float
    last_change_step: int
    counterexample: Counterexample | None

    def line(self) -> str:
        """One line, the first a researcher reads."""
        if self.learned:
            assert self.learned_at_step is not None
            if self.final_states == self.minimal_states:
                what = f"equivalent to the minimal model ({self.minimal_states} states)"
            else:
                what = (
                    f"equivalent to the truth with {self.final_states} states (the minimal "
                    f"model has {self.minimal_states})"
                )
            return f"learned: {what} from step {self.learned_at_step:,} to the end"
        head = (
            f"not learned: {_count(self.final_states, 'state')} for "
            f"{_count(self.minimal_states, 'true class', 'true classes')} after "
            f"{_count(self.steps, 'step')}; "
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
        return {
            "learned": self.learned,
            "text": self.line(),
            "learned_at_step": self.learned_at_step,
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
        position = np.searchsorted(self.keys, wanted * self.width + step, side="right") - 1
        found = (position >= 0) & (self.keys[np.maximum(position, 0)] // self.width == wanted)
        return dict(
            zip(
                wanted[found].tolist(),
                self.sensations[position[found]].tolist(),
                strict=True,
            )
        )


def judge_versions(
    versions: Sequence[ModelRecord],
    *,
    truth: GroundTruth,
    states: _Ints,
    sensations: npt.NDArray[np.bool_],
    true_class: _Ints,
) -> tuple[Verdict, npt.NDArray[np.bool_]]:
    """The verdict, and whether each version was equivalent to the truth where it came into
    force. ``states``, ``sensations`` and ``true_class`` are per step (``0 .. T``)."""
    steps = len(states) - 1
    labels = _Labels.of(states, sensations)
    ends = [record.step for record in versions[1:]] + [steps + 1]
    final = versions[-1]
    final_model = TransitionSystem.from_snapshot(final.snapshot(), version=final.version)
    final_labels = labels.at(final_model.states, steps)
    sequence = check_equivalence(
        final_model,
        final_labels,
        truth,
        start_state=int(states[-1]),
        start_class=int(true_class[-1]),
    )
    path = (
        None
        if sequence is None
        else _walk(final_model, final_labels, truth, sequence, int(states[-1]), int(true_class[-1]))
    )
    watched = [] if path is None else path[0]

    equivalent = np.zeros(len(versions), np.bool_)
    changed_at: int | None = None
    seen: tuple[tuple[int, ...] | None, ...] | None = None
    model: TransitionSystem | None = None
    for index, record in enumerate(versions):
        if model is None:
            model = TransitionSystem.from_snapshot(record.snapshot(), version=record.version)
        else:
            for operation in record.operations:
                model.apply(operation.to_operation())
            model.drain_operations()
        start = record.step
        bound = min(max(start, ends[index] - 1), steps)
        equivalent[index] = (
            check_equivalence(
                model,
                labels.at(model.states, bound),
                truth,
                start_state=int(states[start]),
                start_class=int(true_class[start]),
            )
            is None
        )
        if watched:
            now = tuple(model.successors(s, a) if s in model else None for s, a in watched)
            if seen is not None and now != seen:
                changed_at = record.step
            seen = now

    learned_at: int | None = None
    if sequence is None:
        first = len(versions) - 1
        while first > 0 and equivalent[first - 1]:
            first -= 1
        learned_at = versions[first].step
    counterexample = None
    if path is not None and sequence is not None:
        _, model_states, predicted, actual = path
        counterexample = Counterexample(
            actions=sequence,
            from_state=int(states[-1]),
            from_step=steps,
            true_class=int(true_class[-1]),
            model_states=model_states,
            predicted=predicted,
            actual=actual,
            last_changed_step=changed_at,
        )
    return (
        Verdict(
            learned=sequence is None,
            learned_at_step=learned_at,
            steps=steps,
            final_states=len(final.states),
            minimal_states=truth.n_classes,
            growth_per_step=_growth(versions, steps),
            last_change_step=final.step,
            counterexample=counterexample,
        ),
        equivalent,
    )


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
    at = np.fromiter((record.step for record in versions), np.int64, len(versions))
    sizes = np.fromiter((len(record.states) for record in versions), np.int64, len(versions))
    size_middle = int(sizes[int(np.searchsorted(at, middle, side="right")) - 1])
    return round((int(sizes[-1]) - size_middle) / (steps - middle), 4)


def _count(n: int, one: str, many: str | None = None) -> str:
    return f"{n:,} {one if n == 1 else many or one + 's'}"


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
