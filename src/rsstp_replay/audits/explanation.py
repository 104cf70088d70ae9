"""Where did the steps of a run go, and what would have helped: the explanation of a run.

A long run that did not learn is the case a user most needs explained. From the recording and
the ground truth, the explanation measures:

- the **phases**: the share of the steps ``1 .. T`` in each phase the strategy recorded
  (:func:`~rsstp_replay.audits.summary.phase_shares`);
- the **states it kept revisiting**: the internal states and the true classes the steps
  ``1 .. T`` were in (each step counts the state or class it ended in), the most visited first,
  with their share of the steps;
- **when it last found something new**, four steps, each the last step at which:

  - ``last_model_change_step``: the model changed (the step of the last model version; 0 when
    it never changed);
  - ``last_new_state_step``: the agent was for the first time in an internal state id;
  - ``last_new_class_step``: the arm was for the first time in a pose of a true class;
  - ``last_new_transition_step``: the arm took for the first time a transition of the minimal
    model, a pair (true class at step ``t - 1``, action ``a_t``);

  and ``nothing_new_after``, the largest of the four: from the step after it to the end, the
  model did not change and the run met no internal state, true class or transition it had not
  met before. ``T - nothing_new_after`` steps are the run's tail that taught it nothing;
- **the target**: the entries ``0 .. T`` that sensed it (the reset's too, as the summary's
  sensations), the first and the last; the closest the arm came
  (the largest float feedback, 1 at the target, and the first step it was felt); and, when it
  was never sensed, how many moves of the world lie between the classes the run visited and
  the nearest sensed pose (by the truth's transitions);
- **suggestions**: a few rules over those facts, each saying the fact it rests on (a target
  never sensed: where it is, and what the feedback did; a run that stalled: a bigger budget of
  the same will not help; a run still finding new things at its end: a bigger budget may).

Every figure is one pass of numpy over the columns, a block of steps at a time where it needs
a first occurrence: no loop over steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import numpy.typing as npt

from rsstp_format.records import ModelRecord
from rsstp_replay.audits._columns import first_indices
from rsstp_replay.audits.summary import PhaseShare
from rsstp_sim.arrays import distinct
from rsstp_sim.memory import Memory
from rsstp_sim.truth import GroundTruth
from rsstp_sim.words import counted

__all__ = ["Explanation", "Visited", "explain"]

_IntArray = npt.NDArray[np.int64]
_TOP = 5
"""The most visited states and classes listed."""


@dataclass(frozen=True, slots=True)
class Visited:
    """An internal state or a true class (``id``) and the ``steps`` (a ``share`` of ``1 .. T``)
    that ended in it."""

    id: int
    steps: int
    share: float

    def to_json(self) -> dict[str, Any]:
        return {"id": self.id, "steps": self.steps, "share": self.share}


@dataclass(frozen=True, slots=True)
class Explanation:
    """Where the steps of a run went (see the module docstring for each figure).

    The class figures (``classes_visited``, ``top_classes``, ``last_new_class_step``,
    ``last_new_transition_step``, ``target_moves``) are None without a ground truth; so are
    ``best_feedback`` and its step for a recording without feedback.
    """

    steps: int
    phases: tuple[PhaseShare, ...]
    states_visited: int
    top_states: tuple[Visited, ...]
    classes_visited: int | None
    true_classes: int | None
    top_classes: tuple[Visited, ...]
    last_model_change_step: int
    last_new_state_step: int
    last_new_class_step: int | None
    last_new_transition_step: int | None
    sensed_steps: int
    first_sensed_step: int | None
    last_sensed_step: int | None
    best_feedback: float | None
    best_feedback_step: int | None
    sensed_poses: int | None
    target_moves: int | None
    feedback_mode: str
    learned: bool | None
    suggestions: tuple[str, ...]

    @property
    def nothing_new_after(self) -> int:
        """The last step at which the run met something new (model, state, class, transition)."""
        found = [
            self.last_model_change_step,
            self.last_new_state_step,
            self.last_new_class_step,
            self.last_new_transition_step,
        ]
        return max(step for step in found if step is not None)

    @property
    def stalled_steps(self) -> int:
        """The steps after :attr:`nothing_new_after`: the tail that taught the run nothing."""
        return self.steps - self.nothing_new_after

    def to_text(self) -> str:
        """The explanation for a terminal, one fact a line, then the suggestions."""
        steps = max(self.steps, 1)
        lines = []
        if self.phases:
            lines.append(
                "steps by phase: "
                + ", ".join(f"{p.phase} {_percent(p.share)} ({p.steps:,})" for p in self.phases)
            )
        lines.append(
            f"internal states visited: {self.states_visited:,}; the most visited: "
            + _visits(self.top_states, "state")
        )
        if self.classes_visited is not None and self.true_classes is not None:
            lines.append(
                f"true classes visited: {self.classes_visited:,} of {self.true_classes:,}; the "
                f"most visited: " + _visits(self.top_classes, "class")
            )
        new = [f"the model changed last at step {self.last_model_change_step:,}"]
        new.append(f"a new internal state at step {self.last_new_state_step:,}")
        if self.last_new_class_step is not None:
            new.append(f"a new true class at step {self.last_new_class_step:,}")
        if self.last_new_transition_step is not None:
            new.append(
                f"a new transition of the minimal model at step {self.last_new_transition_step:,}"
            )
        lines.append("last new: " + ", ".join(new))
        lines.append(
            f"nothing new after step {self.nothing_new_after:,}: the last "
            f"{counted(self.stalled_steps, 'step')} ({_percent(self.stalled_steps / steps)}) "
            f"taught the run nothing"
        )
        lines.append(self._target_text())
        lines += [f"suggestion: {text}" for text in self.suggestions]
        return "\n".join(lines)

    def _target_text(self) -> str:
        if self.sensed_steps:
            text = (
                f"target: sensed at {counted(self.sensed_steps, 'step')}, first at step "
                f"{self.first_sensed_step:,}, last at step {self.last_sensed_step:,}"
            )
        else:
            text = "target: never sensed"
            if self.target_moves is not None:
                text += (
                    f"; the nearest sensed pose is {counted(self.target_moves, 'move')} from the "
                    f"classes visited"
                )
        if self.best_feedback is not None:
            text += (
                f"; closest: feedback {self.best_feedback:.4f} ({self.feedback_mode} mode; 1 at "
                f"the target), first felt at step {self.best_feedback_step:,}"
            )
        return text

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict; its keys are the fields' names, with ``nothing_new_after`` and
        ``stalled_steps``."""
        return {
            "steps": self.steps,
            "phases": {p.phase: {"steps": p.steps, "share": p.share} for p in self.phases},
            "states_visited": self.states_visited,
            "top_states": [v.to_json() for v in self.top_states],
            "classes_visited": self.classes_visited,
            "true_classes": self.true_classes,
            "top_classes": [v.to_json() for v in self.top_classes],
            "last_model_change_step": self.last_model_change_step,
            "last_new_state_step": self.last_new_state_step,
            "last_new_class_step": self.last_new_class_step,
            "last_new_transition_step": self.last_new_transition_step,
            "nothing_new_after": self.nothing_new_after,
            "stalled_steps": self.stalled_steps,
            "sensed_steps": self.sensed_steps,
            "first_sensed_step": self.first_sensed_step,
            "last_sensed_step": self.last_sensed_step,
            "best_feedback": self.best_feedback,
            "best_feedback_step": self.best_feedback_step,
            "feedback_mode": self.feedback_mode,
            "sensed_poses": self.sensed_poses,
            "target_moves": self.target_moves,
            "learned": self.learned,
            "suggestions": list(self.suggestions),
        }


def explain(
    memory: Memory,
    model_versions: Sequence[ModelRecord],
    *,
    phases: tuple[PhaseShare, ...] = (),
    feedback_mode: str = "bool",
    truth: GroundTruth | None = None,
    true_class: npt.NDArray[np.integer[Any]] | None = None,
    learned: bool | None = None,
) -> Explanation:
    """Explain a run from its memory and model messages; with ``truth`` and each step's
    ``true_class`` (the truth audit's), by the true classes too. ``phases`` are the summary's,
    ``learned`` the verdict's (None: not judged)."""
    steps = memory.steps
    states = memory.internal_states
    sensations = memory.sensations
    first_state = first_indices(states)
    state_visits = _visits_of(states[1:], steps)
    sensed = np.flatnonzero(sensations)  # entries 0 .. T, the reset's too, as the summary
    feedback = memory.feedback
    has_feedback = len(feedback) > 0 and not np.isnan(feedback).all()
    best_step = int(np.nanargmax(feedback)) if has_feedback else None
    classes = None
    if truth is not None and true_class is not None:
        classes = _ClassFacts.of(truth, np.asarray(true_class), memory.actions, steps)
    found = Explanation(
        steps=steps,
        phases=phases,
        states_visited=int(np.count_nonzero(first_state >= 0)),
        top_states=state_visits,
        classes_visited=None if classes is None else classes.visited,
        true_classes=None if truth is None else truth.n_classes,
        top_classes=() if classes is None else classes.top,
        last_model_change_step=model_versions[-1].step if model_versions else 0,
        last_new_state_step=int(first_state.max(initial=0)),
        last_new_class_step=None if classes is None else classes.last_new_class,
        last_new_transition_step=None if classes is None else classes.last_new_transition,
        sensed_steps=len(sensed),
        first_sensed_step=int(sensed[0]) if len(sensed) else None,
        last_sensed_step=int(sensed[-1]) if len(sensed) else None,
        best_feedback=None if best_step is None else float(feedback[best_step]),
        best_feedback_step=best_step,
        sensed_poses=None if truth is None else truth.n_sensed,
        target_moves=None if classes is None or len(sensed) else classes.target_moves,
        feedback_mode=feedback_mode,
        learned=learned,
        suggestions=(),
    )
    return _with_suggestions(found)


@dataclass(frozen=True, slots=True)
class _ClassFacts:
    visited: int
    top: tuple[Visited, ...]
    last_new_class: int
    last_new_transition: int | None
    target_moves: int | None

    @classmethod
    def of(
        cls,
        truth: GroundTruth,
        true_class: npt.NDArray[np.integer[Any]],
        actions: npt.NDArray[np.integer[Any]],
        steps: int,
    ) -> _ClassFacts:
        first_class = first_indices(true_class, size=truth.n_classes)
        visited = first_class >= 0
        # The transition taken at step t: (class at t - 1, the action's index in truth.actions).
        width = len(truth.actions)
        lookup = np.full(max(truth.actions) + 1, -1, np.int64)
        lookup[list(truth.actions)] = np.arange(width)
        transitions = true_class[:-1].astype(np.int64) * width + lookup[actions[1:]]
        first_transition = first_indices(transitions, size=truth.n_classes * width)
        taken = first_transition[first_transition >= 0]
        return cls(
            visited=int(np.count_nonzero(visited)),
            top=_visits_of(true_class[1:], steps, size=truth.n_classes),
            last_new_class=int(first_class.max(initial=0)),
            last_new_transition=int(taken.max()) + 1 if len(taken) else None,
            target_moves=_moves_to_sensed(truth, visited),
        )


def _visits_of(
    values: npt.NDArray[np.integer[Any]], steps: int, *, size: int | None = None
) -> tuple[Visited, ...]:
    """The :data:`_TOP` most frequent values (ties: the smaller first) with their counts."""
    if not len(values):
        return ()
    counts = np.bincount(values, minlength=size or 0)
    top = np.argsort(-counts, kind="stable")[:_TOP]
    return tuple(
        Visited(int(v), int(counts[v]), int(counts[v]) / steps) for v in top if counts[v] > 0
    )


def _moves_to_sensed(truth: GroundTruth, visited: npt.NDArray[np.bool_]) -> int | None:
    """The fewest moves of the minimal model from a visited class to a sensed class (None: no
    sensed class is reachable from them); breadth first, one frontier at a time."""
    distance = np.full(truth.n_classes, -1, np.int64)
    frontier = np.flatnonzero(visited)
    distance[frontier] = 0
    moves = 0
    while len(frontier):
        if truth.class_sensation[frontier].any():
            return moves
        moves += 1
        following = distinct(truth.class_next[frontier])
        frontier = following[distance[following] < 0]
        distance[frontier] = moves
    return None


def _with_suggestions(found: Explanation) -> Explanation:
    """``found`` with its suggestions: rules over its facts, each naming the fact."""
    if found.learned:
        return found
    out: list[str] = []
    steps = max(found.steps, 1)
    phase = max(found.phases, key=lambda p: p.share) if found.phases else None
    stalled = found.stalled_steps / steps
    if found.sensed_steps == 0:
        if found.sensed_poses == 0:
            out.append(
                "no reachable pose senses the feedback point: the world's truth is one class; "
                "put the target where the arm can reach"
            )
        else:
            where = (
                ""
                if found.target_moves is None
                else f" ({counted(found.target_moves, 'move')} beyond every class it visited)"
            )
            out.append(
                f"the target was never sensed{where}: without a sensation every pose looks the "
                "same to the agent (the learner needs a sensed pose as its landmark), so "
                "nothing could be learned; put the target where the arm starts or explores, or "
                "start the arm nearer it"
            )
            peak = found.best_feedback_step
            if found.feedback_mode == "float" and peak is not None and peak <= steps // 2:
                # (a peak in the run's second half is no evidence of being held there)
                out.append(
                    f"the float feedback peaked at {found.best_feedback:.4f} at step "
                    f"{found.best_feedback_step:,} and never rose after: the climb is held at a "
                    "local maximum (an obstacle between the arm and the target?); with boolean "
                    "feedback the learner searches without climbing"
                )
    if phase is not None and phase.share >= 0.5:
        out.append(
            f"{_percent(phase.share)} of the steps were spent in its {phase.phase} phase"
            + (" (searching for the sensed pose)" if phase.phase == "home" else "")
        )
    classes, n = found.classes_visited, found.true_classes
    if classes is not None and n is not None and classes < 0.1 * n and found.top_classes:
        top = sum(v.share for v in found.top_classes)
        out.append(
            f"it visited {classes:,} of {n:,} true classes ({_percent(classes / n)}), and its "
            f"{len(found.top_classes)} most visited took {_percent(top)} of the steps: it kept "
            "walking the same poses"
        )
    if stalled >= 0.5:
        out.append(
            f"nothing new after step {found.nothing_new_after:,} ({_percent(stalled)} of the run): "
            "a bigger budget of the same run would not help; change the world (target, start) "
            "or the strategy"
        )
    elif stalled < 0.1 and found.learned is False:
        out.append(
            f"it was still finding new states, classes or transitions at step "
            f"{found.nothing_new_after:,}, {_percent(stalled)} before the end: a bigger budget "
            "may help"
        )
    if found.last_model_change_step == 0 and found.sensed_steps > 0:
        out.append(
            f"the target was sensed {counted(found.sensed_steps, 'time')} but the model never "
            "changed: the strategy does not learn from its sensations"
        )
    return replace(found, suggestions=tuple(out))


def _percent(share: float) -> str:
    return f"{100 * share:.1f} %"


def _visits(visits: tuple[Visited, ...], noun: str) -> str:
    return ", ".join(f"{noun} {v.id:,} ({_percent(v.share)})" for v in visits) or "none"
