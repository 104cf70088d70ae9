"""All the audits of a recording in one report: summary, consistency, determinism.

This is what ``rsstp-replay audit`` prints. For a researcher the three sections answer, in
order: what did the run do (summary); does the memory itself prove the learned labelling wrong
(consistency: a contradictory state stands for situations the world tells apart, so no
deterministic model with these internal states can be right); and did the strategy end with a
model that knows where every action leads (determinism).

Contradictions are judged inside the model version in force at each step
(:attr:`AuditReport.within_versions`): a state id means what its version says, and a learner
that split a contradicted state has fixed it. The same audit over the whole history, state ids
across versions (:attr:`AuditReport.consistency`), stays below it, labelled as such.

``--fail-on contradiction`` fails when the memory contradicts a state of the *final* model
version, over the steps it was in force (:attr:`AuditReport.has_contradiction`);
``--fail-on nondeterministic`` fails when the *final* model is nondeterministic
(:attr:`AuditReport.has_nondeterminism`). Only the final model counts: a split makes a model
nondeterministic until deletes resolve it, which is the normal course of learning and no
defect; what was learned is the final model. :attr:`AuditReport.ever_nondeterministic` and
:attr:`AuditReport.ever_contradicted` tell whether any version was.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rsstp_replay.audits.consistency import (
    MAX_STEPS,
    ConsistencyFindings,
    audit_consistency,
    audit_consistency_both,
)
from rsstp_replay.audits.contract import ContractFindings, check_contract
from rsstp_replay.audits.determinism import DeterminismFindings, audit_determinism
from rsstp_replay.audits.loaded import load
from rsstp_replay.audits.summary import AuditSource, SummaryFindings, audit_summary
from rsstp_sim.words import counted

__all__ = ["AuditReport", "run_audits"]


@dataclass(frozen=True, slots=True)
class AuditReport:
    """The findings of every audit over one recording (see the module docstring)."""

    summary: SummaryFindings
    consistency: ConsistencyFindings
    determinism: DeterminismFindings
    within_versions: ConsistencyFindings
    contract: ContractFindings

    @property
    def has_contradiction(self) -> bool:
        """The memory contradicts a state of the final model version (earlier versions do not
        count)."""
        final = self.determinism.final.version
        return any(found.version == final for found in self.within_versions.contradictions)

    @property
    def ever_contradicted(self) -> bool:
        """The memory contradicted a state of some version, the final one or an earlier one."""
        return not self.within_versions.consistent

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
        sections = [
            ("summary", self.summary.to_text()),
            ("consistency", self._consistency_text()),
            ("determinism", "determinism: " + self.determinism.to_text()),
            ("contract", self.contract.to_text()),
        ]
        return "\n\n".join(f"== {title} ==\n{body}" for title, body in sections) + "\n"

    def _consistency_text(self) -> str:
        within, history = self.within_versions, self.consistency
        final = self.determinism.final.version
        in_final = [f for f in within.contradictions if f.version == final]
        sampled = [] if within.sample is None else [within.sample.to_text()]
        if within.consistent:
            steps = counted(within.steps, "step")
            lines = [f"within each model version: no contradictory state in {steps}"]
        else:
            versions = len({found.version for found in within.contradictions})
            last = max(within.contradictions, key=lambda found: found.first_step)
            lines = [
                f"within each model version: {_plural(len(within.contradictions), 'state')} "
                f"contradicted in {_plural(versions, 'version')}, first at step "
                f"{within.first_contradiction_step}, last at step {last.first_step}; "
                + (
                    "none in the final version"
                    if not in_final
                    else f"{len(in_final)} in the final version (version {final})"
                )
            ]
            shown = in_final or list(within.contradictions[-_TEXT_LIMIT:])
            lines += [f"  {line}" for line in _short_text(ConsistencyFindings(tuple(shown), 0))]
        lines = sampled + lines
        if history.consistent:
            lines.append(
                "accumulated over the whole history: no contradictory state in "
                f"{counted(history.steps, 'step')}"
            )
        else:
            lines.append(
                f"accumulated over the whole history (state ids across versions): "
                f"{_plural(len(history.contradictions), 'contradictory state')}, first at step "
                f"{history.first_contradiction_step}"
            )
            lines += [f"  {line}" for line in _short_text(history)]
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict: one key per audit, and the verdicts."""
        return {
            "has_contradiction": self.has_contradiction,
            "ever_contradicted": self.ever_contradicted,
            "has_nondeterminism": self.has_nondeterminism,
            "summary": self.summary.to_json(),
            "consistency_within_versions": self.within_versions.to_json(),
            "consistency": self.consistency.to_json(),
            "determinism": self.determinism.to_json(),
            "contract": self.contract.to_json(),
        }


def run_audits(source: AuditSource, *, consistency_steps: int | None = MAX_STEPS) -> AuditReport:
    """Run the consistency, determinism, summary and contract audits over ``source`` (a
    recording, or a :class:`~rsstp_replay.audits.loaded.LoadedRecording` of one).

    The memory, the model messages and the steps table are read once, and the memory is
    audited once for consistency (the summary reuses that audit): in its last
    ``consistency_steps`` steps when it is longer (None: every step), which the findings say
    (:attr:`ConsistencyFindings.sample`).
    """
    loaded = load(source)
    steps, memory = loaded.steps(), loaded.memory()
    versions = steps["model_version"].to_numpy(np.int64)
    if len(versions) and (versions == versions[0]).all():  # one version: the same audit
        consistency = audit_consistency(memory, max_steps=consistency_steps)
        within = ConsistencyFindings(
            tuple(replace(found, version=int(versions[0])) for found in consistency.contradictions),
            consistency.steps,
            consistency.sample,
        )
    else:
        consistency, within = audit_consistency_both(memory, versions, max_steps=consistency_steps)
    return AuditReport(
        summary=audit_summary(loaded, consistency=consistency),
        consistency=consistency,
        determinism=audit_determinism(loaded),
        within_versions=within,
        contract=check_contract(loaded),
    )


_TEXT_LIMIT = 10
"""Contradicted states listed in the text (all are in the JSON)."""


def _short_text(findings: ConsistencyFindings) -> list[str]:
    lines = findings.to_text().splitlines() if findings.contradictions else []
    if len(lines) > _TEXT_LIMIT:
        return [*lines[:_TEXT_LIMIT], f"... and {len(lines) - _TEXT_LIMIT} more (see --json)"]
    return lines


_plural = counted
