"""The summary audit: what happened in a run, in numbers.

For a researcher this is the first look at a run: how the model grew (states and transitions
after every change), how hard the strategy worked on it (splits, merges, adds and deletes), how
the world answered (blocked moves, sensations seen), how often the model could not predict a
move at all (steps with no transition), and when the memory started to contradict the model
(the first contradiction, and the last state to become contradictory: a strategy that learns
should stop producing new ones), with the final model's size and determinism.

The operations are counted from the model messages (``operations`` of every ``/rsstp/model``
message, the first included: a strategy may reshape the model at reset); a no-op
(``changed: false``) is not counted. Blocked moves and steps with no transition come from the
steps table, sensations from the memory (every entry ``0 .. T``, the reset's included, as in
the live run summary). Contradictions come from the consistency audit.

A strategy's phases and its stop come from its notes (``rsstp.Event`` 2.1): a note with
``{phase}`` starts that phase at its step, for every step until the next one (the steps before
the first are in none); the share of a phase is its steps over the run's. A note with
``{stop, budget}`` says the strategy ended the run at its step.
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
import pandas as pd

from rsstp_format.records import ModelRecord
from rsstp_replay.audits.compare import HasMemory
from rsstp_replay.audits.consistency import ConsistencyFindings, Sample, audit_consistency
from rsstp_replay.audits.determinism import HasModelVersions
from rsstp_replay.reader import version_heads, version_sizes
from rsstp_sim.errors import ModelError
from rsstp_sim.runner import stop_text
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.words import counted

__all__ = [
    "AuditSource",
    "ModelSize",
    "PhaseShare",
    "Stop",
    "SummaryFindings",
    "audit_summary",
    "phase_changes",
    "phase_shares",
    "strategy_stop",
]


class AuditSource(HasMemory, HasModelVersions, Protocol):
    """What the audits read from a recording (:class:`~rsstp_replay.Recording` has it).

    - ``memory()``: the agent's :class:`~rsstp_sim.memory.Memory`;
    - ``model_versions()``: the ``/rsstp/model`` messages, in order;
    - ``steps(geometry=False)``: one row per step (0 is the reset) with at least the boolean
      columns ``blocked`` and ``no_transition`` (``geometry=False``: the joint positions and
      obstacle distances may be left out, the audits do not read them);
    - ``step_log_times()`` and ``events()``: for the contract's ``log-time`` and
      ``event-in-range`` rules.
    """

    def steps(self, *, geometry: bool = True) -> pd.DataFrame: ...
    def step_log_times(self) -> npt.NDArray[np.int64]: ...
    def events(self) -> pd.DataFrame: ...


@dataclass(frozen=True, slots=True)
class ModelSize:
    """The model's size from step ``step`` on (version ``version``)."""

    version: int
    step: int
    states: int
    transitions: int


@dataclass(frozen=True, slots=True)
class PhaseShare:
    """The steps a strategy spent in ``phase`` (``steps`` of them, a ``share`` of the run's
    steps in ``[0, 1]``)."""

    phase: str
    steps: int
    share: float


@dataclass(frozen=True, slots=True)
class Stop:
    """The strategy ended the run at ``step``, of ``budget`` steps (None: not recorded), for
    ``reason``."""

    step: int
    budget: int | None
    reason: str

    def to_text(self) -> str:
        return f"{stop_text(self.step, self.budget)}: {self.reason}"


@dataclass(frozen=True, slots=True)
class SummaryFindings:
    """The numbers of a run (see the module docstring).

    ``sizes`` has one entry per model version; ``first_contradiction_step`` is the first step at
    which the memory contradicted any state, ``last_contradiction_step`` the latest step at
    which a state became contradictory (the largest ``first_step`` of the consistency audit).
    ``phases``: the steps per phase the strategy recorded, in the order first entered (empty if
    it recorded none); ``stop``: how the strategy ended the run, or None;
    ``consistency_sample``: the steps the contradictions were judged in, when not all were.
    """

    steps: int
    sizes: tuple[ModelSize, ...]
    splits: int
    merges: int
    adds: int
    deletes: int
    blocked: int
    no_transition: int
    sensations_true: int
    sensations_false: int
    contradictory_states: int
    first_contradiction_step: int | None
    last_contradiction_step: int | None
    final_deterministic: bool
    phases: tuple[PhaseShare, ...] = ()
    stop: Stop | None = None
    consistency_sample: Sample | None = None

    @property
    def final_size(self) -> ModelSize:
        """The final model's size."""
        return self.sizes[-1]

    @property
    def operations(self) -> int:
        """Every counted operation."""
        return self.splits + self.merges + self.adds + self.deletes

    def to_frame(self) -> pd.DataFrame:
        """The model size over time: ``version``, ``step``, ``states``, ``transitions`` (int64),
        one row per model version."""
        return pd.DataFrame(
            {
                name: np.array([getattr(size, name) for size in self.sizes], dtype=np.int64)
                for name in ("version", "step", "states", "transitions")
            }
        )

    def to_text(self) -> str:
        """Human readable, one fact per line."""
        final = self.final_size
        verdict = "deterministic" if self.final_deterministic else "nondeterministic"
        if self.first_contradiction_step is None:
            contradictions = "none"
        else:
            contradictions = (
                f"{_plural(self.contradictory_states, 'contradictory state')}, first at step "
                f"{self.first_contradiction_step}, last new one at step "
                f"{self.last_contradiction_step}"
            )
        if self.consistency_sample is not None:
            contradictions += (
                f" (judged in the last {self.consistency_sample.steps:,} steps only, from step "
                f"{self.consistency_sample.first_step:,})"
            )
        phases = ", ".join(
            f"{p.phase} {100 * p.share:.1f} % ({p.steps:,} steps)" for p in self.phases
        )
        return "\n".join(
            ([] if self.stop is None else [self.stop.to_text()])
            + [
                f"steps: {self.steps:,}",
                f"final model: {_plural(final.states, 'state')}, "
                f"{_plural(final.transitions, 'transition')}, {verdict} (version "
                f"{final.version}, from step {final.step}; "
                f"{_plural(len(self.sizes), 'model version')})",
                f"operations: {_plural(self.splits, 'split')}, {_plural(self.merges, 'merge')}, "
                f"{_plural(self.adds, 'add')}, {_plural(self.deletes, 'delete')}",
                f"blocked moves: {self.blocked}",
                f"steps with no transition in the model: {self.no_transition}",
                f"sensations seen: true {self.sensations_true:,}, false {self.sensations_false:,}",
                f"contradictions: {contradictions}",
            ]
            + ([f"phases: {phases}"] if self.phases else [])
        )

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (``sizes`` as a list of rows)."""
        final = self.final_size
        return {
            "steps": self.steps,
            "final_model": {
                "version": final.version,
                "step": final.step,
                "states": final.states,
                "transitions": final.transitions,
                "deterministic": self.final_deterministic,
            },
            "operations": {
                "split": self.splits,
                "merge": self.merges,
                "add": self.adds,
                "delete": self.deletes,
            },
            "blocked": self.blocked,
            "no_transition": self.no_transition,
            "sensations": {"true": self.sensations_true, "false": self.sensations_false},
            "contradictions": {
                "states": self.contradictory_states,
                "first_step": self.first_contradiction_step,
                "last_step": self.last_contradiction_step,
                "sample": None
                if self.consistency_sample is None
                else {
                    "first_step": self.consistency_sample.first_step,
                    "last_step": self.consistency_sample.last_step,
                },
            },
            "phases": {p.phase: {"steps": p.steps, "share": p.share} for p in self.phases},
            "stopped": None
            if self.stop is None
            else {"step": self.stop.step, "budget": self.stop.budget, "reason": self.stop.reason},
            "sizes": [
                {
                    "version": size.version,
                    "step": size.step,
                    "states": size.states,
                    "transitions": size.transitions,
                }
                for size in self.sizes
            ],
        }


def audit_summary(
    source: AuditSource, *, consistency: ConsistencyFindings | None = None
) -> SummaryFindings:
    """Summarise a run (see the module docstring).

    ``consistency`` is the consistency audit of ``source.memory()`` when already at hand (it is
    computed otherwise). Raises :class:`~rsstp_sim.errors.ModelError` when the recording has no
    model message.
    """
    memory = source.memory()
    history: Sequence[ModelRecord] = source.model_versions()
    records = version_heads(history)
    if not records:
        raise ModelError("summary: no model message (a recording has one at step 0)")
    if consistency is None:
        consistency = audit_consistency(memory)
    steps = source.steps(geometry=False)
    kinds = Counter(
        operation.kind for record in records for operation in record.operations if operation.changed
    )
    sensations_true = int(np.count_nonzero(memory.sensations))
    final = history[-1]
    final_model = TransitionSystem.from_snapshot(final.snapshot(), version=final.version)
    contradictions = consistency.contradictions
    events = source.events()
    return SummaryFindings(
        steps=memory.steps,
        sizes=tuple(
            ModelSize(record.version, record.step, n_states, n_transitions)
            for record, n_states, n_transitions in zip(
                records, *(column.tolist() for column in version_sizes(history)), strict=True
            )
        ),
        splits=kinds["split"],
        merges=kinds["merge"],
        adds=kinds["add"],
        deletes=kinds["delete"],
        blocked=int(steps["blocked"].sum()),
        no_transition=int(steps["no_transition"].sum()),
        sensations_true=sensations_true,
        sensations_false=len(memory) - sensations_true,
        contradictory_states=len(contradictions),
        first_contradiction_step=consistency.first_contradiction_step,
        last_contradiction_step=(
            max(found.first_step for found in contradictions) if contradictions else None
        ),
        final_deterministic=final_model.is_deterministic(),
        phases=phase_shares(events, memory.steps),
        stop=strategy_stop(events),
        consistency_sample=consistency.sample,
    )


def _note_data(events: pd.DataFrame, key: str) -> list[tuple[int, dict[str, Any]]]:
    """The notes whose data has ``key``: (step, data), in order."""
    notes = events[events["kind"] == "note"]
    found = []
    quoted = f'"{key}"'
    for step, data in zip(notes["step"].tolist(), notes["data"].tolist(), strict=True):
        if isinstance(data, str):  # JSON text, as Recording.events gives it
            if quoted not in data:
                continue
            data = json.loads(data)
        if isinstance(data, dict) and key in data:
            found.append((int(step), data))
    return found


def phase_changes(events: pd.DataFrame) -> list[tuple[int, str]]:
    """The strategy's phase notes: (step, the phase entered there), in order."""
    return [(step, str(data["phase"])) for step, data in _note_data(events, "phase")]


def phase_shares(events: pd.DataFrame, steps: int) -> tuple[PhaseShare, ...]:
    """The steps ``1 .. steps`` by the phase the strategy's phase notes put them in."""
    changes = phase_changes(events)
    if not changes or steps <= 0:
        return ()
    starts = np.array([max(step, 1) for step, _ in changes] + [steps + 1], dtype=np.int64)
    spans = np.diff(np.minimum(starts, steps + 1))
    totals: dict[str, int] = {}
    for (_, phase), span in zip(changes, spans.tolist(), strict=True):
        totals[phase] = totals.get(phase, 0) + int(span)
    return tuple(PhaseShare(phase, n, n / steps) for phase, n in totals.items())


def strategy_stop(events: pd.DataFrame) -> Stop | None:
    """How the strategy ended the run (its stop note), or None: it did not."""
    stops = _note_data(events, "stop")
    if not stops:
        return None
    step, data = stops[-1]
    budget = data.get("budget")
    return Stop(step, None if budget is None else int(budget), str(data["stop"]))


_plural = counted
