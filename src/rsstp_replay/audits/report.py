"""All the audits of a recording in one report: summary, consistency, determinism.

This is what ``rsstp-replay audit`` prints. For a researcher the three sections answer, in
order: what did the run do (summary); does the memory itself prove the learned labelling wrong
(consistency: a contradictory state stands for situations the world tells apart, so no
deterministic model with these internal states can be right); and did the strategy end with a
model that knows where every action leads (determinism).

``--fail-on contradiction`` fails when any state is contradictory
(:attr:`AuditReport.has_contradiction`); ``--fail-on nondeterministic`` fails when the *final*
model is nondeterministic (:attr:`AuditReport.has_nondeterminism`). Only the final model
counts: a split makes a model nondeterministic until deletes resolve it, which is the normal
course of the thesis algorithm and no defect; what was learned is the final model.
:attr:`AuditReport.ever_nondeterministic` tells whether any version was.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsstp_replay.audits.consistency import ConsistencyFindings, audit_consistency
from rsstp_replay.audits.determinism import DeterminismFindings, audit_determinism
from rsstp_replay.audits.summary import AuditSource, SummaryFindings, audit_summary
from rsstp_sim.memory import Memory
from rsstp_sim.recording.records import ModelRecord

__all__ = ["AuditReport", "run_audits"]


@dataclass(frozen=True, slots=True)
class AuditReport:
    """The findings of every audit over one recording (see the module docstring)."""

    summary: SummaryFindings
    consistency: ConsistencyFindings
    determinism: DeterminismFindings

    @property
    def has_contradiction(self) -> bool:
        """The memory contradicts at least one internal state."""
        return not self.consistency.consistent

    @property
    def has_nondeterminism(self) -> bool:
        """The final model is nondeterministic (earlier versions do not count)."""
        return not self.determinism.final.deterministic

    @property
    def ever_nondeterministic(self) -> bool:
        """Some model version, the final one or an earlier one, was nondeterministic."""
        return self.determinism.nondeterministic_versions > 0

    def to_text(self) -> str:
        """Sections with headings, for a terminal."""
        consistency = self.consistency
        if consistency.consistent:
            head = f"consistency: no contradictory state in {consistency.steps} steps"
        else:
            count = len(consistency.contradictions)
            head = (
                f"consistency: {count} contradictory state{'' if count == 1 else 's'}, "
                f"first at step {consistency.first_contradiction_step}"
            )
        sections = [
            ("summary", self.summary.to_text()),
            (
                "consistency",
                head if consistency.consistent else head + "\n" + _indent(consistency.to_text()),
            ),
            ("determinism", "determinism: " + self.determinism.to_text()),
        ]
        return "\n\n".join(f"== {title} ==\n{body}" for title, body in sections) + "\n"

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict: one key per audit, and the two verdicts."""
        return {
            "has_contradiction": self.has_contradiction,
            "has_nondeterminism": self.has_nondeterminism,
            "summary": self.summary.to_json(),
            "consistency": self.consistency.to_json(),
            "determinism": self.determinism.to_json(),
        }


def run_audits(source: AuditSource) -> AuditReport:
    """Run the consistency, determinism and summary audits over ``source`` (a recording).

    The memory, the model messages and the steps table are read once, and the memory is
    audited once for consistency (the summary reuses that audit).
    """
    loaded = _Loaded(source.memory(), source.model_versions(), source.steps())
    consistency = audit_consistency(loaded.memory())
    return AuditReport(
        summary=audit_summary(loaded, consistency=consistency),
        consistency=consistency,
        determinism=audit_determinism(loaded),
    )


class _Loaded:
    """A source whose parts were read once (a recording may decode them on every call)."""

    def __init__(self, memory: Memory, models: Sequence[ModelRecord], steps: pd.DataFrame) -> None:
        self._memory, self._models, self._steps = memory, models, steps

    def memory(self) -> Memory:
        return self._memory

    def model_versions(self) -> Sequence[ModelRecord]:
        return self._models

    def steps(self) -> pd.DataFrame:
        return self._steps


def _indent(text: str) -> str:
    return "\n".join(f"  {line}" for line in text.splitlines())
