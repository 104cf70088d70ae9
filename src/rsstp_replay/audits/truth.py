"""The truth audit: what the agent's internal states really stood for (DESIGN.md section 5).

The world is finite; its reachable poses, labelled with their sensation, form a
deterministic Moore machine whose minimisation is the smallest correct model
(:mod:`rsstp_sim.truth`). Every step of a recording has a pose, so every step
has a *true class*: the state of that minimal machine. Comparing the agent's
internal states with the true classes says exactly what went wrong:

- **aliasing**: one internal state stood for several true classes. The agent
  confuses situations that behave differently; a deterministic model with that
  labelling cannot predict correctly.
- **redundancy**: one true class was represented by several internal states. The
  agent split a behaviour over several states it cannot tell apart (the thesis
  algorithm's failure: it never recognises a state it already created).
- **first mismatch**: the first step at which the correspondence between
  internal states and true classes stopped being one to one.
- **final model**: whether the model at the last step, with each state labelled
  by the sensation last seen in it, is equivalent to the truth from where the
  agent ended, and if not the shortest action sequence that tells them apart.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from rsstp_sim.memory import Memory
from rsstp_sim.scenario import Scenario
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth, check_equivalence, compute_truth

__all__ = ["TruthFindings", "TruthSource", "audit_truth", "step_true_classes"]


class TruthSource(Protocol):
    """What the truth audit reads from a recording."""

    @property
    def scenario(self) -> Scenario: ...
    @property
    def n_steps(self) -> int: ...
    def steps(self) -> pd.DataFrame: ...
    def memory(self) -> Memory: ...
    def model_at(self, step: int) -> TransitionSystem: ...


def step_true_classes(steps: pd.DataFrame, truth: GroundTruth) -> NDArray[np.int64]:
    """The true class of every row's pose (columns ``angle_deg_0 .. angle_deg_{n-1}``)."""
    columns = [f"angle_deg_{j}" for j in range(truth.n_joints)]
    return truth.classes_of(steps[columns].to_numpy(dtype=np.int64))


def _first_change(keys: NDArray[np.int64], values: NDArray[np.int64]) -> int | None:
    """First index where a key is seen with a value other than the one it first had."""
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    differs = values != values[first][inverse]
    return int(np.argmax(differs)) if differs.any() else None


def _grouped(keys: NDArray[np.int64], values: NDArray[np.int64]) -> dict[int, tuple[int, ...]]:
    pairs = np.unique(np.stack([keys, values], axis=1), axis=0)
    out: dict[int, list[int]] = {}
    for key, value in pairs.tolist():
        out.setdefault(key, []).append(value)
    return {k: tuple(v) for k, v in out.items()}


@dataclass(frozen=True)
class TruthFindings:
    """The truth audit of one recording (see the module docstring for what each part means)."""

    scenario: str
    reachable_poses: int
    minimal_states: int
    steps: int
    classes_of_state: Mapping[int, tuple[int, ...]]
    states_of_class: Mapping[int, tuple[int, ...]]
    first_aliasing_step: int | None
    first_redundancy_step: int | None
    final_model_states: int
    final_equivalent: bool
    counterexample: tuple[int, ...] | None
    true_class: NDArray[np.int64] = field(repr=False, compare=False)

    @property
    def aliased(self) -> dict[int, tuple[int, ...]]:
        """Internal states that stood for more than one true class."""
        return {s: c for s, c in self.classes_of_state.items() if len(c) > 1}

    @property
    def redundant(self) -> dict[int, tuple[int, ...]]:
        """True classes represented by more than one internal state."""
        return {c: s for c, s in self.states_of_class.items() if len(s) > 1}

    @property
    def first_mismatch_step(self) -> int | None:
        """The first step where states and classes stopped corresponding one to one."""
        found = [s for s in (self.first_aliasing_step, self.first_redundancy_step) if s is not None]
        return min(found) if found else None

    @property
    def classes_visited(self) -> int:
        return len(self.states_of_class)

    def to_text(self) -> str:
        aliased, redundant = self.aliased, self.redundant
        lines = [
            f"truth: {self.scenario}: {self.reachable_poses:,} reachable poses, "
            f"minimal model {self.minimal_states} states; the run visited "
            f"{self.classes_visited} classes with {len(self.classes_of_state)} internal states",
            f"aliasing: {len(aliased)} internal states stood for several true classes"
            + (f", first at step {self.first_aliasing_step}" if aliased else ""),
        ]
        for state, classes in sorted(aliased.items())[:10]:
            lines.append(f"  state {state}: classes {_short(classes)}")
        lines.append(
            f"redundancy: {len(redundant)} true classes were split over several internal states"
            + (f", first at step {self.first_redundancy_step}" if redundant else "")
        )
        for cls, states in sorted(redundant.items())[:10]:
            lines.append(f"  class {cls}: states {_short(states)}")
        if self.first_mismatch_step is None:
            lines.append("the internal states matched the true classes one to one at every step")
        else:
            lines.append(f"first mismatch at step {self.first_mismatch_step}")
        if self.final_equivalent:
            lines.append(f"final model ({self.final_model_states} states): equivalent to the truth")
        else:
            lines.append(
                f"final model ({self.final_model_states} states): NOT equivalent; shortest "
                f"counterexample: actions {list(self.counterexample or ())}"
            )
        return "\n".join(lines) + "\n"

    def to_json(self) -> dict[str, Any]:
        return {
            "scenario": self.scenario,
            "reachable_poses": self.reachable_poses,
            "minimal_states": self.minimal_states,
            "steps": self.steps,
            "classes_visited": self.classes_visited,
            "internal_states_visited": len(self.classes_of_state),
            "aliased_states": {str(s): list(c) for s, c in sorted(self.aliased.items())},
            "redundant_classes": {str(c): list(s) for c, s in sorted(self.redundant.items())},
            "first_aliasing_step": self.first_aliasing_step,
            "first_redundancy_step": self.first_redundancy_step,
            "first_mismatch_step": self.first_mismatch_step,
            "final_model_states": self.final_model_states,
            "final_equivalent": self.final_equivalent,
            "counterexample": None if self.counterexample is None else list(self.counterexample),
        }


def _short(values: tuple[int, ...], limit: int = 12) -> str:
    shown = ", ".join(map(str, values[:limit]))
    return f"[{shown}{', ...' if len(values) > limit else ''}] ({len(values)})"


def _labels(memory: Memory) -> dict[int, bool]:
    """Each internal state's label: the sensation last seen in it."""
    states = memory.internal_states[::-1]
    sensations = memory.sensations[::-1]
    unique, last = np.unique(states, return_index=True)
    return dict(zip(unique.tolist(), sensations[last].tolist(), strict=True))


def audit_truth(source: TruthSource, *, truth: GroundTruth | None = None) -> TruthFindings:
    """Run the truth audit (computes the ground truth unless ``truth`` is given)."""
    truth = compute_truth(source.scenario) if truth is None else truth
    steps = source.steps()
    true_class = step_true_classes(steps, truth)
    memory = source.memory()
    states = np.asarray(memory.internal_states, dtype=np.int64)
    final = source.model_at(source.n_steps)
    counterexample = check_equivalence(
        final,
        _labels(memory),
        truth,
        start_state=final.current,
        start_class=int(true_class[-1]),
    )
    return TruthFindings(
        scenario=truth.scenario_name,
        reachable_poses=truth.n_poses,
        minimal_states=truth.n_classes,
        steps=source.n_steps,
        classes_of_state=_grouped(states, true_class),
        states_of_class=_grouped(true_class, states),
        first_aliasing_step=_first_change(states, true_class),
        first_redundancy_step=_first_change(true_class, states),
        final_model_states=len(final),
        final_equivalent=counterexample is None,
        counterexample=counterexample,
        true_class=true_class,
    )
