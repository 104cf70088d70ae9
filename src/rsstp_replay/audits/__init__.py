"""Audits of a memory or recording: what the data itself proves about the learned model.

Each audit returns a frozen findings object with ``to_text()`` and ``to_json()``:

- :func:`compare`: the thesis's ``compare(n, m)`` of two sub-memories;
- :func:`audit_consistency`: every internal state the memory contradicts;
- :func:`audit_determinism`: nondeterministic and empty pairs of every model version;
- :func:`audit_summary`: the numbers of a run;
- :func:`run_audits`: consistency, determinism and summary in one :class:`AuditReport`;
- :func:`audit_consistency_by_version`: the same, inside the model version in force at each
  step (a state id means what its version says);
- :func:`audit_truth`: the verdict (learned, from which step, or why not), and every model
  version against the ground truth (aliasing, redundancy, contradictions, equivalence);
- :func:`explain`: where a run's steps went (phases, the states and classes it kept
  revisiting, the last step it met anything new) and what would have helped;
- :func:`state_roles`: what each state of each version stood for by the truth (exact,
  redundant, aliased, unvisited); :func:`class_roles`, the same per true class;
- :func:`check_contract`: the step records against the model messages, at every step.

The audits read a recording through :class:`AuditSource` (``memory()``, ``model_versions()``,
``steps()``), so anything with those methods can be audited.
"""

from rsstp_replay.audits.class_roles import RoleChanges, class_role_changes, class_roles
from rsstp_replay.audits.compare import CompareFindings, HasMemory, compare
from rsstp_replay.audits.consistency import (
    MAX_STEPS,
    ConsistencyFindings,
    Sample,
    StateContradiction,
    Witness,
    audit_consistency,
    audit_consistency_by_version,
    find_contradictions,
)
from rsstp_replay.audits.contract import ContractFindings, Violation, check_contract
from rsstp_replay.audits.determinism import (
    DeterminismFindings,
    HasModelVersions,
    VersionDeterminism,
    audit_determinism,
)
from rsstp_replay.audits.explanation import Explanation, Visited, explain
from rsstp_replay.audits.report import AuditReport, run_audits
from rsstp_replay.audits.state_roles import ROLE_NAMES, state_roles
from rsstp_replay.audits.summary import AuditSource, ModelSize, SummaryFindings, audit_summary
from rsstp_replay.audits.truth import (
    TruthFindings,
    TruthSource,
    audit_truth,
    step_true_classes,
    truth_table,
)
from rsstp_replay.audits.verdict import Counterexample, Verdict

__all__ = [
    "AuditReport",
    "AuditSource",
    "CompareFindings",
    "ConsistencyFindings",
    "ContractFindings",
    "Counterexample",
    "DeterminismFindings",
    "Explanation",
    "HasMemory",
    "MAX_STEPS",
    "HasModelVersions",
    "ModelSize",
    "ROLE_NAMES",
    "RoleChanges",
    "Sample",
    "StateContradiction",
    "SummaryFindings",
    "TruthFindings",
    "TruthSource",
    "Verdict",
    "VersionDeterminism",
    "Visited",
    "Violation",
    "Witness",
    "audit_consistency",
    "audit_consistency_by_version",
    "audit_determinism",
    "audit_summary",
    "audit_truth",
    "check_contract",
    "class_role_changes",
    "class_roles",
    "compare",
    "explain",
    "find_contradictions",
    "run_audits",
    "state_roles",
    "step_true_classes",
    "truth_table",
]
