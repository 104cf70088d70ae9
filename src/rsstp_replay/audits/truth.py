"""The truth audit: did the run learn the world, and what did its internal states stand for.

The world is finite; its reachable poses, labelled with their sensation, form a
deterministic Moore machine whose minimisation is the smallest correct model
(:mod:`rsstp_sim.truth`). Every step of a recording has a pose, so every step
has a *true class*: the state of that minimal machine.

The audit opens with a **verdict** (:mod:`rsstp_replay.audits.verdict`): learned, from
which step, or not learned and the shortest action sequence that shows it. Then each
model version is judged on its own, since a state id means what its version says (a
split narrows a state, a merge widens it): for every version, over the steps it was in
force, which of its states stood for several true classes, which classes it spread over
several states, which of its states the memory contradicts, and whether it was
equivalent to the truth (:attr:`TruthFindings.versions`, one row per version, for pandas).
Last, the same figures accumulated over the whole history, state ids across versions:

- **aliasing**: one internal state stood for several true classes. The agent
  confuses situations that behave differently; a deterministic model with that
  labelling cannot predict correctly.
- **redundancy**: one true class was represented by several internal states. The
  agent split a behaviour over several states it cannot tell apart (the thesis
  algorithm's failure: it never recognises a state it already created).
- **first mismatch**: the first step at which the correspondence between
  internal states and true classes stopped being one to one.

Those accumulated figures read a successful learner as a failure (its early versions
reused state ids that meant something else then); they stay, labelled as such, because a
strategy that should never change its mind is judged by them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import pandas as pd
from numpy.typing import NDArray

from rsstp_format.records import ModelRecord
from rsstp_replay.audits._columns import first_indices
from rsstp_replay.audits.consistency import (
    MAX_STEPS,
    ConsistencyFindings,
    Sample,
    audit_consistency_by_version,
)
from rsstp_replay.audits.contract import version_index
from rsstp_replay.audits.loaded import load
from rsstp_replay.audits.verdict import Counterexample, Verdict, judge_versions
from rsstp_replay.reader import version_heads, version_sizes
from rsstp_sim.arrays import distinct
from rsstp_sim.memory import Memory
from rsstp_sim.scenario import AnyScenario
from rsstp_sim.truth import GroundTruth
from rsstp_sim.truth.cache import load_truth
from rsstp_sim.words import counted

__all__ = ["TruthFindings", "TruthSource", "audit_truth", "step_true_classes", "truth_table"]


class TruthSource(Protocol):
    """What the truth audit reads from a recording."""

    @property
    def scenario(self) -> AnyScenario: ...
    @property
    def n_steps(self) -> int: ...
    def steps(self, *, geometry: bool = True) -> pd.DataFrame: ...
    def memory(self) -> Memory: ...
    def model_versions(self) -> Sequence[ModelRecord]: ...
    def step_log_times(self) -> NDArray[np.int64]: ...
    def events(self) -> pd.DataFrame: ...


def step_true_classes(steps: pd.DataFrame, truth: GroundTruth) -> NDArray[np.int64]:
    """The true class of every row's pose (the truth's ``value_names`` columns)."""
    return truth.classes_of_table(steps)


def truth_table(
    source: TruthSource, *, truth: GroundTruth | None = None, findings: TruthFindings | None = None
) -> pd.DataFrame:
    """The steps table with the ground truth of every step: ``true_class`` (int64), ``pose``
    (int64, the pose's index among the scenario's reachable poses, as in
    :class:`~rsstp_sim.truth.GroundTruth`) and ``aliased`` (bool: the step's internal state
    stood for several true classes under the model version in force, over that version's
    steps). ``findings`` is the truth audit when already at hand."""
    truth = load_truth(source.scenario) if truth is None else truth
    findings = audit_truth(source, truth=truth) if findings is None else findings
    table = source.steps()
    columns = list(truth.value_names)
    table["true_class"] = findings.true_class
    table["pose"] = truth.poses_of(table[columns].to_numpy(dtype=np.int64))
    table["aliased"] = findings.aliased_step
    return table


def _codes(values: NDArray[np.int64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The distinct values, sorted, and each value's index among them."""
    distinct, codes = np.unique(values, return_inverse=True)
    return distinct, codes.astype(np.int64)


def _pairs(keys: NDArray[np.int64], values: NDArray[np.int64]) -> NDArray[np.int64]:
    """The distinct ``(key, value)`` pairs, sorted, shape ``(P, 2)`` (one integer sort, not a
    row-wise ``unique``)."""
    if not len(keys):
        return np.empty((0, 2), np.int64)
    low = min(int(keys.min()), int(values.min()))
    width = int(values.max()) + 1
    if low >= 0 and (int(keys.max()) + 1) * width < 2**62:  # one sort of packed pairs
        packed = distinct(keys * width + values)
        return np.stack([packed // width, packed % width], axis=1)
    key_ids, key_codes = _codes(keys)
    value_ids, value_codes = _codes(values)
    combined = distinct(key_codes * len(value_ids) + value_codes)
    return np.stack(
        [key_ids[combined // len(value_ids)], value_ids[combined % len(value_ids)]], axis=1
    )


def _first_change(keys: NDArray[np.int64], values: NDArray[np.int64]) -> int | None:
    """First index where a key is seen with a value other than the one it first had."""
    if len(keys) and int(keys.min()) >= 0 and int(keys.max()) < 4 * len(keys) + 2**16:
        first = first_indices(keys)  # no sort of a long run's steps
        differs = values != values[first[keys]]
    else:
        _, at, inverse = np.unique(keys, return_index=True, return_inverse=True)
        differs = values != values[at][inverse]
    return int(np.argmax(differs)) if differs.any() else None


def _grouped_counts(keys: NDArray[np.int64], values: NDArray[np.int64]) -> NDArray[np.int64]:
    """For every row, how many distinct values its key has over all rows."""
    pairs = _pairs(keys, values)
    distinct_keys, per_key = np.unique(pairs[:, 0], return_counts=True)
    return np.asarray(per_key[np.searchsorted(distinct_keys, keys)], np.int64)


def _grouped(keys: NDArray[np.int64], values: NDArray[np.int64]) -> dict[int, tuple[int, ...]]:
    pairs = _pairs(keys, values)
    if not len(pairs):
        return {}
    starts = np.flatnonzero(np.r_[True, pairs[1:, 0] != pairs[:-1, 0]])
    groups = np.split(pairs[:, 1], starts[1:])
    return {
        int(pairs[start, 0]): tuple(group.tolist())
        for start, group in zip(starts, groups, strict=True)
    }


@dataclass(frozen=True)
class TruthFindings:
    """The truth audit of one recording (see the module docstring for what each part means).

    ``versions`` has one row per model version: ``version``, ``step`` (the step it came into
    force), ``last_step`` (the last step it was in force; ``step - 1`` for a version replaced
    within its own step), ``steps_in_force``, ``states``, ``transitions``, ``deterministic``,
    ``aliased_states`` and ``redundant_classes`` (over its steps), ``contradictory_states`` (the
    memory's contradictions between two times in the same state of this version) and
    ``equivalent`` (to the truth, where it came into force). ``aliased_step`` says per step
    whether its internal state stood for several true classes under its version.
    ``consistency_sample``: the steps ``contradictory_states`` was judged in, when not all were.
    """

    scenario: str
    reachable_poses: int
    minimal_states: int
    steps: int
    verdict: Verdict
    versions: pd.DataFrame = field(repr=False, compare=False)
    classes_of_state: Mapping[int, tuple[int, ...]]
    states_of_class: Mapping[int, tuple[int, ...]]
    first_aliasing_step: int | None
    first_redundancy_step: int | None
    final_aliased: Mapping[int, tuple[int, ...]]
    final_redundant: Mapping[int, tuple[int, ...]]
    true_class: NDArray[np.int64] = field(repr=False, compare=False)
    aliased_step: NDArray[np.bool_] = field(repr=False, compare=False)
    consistency_sample: Sample | None = None

    @property
    def learned_at_step(self) -> int | None:
        return self.verdict.learned_at_step

    @property
    def counterexample(self) -> Counterexample | None:
        return self.verdict.counterexample

    @property
    def aliased(self) -> dict[int, tuple[int, ...]]:
        """Over the whole history: internal states that stood for several true classes."""
        return {s: c for s, c in self.classes_of_state.items() if len(c) > 1}

    @property
    def redundant(self) -> dict[int, tuple[int, ...]]:
        """Over the whole history: true classes represented by several internal states."""
        return {c: s for c, s in self.states_of_class.items() if len(s) > 1}

    @property
    def first_mismatch_step(self) -> int | None:
        """Over the whole history: the first step where states and classes stopped
        corresponding one to one."""
        found = [s for s in (self.first_aliasing_step, self.first_redundancy_step) if s is not None]
        return min(found) if found else None

    @property
    def classes_visited(self) -> int:
        return len(self.states_of_class)

    def to_text(self, *, verdict: bool = True) -> str:
        """The audit for a terminal; ``verdict=False`` leaves out the verdict (shown first)."""
        table = self.versions
        lines = [
            *([self.verdict.to_text()] if verdict else []),
            f"truth: {self.scenario}: {counted(self.reachable_poses, 'reachable pose')}, minimal "
            f"model {counted(self.minimal_states, 'state')}; the run visited "
            f"{counted(self.classes_visited, 'class', 'classes')} in "
            f"{counted(self.steps, 'step')}",
            f"within each model version ({counted(len(table), 'version')}; a state id means "
            f"what its version says):",
        ]
        for column, what in (
            ("aliased_states", "a state stood for several true classes"),
            ("redundant_classes", "a true class was spread over several states"),
            ("contradictory_states", "the memory contradicts a state"),
        ):
            sampled = ""
            if column == "contradictory_states" and self.consistency_sample is not None:
                sampled = f" (judged in steps {self.consistency_sample.first_step:,}.. only)"
            lines.append(f"  {what}: {_versions_with(table, column)}{sampled}")
        for state, classes in sorted(self.final_aliased.items())[:10]:
            lines.append(f"    final version: state {state:,} stood for classes {_short(classes)}")
        for cls, states in sorted(self.final_redundant.items())[:10]:
            lines.append(f"    final version: class {cls:,} was in states {_short(states)}")
        equivalent = table.loc[table["equivalent"]]
        lines.append(
            f"  equivalent to the truth: {counted(len(equivalent), 'version')}"
            + (
                f", the first at step {int(equivalent['step'].iloc[0]):,}"
                if len(equivalent)
                else ""
            )
        )
        aliased, redundant = self.aliased, self.redundant
        lines.append(
            "accumulated over the whole history (state ids across versions, so a state "
            "counts what it meant in every version):"
        )
        lines.append(
            f"  aliasing: {counted(len(aliased), 'internal state')} stood for several true classes"
            + (f", first at step {self.first_aliasing_step:,}" if aliased else "")
        )
        lines.append(
            f"  redundancy: {counted(len(redundant), 'true class', 'true classes')} were split "
            f"over several internal states"
            + (f", first at step {self.first_redundancy_step:,}" if redundant else "")
        )
        if self.first_mismatch_step is None:
            lines.append("  the internal states matched the true classes one to one at every step")
        else:
            lines.append(f"  first mismatch at step {self.first_mismatch_step:,}")
        return "\n".join(lines) + "\n"

    def to_json(self) -> dict[str, Any]:
        counterexample = self.counterexample
        return {
            "verdict": self.verdict.to_json(),
            "learned_at_step": self.learned_at_step,
            "counterexample": None if counterexample is None else counterexample.to_json(),
            "scenario": self.scenario,
            "reachable_poses": self.reachable_poses,
            "minimal_states": self.minimal_states,
            "steps": self.steps,
            "final_model_states": self.verdict.final_states,
            "final_equivalent": self.verdict.learned,
            "final_version": {
                "aliased_states": {str(s): list(c) for s, c in sorted(self.final_aliased.items())},
                "redundant_classes": {
                    str(c): list(s) for c, s in sorted(self.final_redundant.items())
                },
            },
            "versions": {
                column: self.versions[column].tolist() for column in self.versions.columns
            },
            "consistency_sample": None
            if self.consistency_sample is None
            else {
                "first_step": self.consistency_sample.first_step,
                "last_step": self.consistency_sample.last_step,
            },
            "history": {
                "classes_visited": self.classes_visited,
                "internal_states_visited": len(self.classes_of_state),
                "aliased_states": {str(s): list(c) for s, c in sorted(self.aliased.items())},
                "redundant_classes": {str(c): list(s) for c, s in sorted(self.redundant.items())},
                "first_aliasing_step": self.first_aliasing_step,
                "first_redundancy_step": self.first_redundancy_step,
                "first_mismatch_step": self.first_mismatch_step,
            },
        }


def _versions_with(table: pd.DataFrame, column: str) -> str:
    """``in N versions, the last at steps a..b (version v); none in the final version``."""
    hit = table.loc[table[column] > 0]
    if not len(hit):
        return "in no version"
    last = hit.iloc[-1]
    final = int(table[column].iloc[-1])
    return (
        f"in {len(hit):,} of {counted(len(table), 'version')}, the last version "
        f"{int(last['version']):,} (steps {int(last['step']):,}..{int(last['last_step']):,})"
        + ("; none in the final version" if final == 0 else f"; {final:,} in the final version")
    )


def _short(values: tuple[int, ...], limit: int = 12) -> str:
    shown = ", ".join(f"{v:,}" for v in values[:limit])
    return f"[{shown}{', ...' if len(values) > limit else ''}] ({len(values):,})"


def audit_truth(
    source: TruthSource,
    *,
    truth: GroundTruth | None = None,
    within_versions: ConsistencyFindings | None = None,
    consistency_steps: int | None = MAX_STEPS,
) -> TruthFindings:
    """Run the truth audit. The ground truth is computed unless ``truth`` is given, and the
    consistency audit within versions unless ``within_versions`` is (an
    :class:`~rsstp_replay.audits.report.AuditReport` has it), in the last
    ``consistency_steps`` steps of a longer memory (None: every step)."""
    truth = load_truth(source.scenario) if truth is None else truth
    loaded = load(source)
    steps = loaded.steps()
    true_class = step_true_classes(steps, truth)
    memory = loaded.memory()
    history = loaded.model_versions()
    versions = version_heads(history)
    states = np.asarray(memory.internal_states, dtype=np.int64)
    index = version_index(versions, np.arange(len(states), dtype=np.int64))
    columns = list(truth.value_names)
    verdict, equivalent = judge_versions(
        history,
        truth=truth,
        states=states,
        sensations=np.asarray(memory.sensations, np.bool_),
        true_class=true_class,
        actions=np.asarray(memory.actions),  # the table's action column, -1 at step 0
        angles=np.stack([steps[name].to_numpy() for name in columns], axis=1),
    )

    # Within each version: keys (version index, state) and (version index, class).
    width_state = int(states.max(initial=0)) + 1
    width_class = truth.n_classes
    # One key column at a time: a long run's columns are the audit's memory.
    aliased_step = _grouped_counts(index * width_state + states, true_class) > 1
    redundant_step = _grouped_counts(index * width_class + true_class, states) > 1
    n = len(versions)
    aliased_states = _distinct_per_version(index[aliased_step], states[aliased_step], n)
    redundant_classes = _distinct_per_version(index[redundant_step], true_class[redundant_step], n)
    contradictions = within_versions or audit_consistency_by_version(
        memory, steps["model_version"].to_numpy(np.int64), max_steps=consistency_steps
    )
    numbers = [record.version for record in versions]
    contradicted = np.zeros(n, np.int64)
    position = {version: k for k, version in enumerate(numbers)}
    for found in contradictions.contradictions:
        assert found.version is not None
        contradicted[position[found.version]] += 1

    starts = np.fromiter((record.step for record in versions), np.int64, n)
    n_states, n_transitions = version_sizes(history)
    ends = np.r_[starts[1:], len(states)] - 1
    table = pd.DataFrame(
        {
            "version": np.asarray(numbers, np.int64),
            "step": starts,
            "last_step": ends,
            "steps_in_force": np.maximum(ends - starts + 1, 0),
            "states": n_states,
            "transitions": n_transitions,
            "deterministic": np.fromiter((r.deterministic for r in versions), np.bool_, n),
            "aliased_states": aliased_states,
            "redundant_classes": redundant_classes,
            "contradictory_states": contradicted,
            "equivalent": equivalent,
        }
    )
    last = index == n - 1
    return TruthFindings(
        scenario=truth.scenario_name,
        reachable_poses=truth.n_poses,
        minimal_states=truth.n_classes,
        steps=len(states) - 1,
        verdict=verdict,
        versions=table,
        classes_of_state=_grouped(states, true_class),
        states_of_class=_grouped(true_class, states),
        first_aliasing_step=_first_change(states, true_class),
        first_redundancy_step=_first_change(true_class, states),
        final_aliased={
            s: c for s, c in _grouped(states[last], true_class[last]).items() if len(c) > 1
        },
        final_redundant={
            c: s for c, s in _grouped(true_class[last], states[last]).items() if len(s) > 1
        },
        true_class=true_class,
        aliased_step=aliased_step,
        consistency_sample=contradictions.sample,
    )


def _distinct_per_version(
    version: NDArray[np.int64], values: NDArray[np.int64], n: int
) -> NDArray[np.int64]:
    """How many distinct values each version index ``0 .. n-1`` has."""
    pairs = _pairs(version, values)
    return np.bincount(pairs[:, 0], minlength=n).astype(np.int64)
