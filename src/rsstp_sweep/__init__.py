"""Sweeps: many runs on Dask, one table, one report.

- :func:`load_sweep` / :func:`parse_sweep`: a sweep file, checked and expanded into
  :class:`Run` objects (scenario x strategy x grid x seed);
- :func:`run_sweep`: every run on a Dask cluster (a local one by default), each recorded and
  audited by a worker, gathered into ``runs.parquet``;
- :func:`execute_run`: one run, as a worker does it;
- :func:`read_runs`, :func:`summarize`, :func:`plot_report`, :func:`parse_gate`,
  :func:`check_gate`: the report over a sweep's table and its CI gate.

The sweep sits above both the simulator and the replay side: it records with one and audits
with the other.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rsstp_sweep.engine import RUNS_TABLE, SweepResult, run_sweep, runs_frame
    from rsstp_sweep.execute import ROW_FIELDS, execute_run
    from rsstp_sweep.plan import Run, Sweep, SweepError, load_sweep, parse_sweep
    from rsstp_sweep.report import (
        GATE_METRICS,
        Gate,
        ReportError,
        check_gate,
        parse_gate,
        plot_report,
        read_runs,
        summarize,
        summary_text,
    )

_HOME = {
    **dict.fromkeys(["RUNS_TABLE", "SweepResult", "run_sweep", "runs_frame"], "engine"),
    **dict.fromkeys(["ROW_FIELDS", "execute_run"], "execute"),
    **dict.fromkeys(["Run", "Sweep", "SweepError", "load_sweep", "parse_sweep"], "plan"),
    **dict.fromkeys(
        ["GATE_METRICS", "Gate", "ReportError", "check_gate", "parse_gate", "plot_report"]
        + ["read_runs", "summarize", "summary_text"],
        "report",
    ),
}


def __getattr__(name: str) -> Any:
    """The public names, imported on first use: the command lines register the sweep's
    commands without paying for pandas or Dask."""
    if name not in _HOME:
        raise AttributeError(f"module 'rsstp_sweep' has no attribute {name!r}")
    return getattr(importlib.import_module(f"rsstp_sweep.{_HOME[name]}"), name)


__all__ = [
    "GATE_METRICS",
    "ROW_FIELDS",
    "RUNS_TABLE",
    "Gate",
    "ReportError",
    "Run",
    "Sweep",
    "SweepError",
    "SweepResult",
    "check_gate",
    "execute_run",
    "load_sweep",
    "parse_gate",
    "parse_sweep",
    "plot_report",
    "read_runs",
    "run_sweep",
    "runs_frame",
    "summarize",
    "summary_text",
]
