"""The sweep's errors: a sweep file that is invalid, a sweep directory that cannot be
read."""

from __future__ import annotations

from rsstp_sim.errors import RsstpError

__all__ = ["ReportError", "SweepError"]


class SweepError(RsstpError):
    """A sweep file is invalid (the message names the file and the key)."""


class ReportError(RsstpError):
    """A sweep directory or a gate cannot be read."""
