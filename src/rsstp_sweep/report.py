"""A sweep's report: one row per scenario and strategy, a plot, a gate for CI.

For each scenario and strategy (with its parameters) :func:`summarize` gives:

- ``runs``, ``done``, ``failed`` (failed or not run);
- ``learned_fraction``: the share of the sweep's runs (failed ones count as not learned) whose
  final model is equivalent to the ground truth;
- ``learned_at_step_median``, ``learned_at_step_q25``, ``learned_at_step_q75``: over the runs
  that learned (empty when none did);
- ``final_states_median`` and ``minimal_states``: the model's size against the minimal one;
- ``contradictory_states_median`` and ``blocked_median``.

A gate (:func:`check_gate`) is ``METRIC OP NUMBER`` (``<``, ``<=``, ``>``, ``>=``, ``==``,
``!=``), e.g. ``learned_fraction < 0.9``: it holds, and the gate fails, when it is true for
any row; a row with no value for the metric (nobody learned, so no median) fails it too.
"""

from __future__ import annotations

import io
import math
import operator
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsstp_sweep.errors import ReportError

__all__ = [
    "GATE_METRICS",
    "Gate",
    "ReportError",
    "check_gate",
    "parse_gate",
    "plot_report",
    "read_runs",
    "summarize",
    "summary_text",
]


_OPERATORS: dict[str, Callable[[float, float], bool]] = {
    "<=": operator.le,
    ">=": operator.ge,
    "==": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    ">": operator.gt,
}
GATE_METRICS = (
    "runs",
    "done",
    "failed",
    "learned_fraction",
    "learned_at_step_median",
    "learned_at_step_q25",
    "learned_at_step_q75",
    "final_states_median",
    "minimal_states",
    "contradictory_states_median",
    "blocked_median",
)
_STYLES = ["-", "--", ":", "-."]
_GATE = re.compile(r"^\s*([a-z_0-9]+)\s*(<=|>=|==|!=|<|>)\s*([-+]?[0-9.]+(?:[eE][-+]?[0-9]+)?)\s*$")


@dataclass(frozen=True, slots=True)
class Gate:
    """``metric op value``: fails a report when true for any of its rows."""

    metric: str
    op: str
    value: float

    def __str__(self) -> str:
        return f"{self.metric} {self.op} {self.value:g}"


def read_runs(directory: str) -> pd.DataFrame:
    """The ``runs.parquet`` of a sweep's output directory (a folder or fsspec URL)."""
    import fsspec

    from rsstp_sweep.engine import RUNS_TABLE

    try:
        fs, root = fsspec.core.url_to_fs(directory)
        path = f"{root.rstrip('/')}/{RUNS_TABLE}"
        if not fs.exists(path):
            raise ReportError(f"{directory}: no {RUNS_TABLE} (is it a sweep's output folder?)")
        with fs.open(path, "rb") as file:
            data = file.read()
        frame = pd.read_parquet(io.BytesIO(data))
    except ReportError:
        raise
    except Exception as exc:  # a foreign or damaged file: one line
        raise ReportError(f"{directory}: cannot read {RUNS_TABLE}: {exc}") from None
    missing = {"scenario", "strategy", "params", "status", "equivalent"} - set(frame.columns)
    if missing:
        raise ReportError(f"{directory}: {RUNS_TABLE} lacks the column {sorted(missing)[0]!r}")
    return frame


def summarize(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per scenario and strategy (see the module docstring)."""
    rows = []
    for (scenario, strategy, params), group in runs.groupby(
        ["scenario", "strategy", "params"], sort=False
    ):
        done = group[group["status"] == "done"]
        learned = done[done["equivalent"].fillna(False).astype(bool)]
        at = learned["learned_at_step"].dropna().astype(float)
        rows.append(
            {
                "scenario": scenario,
                "strategy": strategy,
                "params": params,
                "runs": len(group),
                "done": len(done),
                "failed": len(group) - len(done),
                "learned_fraction": len(learned) / len(group),
                "learned_at_step_median": at.median() if len(at) else math.nan,
                "learned_at_step_q25": at.quantile(0.25) if len(at) else math.nan,
                "learned_at_step_q75": at.quantile(0.75) if len(at) else math.nan,
                "final_states_median": _median(done["final_states"]),
                "minimal_states": _median(done["minimal_states"]),
                "contradictory_states_median": _median(done["contradictory_states"]),
                "blocked_median": _median(done["blocked"]),
            }
        )
    return pd.DataFrame(rows, columns=["scenario", "strategy", "params", *GATE_METRICS])


def summary_text(summary: pd.DataFrame) -> str:
    """The summary as an aligned text table."""
    shown = pd.DataFrame(
        {
            "scenario": summary["scenario"],
            "strategy": [
                _label(s, p) for s, p in zip(summary["strategy"], summary["params"], strict=True)
            ],
            "runs": summary["runs"],
            "failed": summary["failed"],
            "learned": [f"{f:.0%}" for f in summary["learned_fraction"]],
            "learned at step (median [q25, q75])": [
                "-" if math.isnan(m) else f"{m:,.0f} [{a:,.0f}, {b:,.0f}]"
                for m, a, b in zip(
                    summary["learned_at_step_median"],
                    summary["learned_at_step_q25"],
                    summary["learned_at_step_q75"],
                    strict=True,
                )
            ],
            "states / minimal (median)": [
                "-" if math.isnan(s) else f"{s:,.0f} / {m:,.0f}"
                for s, m in zip(
                    summary["final_states_median"], summary["minimal_states"], strict=True
                )
            ],
        }
    )
    return shown.to_string(index=False)


def parse_gate(text: str) -> Gate:
    """``METRIC OP NUMBER``; :class:`ReportError` names what is wrong."""
    match = _GATE.match(text)
    if match is None:
        raise ReportError(
            f"--fail-if {text!r}: expected METRIC OP NUMBER, e.g. 'learned_fraction < 0.9'"
        )
    metric, op, value = match.groups()
    if metric not in GATE_METRICS:
        raise ReportError(
            f"--fail-if {text!r}: unknown metric {metric!r} (one of {', '.join(GATE_METRICS)})"
        )
    try:
        number = float(value)
    except ValueError:
        raise ReportError(f"--fail-if {text!r}: {value!r} is not a number") from None
    return Gate(metric, op, number)


def check_gate(summary: pd.DataFrame, gate: Gate) -> list[str]:
    """The rows that fail ``gate``, one line each (empty: the gate passes)."""
    test = _OPERATORS[gate.op]
    failing = []
    for row in summary.itertuples(index=False):
        value = float(getattr(row, gate.metric))
        if math.isnan(value) or test(value, gate.value):
            shown = "no value" if math.isnan(value) else f"{value:g}"
            failing.append(
                f"{row.scenario} / {_label(str(row.strategy), str(row.params))}: "
                f"{gate.metric} = {shown}"
            )
    return failing


def plot_report(runs: pd.DataFrame, out: str) -> None:
    """For each scenario, the fraction of runs that have learned (and stay learned) by each
    step, one line per strategy: a step curve from 0 to the sweep's steps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenarios = list(dict.fromkeys(runs["scenario"]))
    fig, axes = plt.subplots(
        1, len(scenarios), figsize=(4.2 * len(scenarios) + 0.8, 3.4), squeeze=False
    )
    for ax, scenario in zip(axes[0], scenarios, strict=True):
        of_scenario = runs[runs["scenario"] == scenario]
        steps = int(of_scenario["steps"].max())
        groups = of_scenario.groupby(["strategy", "params"], sort=False)
        for style, ((strategy, params), group) in zip(_STYLES * len(runs), groups, strict=False):
            learned = group[(group["status"] == "done") & group["equivalent"].fillna(False)]
            at = sorted(float(s) for s in learned["learned_at_step"].dropna())
            xs = [0.0, *at, float(steps)]
            ys = [0.0, *(i / len(group) for i in range(1, len(at) + 1)), len(at) / len(group)]
            label = f"{_label(str(strategy), str(params))} (n={len(group)})"
            ax.step(xs, ys, where="post", linestyle=style, linewidth=1.8, label=label)
        ax.set_title(scenario)
        ax.set_xlabel("step")
        ax.set_xlim(0, max(steps, 1))
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("fraction of runs learned")
    axes[0][-1].legend(loc="lower right", fontsize="small")
    fig.suptitle("Learned by step: equivalent to the ground truth from then to the end")
    fig.tight_layout()
    try:
        fig.savefig(out, dpi=150)
    finally:
        plt.close(fig)


def _median(values: pd.Series[Any]) -> float:
    clean = values.dropna().astype(float)
    return float(clean.median()) if len(clean) else math.nan


def _label(strategy: str, params: str) -> str:
    return strategy if params in ("{}", "", None) else f"{strategy} {params}"
