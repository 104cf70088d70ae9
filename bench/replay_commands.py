"""Replay commands end to end, as a user runs them: ``table``, ``audit``, ``audit --truth``.

    python bench/replay_commands.py                  # 1,000,000 steps
    python bench/replay_commands.py --steps 10000000 --only audit

Each command runs in a fresh process (``rsstp-replay`` beside this interpreter), cold: its
wall time includes starting Python and the imports. Peak memory is the child's maximum RSS
(``resource.getrusage(RUSAGE_CHILDREN)`` of a fresh runner process per command). The recording
is ``rsstp-sim record three-joint --strategy random --seed 1 --steps N``, made once and kept as
``/tmp/rsstp-bench-three-joint-N.mcap``. The machine's load average is printed: these are
wall-clock figures and other work slows them.

Targets (issue "Speed where users feel it", point 5), a million steps: ``table`` to parquet
<= 3 s, ``audit`` <= 5 s, ``audit --truth`` <= 10 s, each <= 1.5 GiB; ten million steps:
``audit`` within 3 GiB and (issue 21, point 3) at most 200 bytes a step.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from _cold import measure
from _recordings import random_three_joint

BIN = Path(sys.executable).parent
TARGETS_1M = {"table": (3.0, 1.5), "audit": (5.0, 1.5), "audit --truth": (10.0, 1.5)}
TARGET_10M_GIB = 3.0
TARGET_10M_BYTES_PER_STEP = 200


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--only", choices=sorted(TARGETS_1M), action="append")
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    mcap = random_three_joint(args.steps)
    replay = str(BIN / "rsstp-replay")
    out = Path(tempfile.gettempdir()) / "rsstp-bench-table.parquet"
    commands = {
        "table": [replay, "table", str(mcap), "-o", str(out), "--force"],
        "audit": [replay, "audit", str(mcap)],
        "audit --truth": [replay, "audit", "--truth", str(mcap)],
    }
    print(
        f"{args.steps:,} steps, {mcap.stat().st_size / 1e6:.1f} MB; load {os.getloadavg()[0]:.1f}"
    )
    for name in args.only or list(commands):
        runs = [measure(commands[name]) for _ in range(args.repeat)]
        seconds = [s for s, _ in runs]
        peak = max(p for _, p in runs)
        if args.steps == 1_000_000:
            target_s, target_gib = TARGETS_1M[name]
            verdict = (
                f"(targets {target_s:g} s, {target_gib:g} GiB: "
                f"{'met' if min(seconds) <= target_s and peak <= target_gib else 'NOT met'})"
            )
        elif args.steps == 10_000_000 and name == "audit":
            per_step = peak * 2**30 / (args.steps + 1)
            met = peak <= TARGET_10M_GIB and per_step <= TARGET_10M_BYTES_PER_STEP
            verdict = (
                f"(targets {TARGET_10M_GIB:g} GiB, {TARGET_10M_BYTES_PER_STEP} bytes/step: "
                f"{'met' if met else 'NOT met'})"
            )
        else:
            verdict = ""
        shown = ", ".join(f"{s:.2f}" for s in seconds)
        print(
            f"{name:<14} cold, fresh process: {shown} s; peak {peak:.2f} GiB "
            f"({peak * 2**30 / (args.steps + 1):.0f} bytes/step) {verdict}"
        )
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
