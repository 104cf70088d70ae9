"""Simulator commands end to end, as a user runs them: ``--help``, ``run`` and ``record``.

    python bench/sim_commands.py                      # 1,000,000 steps
    python bench/sim_commands.py --steps 10000000     # the long-run figures

Each command runs in a fresh process (``rsstp-sim`` beside this interpreter), cold: its wall
time includes starting Python and the imports; peak memory is the child's maximum RSS
(see ``bench/_cold.py``). ``run`` and ``record`` are ``three-joint --strategy random --seed 1
--quiet``; the recording goes to a temporary folder and its size gives the bytes per step.

Targets (issue "Speed where users feel it"): ``rsstp-sim --help`` <= 0.3 s; ``run`` of a
million steps >= 300,000 steps/s; ``record`` of a million steps >= 150,000 steps/s, <= 2 x
the run's time, <= 80 bytes per step; ``record`` of ten million steps <= 600 MiB peak.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from _cold import measure

BIN = Path(sys.executable).parent
HELP_S = 0.3
RUN_RATE = 300_000
RECORD_RATE = 150_000
RECORD_OVER_RUN = 2.0
BYTES_PER_STEP = 80
LONG_MIB = 600


def _verdict(met: bool) -> str:
    return "met" if met else "NOT met"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    sim = str(BIN / "rsstp-sim")
    walk = ["three-joint", "--strategy", "random", "--seed", "1", "--steps", str(args.steps)]
    print(f"{args.steps:,} random steps of three-joint; load {os.getloadavg()[0]:.1f}")

    helps = [measure([sim, "--help"])[0] for _ in range(max(args.repeat, 3))]
    shown = ", ".join(f"{s:.2f}" for s in helps)
    print(f"--help         {shown} s (target <= {HELP_S:g} s: {_verdict(min(helps) <= HELP_S)})")

    runs = [measure([sim, "run", *walk, "--quiet"]) for _ in range(args.repeat)]
    run_s = min(s for s, _ in runs)
    print(
        f"run            {', '.join(f'{s:.2f}' for s, _ in runs)} s: {args.steps / run_s:,.0f} "
        f"steps/s, peak {max(p for _, p in runs) * 1024:.0f} MiB (target >= {RUN_RATE:,}: "
        f"{_verdict(args.steps / run_s >= RUN_RATE)})"
    )

    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run.mcap"
        records = [
            measure([sim, "record", *walk, "-o", str(out), "--force", "--quiet"])
            for _ in range(args.repeat)
        ]
        size = out.stat().st_size
    record_s = min(s for s, _ in records)
    peak_mib = max(p for _, p in records) * 1024
    rate, ratio, per_step = args.steps / record_s, record_s / run_s, size / (args.steps + 1)
    print(
        f"record         {', '.join(f'{s:.2f}' for s, _ in records)} s: {rate:,.0f} steps/s "
        f"(target >= {RECORD_RATE:,}: {_verdict(rate >= RECORD_RATE)}), {ratio:.2f} x the run "
        f"(target <= {RECORD_OVER_RUN:g}: {_verdict(ratio <= RECORD_OVER_RUN)}), "
        f"{per_step:.1f} bytes/step (target <= {BYTES_PER_STEP}: "
        f"{_verdict(per_step <= BYTES_PER_STEP)}), peak {peak_mib:.0f} MiB"
        + (
            f" (target <= {LONG_MIB} MiB: {_verdict(peak_mib <= LONG_MIB)})"
            if args.steps >= 10_000_000
            else ""
        )
    )
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
