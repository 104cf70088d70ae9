"""Audits of a memory or recording: what the data itself proves about the learned model."""

from rsstp_replay.audits.consistency import (
    ConsistencyFindings,
    StateContradiction,
    Witness,
    audit_consistency,
    find_contradictions,
)

__all__ = [
    "ConsistencyFindings",
    "StateContradiction",
    "Witness",
    "audit_consistency",
    "find_contradictions",
]
