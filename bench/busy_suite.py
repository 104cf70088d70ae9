"""The README's test command on a quiet machine, then twice beside a CPU-bound process.

    python bench/busy_suite.py                       # 1 quiet run, 2 busy runs, 1 hog
    python bench/busy_suite.py --quiet-runs 0 --busy-runs 2 --hogs 2

No test may depend on how fast the machine is (issue 30): the suite must pass with the
machine's cores taken by something else. Each run is the README's test command,
``.venv/bin/python -m pytest`` in the repository (this script's own interpreter stands for
the venv's python); the busy runs share the machine with ``--hogs`` processes each spinning a
Python loop (pinned to no core), started before the first busy run and killed after the
last. Each run's output goes to ``--logs``; printed at the end, one row per run: its start
(UTC), wall time, exit code, the counts of pytest's last line and the load average (1 min)
at its start and end.

The machine is shared: what else ran beside it shows in the load at the start of a quiet run.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
HOG = "while True:\n    pass\n"
COUNTS = re.compile(r"(\d+) (passed|failed|errors?|skipped|deselected|xfailed|xpassed)")


@dataclass(frozen=True, slots=True)
class Run:
    """One run of the test command: what it found and how long it took."""

    kind: str  # "quiet" or "busy"
    started: datetime
    seconds: float
    code: int
    counts: dict[str, int]
    load_before: float
    load_after: float
    log: Path

    def row(self) -> str:
        counts = ", ".join(f"{n} {what}" for what, n in self.counts.items()) or "(no summary)"
        return (
            f"{self.kind:<5}  {self.started:%Y-%m-%d %H:%M}  {self.seconds:7.0f} s  "
            f"{self.code:>4}  {self.load_before:5.2f} -> {self.load_after:5.2f}  {counts}"
        )


def run_suite(kind: str, log: Path, pytest_args: list[str]) -> Run:
    """The README's test command once, its output in ``log``."""
    started = datetime.now(UTC)
    load_before = os.getloadavg()[0]
    began = time.perf_counter()
    with log.open("w") as out:
        code = subprocess.run(
            [sys.executable, "-m", "pytest", *pytest_args],
            cwd=ROOT,
            stdout=out,
            stderr=subprocess.STDOUT,
            check=False,
        ).returncode
    seconds = time.perf_counter() - began
    return Run(kind, started, seconds, code, summary(log.read_text()), load_before,
               os.getloadavg()[0], log)  # fmt: skip


def summary(output: str) -> dict[str, int]:
    """The counts of pytest's last summary line ("3 failed, 1200 passed, 2 skipped in ...")."""
    lines = [line for line in output.splitlines() if re.search(r" in [\d.]+s", line)]
    if not lines:
        return {}
    found = {what.rstrip("s") if what.startswith("error") else what: int(n)
             for n, what in COUNTS.findall(lines[-1])}  # fmt: skip
    return found


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quiet-runs", type=int, default=1, help="runs with no hog first")
    parser.add_argument("--busy-runs", type=int, default=2, help="runs beside the hogs")
    parser.add_argument("--hogs", type=int, default=1, help="CPU-bound processes beside them")
    parser.add_argument("--logs", type=Path, help="folder of the runs' output (default: temp)")
    parser.add_argument("pytest_args", nargs="*", help="more arguments for pytest (after --)")
    args = parser.parse_args()
    if min(args.quiet_runs, args.busy_runs, args.hogs) < 0:
        parser.error("the counts of runs and hogs are numbers >= 0")
    logs = args.logs or Path(tempfile.mkdtemp(prefix="busy-suite-"))
    logs.mkdir(parents=True, exist_ok=True)
    print(f"{os.cpu_count()} cores; load {os.getloadavg()[0]:.2f}; output in {logs}", flush=True)
    runs = []
    for n in range(args.quiet_runs):
        runs.append(run_suite("quiet", logs / f"quiet-{n + 1}.txt", args.pytest_args))
        print(runs[-1].row(), flush=True)
    hogs = []
    try:
        if args.busy_runs:
            hogs = [subprocess.Popen([sys.executable, "-c", HOG]) for _ in range(args.hogs)]
        for n in range(args.busy_runs):
            runs.append(run_suite("busy", logs / f"busy-{n + 1}.txt", args.pytest_args))
            print(runs[-1].row(), flush=True)
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
    print(f"\nrun    start (UTC)        wall time  exit  load (1 min)    counts ({args.hogs} hog)")
    for run in runs:
        print(run.row())
    return 0 if all(run.code == 0 for run in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
