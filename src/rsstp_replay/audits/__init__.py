"""Audits of a memory or recording: what the data itself proves about the learned model.

Each audit returns a frozen findings object with ``to_text()`` and ``to_json()``:

- :func:`compare`: the thesis's ``compare(n, m)`` of two sub-memories;
- :func:`audit_consistency`: every internal state the memory contradicts;
- :func:`audit_determinism`: nondeterministic and empty pairs of every model version;
- :func:`audit_summary`: the numbers of a run;
- :func:`run_audits`: consistency, determinism and summary in one :class:`AuditReport`;
- :func:`audit_truth`: the internal states against the ground truth (aliasing, redundancy,
  equivalence of the final model).

The audits read a recording through :class:`AuditSource` (``memory()``, ``model_versions()``,
``steps()``), so anything with those methods can be audited.
"""

from rsstp_replay.audits.compare import CompareFindings, HasMemory, compare
from rsstp_replay.audits.consistency import (
    ConsistencyFindings,
    StateContradiction,
    Witness,
    audit_consistency,
    find_contradictions,
)
from rsstp_replay.audits.determinism import (
    DeterminismFindings,
    HasModelVersions,
    VersionDeterminism,
    audit_determinism,
)
from rsstp_replay.audits.report import AuditReport, run_audits
from rsstp_replay.audits.summary import AuditSource, ModelSize, SummaryFindings, audit_summary
from rsstp_replay.audits.truth import TruthFindings, TruthSource, audit_truth, step_true_classes

__all__ = [
    "AuditReport",
    "AuditSource",
    "CompareFindings",
    "ConsistencyFindings",
    "DeterminismFindings",
    "HasMemory",
    "HasModelVersions",
    "ModelSize",
    "StateContradiction",
    "SummaryFindings",
    "TruthFindings",
    "TruthSource",
    "VersionDeterminism",
    "Witness",
    "audit_consistency",
    "audit_determinism",
    "audit_summary",
    "audit_truth",
    "compare",
    "find_contradictions",
    "run_audits",
    "step_true_classes",
]
