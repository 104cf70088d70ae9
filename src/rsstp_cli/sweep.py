"""The two sweep commands: ``rsstp-sim sweep`` and ``rsstp-replay report``.

Each CLI registers its parser here (:func:`add_sweep_parser`, :func:`add_report_parser`) and
imports this package only when the command runs, so the other commands do not pay for Dask.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Mapping
from typing import Any

__all__ = ["add_report_parser", "add_sweep_parser"]


def add_sweep_parser(sub: Any) -> None:
    """``sweep SWEEP.toml -o DIR [--workers N] [--scheduler ADDRESS] [--quiet]``."""
    p = sub.add_parser("sweep", help="many runs on Dask: one recording each and runs.parquet")
    p.add_argument("sweep", help="the sweep file (.toml; see the README)")
    p.add_argument("-o", "--output", required=True, help="output folder or fsspec URL")
    p.add_argument(
        "--workers",
        type=_positive,
        default=None,
        help="worker processes of the local cluster (default: the core count)",
    )
    p.add_argument(
        "--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, e.g. tcp://host:8786"
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar (none when piped)")
    p.set_defaults(func=_cmd_sweep)


def add_report_parser(sub: Any) -> None:
    """``report DIR [--json] [--plot OUT.png] [--fail-if EXPR]``."""
    p = sub.add_parser("report", help="a sweep's table per scenario and strategy, a plot, a gate")
    p.add_argument("directory", help="a sweep's output folder (or fsspec URL)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--plot", metavar="OUT.png", help="plot the learned fraction against steps")
    p.add_argument("--force", action="store_true", help="overwrite an existing plot")
    p.add_argument(
        "--strategy",
        action="append",
        default=[],
        metavar="NAME",
        help="report only these strategies (repeatable), e.g. to gate the learner alone",
    )
    p.add_argument(
        "--fail-if",
        action="append",
        default=[],
        metavar="EXPR",
        help="exit 1 when true for a row, e.g. 'learned_fraction < 0.9' (repeatable)",
    )
    p.set_defaults(func=_cmd_report)


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}")
    return value


def _cmd_sweep(args: argparse.Namespace) -> int:
    from rsstp_cli._commandline import UsageError, progress
    from rsstp_sweep.engine import RUNS_TABLE, run_sweep
    from rsstp_sweep.plan import load_sweep

    if args.workers is not None and args.scheduler is not None:
        raise UsageError("--workers sizes the local cluster: give it or --scheduler, not both")
    sweep = load_sweep(args.sweep)
    _check_output(args.output)
    prog = "rsstp-sim"
    failed: list[str] = []
    counts = {"done": 0, "reused": 0}
    with progress(len(sweep.runs), "sweep", unit="run", quiet=args.quiet) as bar:

        def on_row(row: Mapping[str, Any]) -> None:
            if row["status"] == "failed":
                failed.append(row["run"])
                print(f"{prog}: run {row['run']} failed: {row['error']}", file=sys.stderr)
            else:
                counts["done"] += 1
                counts["reused"] += bool(row["reused"])
            bar.stage(f"sweep ({len(failed)} failed)" if failed else "sweep")
            bar.to(counts["done"] + len(failed))

        result = run_sweep(
            sweep, args.output, workers=args.workers, scheduler=args.scheduler, on_row=on_row
        )
    where = f"{args.output.rstrip('/')}/{RUNS_TABLE}"
    reused = f" ({counts['reused']} kept from before)" if counts["reused"] else ""
    print(
        f"{counts['done']} of {len(sweep.runs)} runs done{reused}, {len(failed)} failed; "
        f"table: {where}"
    )
    if result.interrupted:
        print(f"{prog}: interrupted: kept {counts['done']} finished runs", file=sys.stderr)
        return 130
    return 1 if failed else 0


def _check_output(output: str) -> None:
    """An output that cannot be a folder is one line before the cluster starts."""
    import fsspec
    from fsspec.implementations.local import LocalFileSystem

    from rsstp_cli._commandline import UsageError

    try:
        fs, root = fsspec.core.url_to_fs(output)
        if fs.exists(root) and not fs.isdir(root):
            raise UsageError(f"{output}: exists and is not a folder")
        parent = os.path.dirname(root.rstrip("/")) or "."  # the folder may be new, not its parent
        local = isinstance(fs, LocalFileSystem)  # an object store has no folders to miss
        if local and not fs.isdir(parent):
            raise UsageError(f"{output}: the output directory {parent} does not exist")
        fs.makedirs(root, exist_ok=True)
        probe = f"{root.rstrip('/')}/.rsstp-write-test"
        with fs.open(probe, "wb") as file:
            file.write(b"")
        fs.rm(probe)
    except UsageError:
        raise
    except (OSError, ValueError, ImportError) as exc:
        raise UsageError(f"{output}: cannot write the sweep there: {exc}") from None


def _cmd_report(args: argparse.Namespace) -> int:
    from rsstp_cli._commandline import UsageError
    from rsstp_sweep import report

    gates = [report.parse_gate(text) for text in args.fail_if]  # a bad gate before any work
    if args.plot is not None and os.path.exists(args.plot) and not args.force:
        raise UsageError(f"{args.plot}: already exists (use --force to overwrite)")
    runs = report.read_runs(args.directory)
    if args.strategy:
        unknown = sorted(set(args.strategy) - set(runs["strategy"]))
        if unknown:
            known = ", ".join(sorted(set(runs["strategy"])))
            raise UsageError(f"--strategy {unknown[0]}: not in this sweep ({known})")
        runs = runs[runs["strategy"].isin(args.strategy)]
    summary = report.summarize(runs)
    if args.json:
        records = [
            {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in row.items()}
            for row in summary.to_dict(orient="records")
        ]
        print(json.dumps(records, indent=2, default=_plain))
    else:
        print(report.summary_text(summary))
    if args.plot is not None:
        try:
            report.plot_report(runs, args.plot)
        except (OSError, ValueError) as exc:
            raise UsageError(f"{args.plot}: cannot write the plot: {exc}") from None
        if not args.json:
            print(f"wrote {args.plot}")
    failing = [(gate, line) for gate in gates for line in report.check_gate(summary, gate)]
    for gate, line in failing:
        print(f"rsstp-replay: report failed --fail-if '{gate}': {line}", file=sys.stderr)
    return 1 if failing else 0


def _plain(value: object) -> object:
    """numpy scalars as Python numbers for JSON."""
    item = getattr(value, "item", None)
    return item() if callable(item) else str(value)
