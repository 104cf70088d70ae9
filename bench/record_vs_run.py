"""``rsstp-sim record`` against ``rsstp-sim run``, side by side, cold, at three lengths.

    python bench/record_vs_run.py                              # 100,000, 1M and 10M steps
    python bench/record_vs_run.py --steps 1000000 --repeat 5

For each length, ``run`` and ``record`` of ``three-joint --strategy random --seed 1 --quiet``
alternate, each in a fresh process (``rsstp-sim`` beside this interpreter: wall time includes
starting Python and the imports), ``--repeat`` times; the recording goes to a temporary
folder. Reported: each command's wall seconds (range), its CPU seconds (user and system,
every thread: ``record`` compresses and writes on a second thread), ``record``'s steps/s,
``record / run`` per pair (wall), bytes per step on disk and peak memory, and the load
average before and after (on a shared 2-core machine the wall figures stretch with it).

Targets (issue 21): ``record`` <= 2 x ``run`` and >= 150,000 steps/s at 1,000,000 steps,
<= 80 bytes a step.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from _cold import measure_cpu

BIN = Path(sys.executable).parent
RECORD_RATE = 150_000
RECORD_OVER_RUN = 2.0
BYTES_PER_STEP = 80


def _span(values: list[float], form: str) -> str:
    low, high = min(values), max(values)
    return format(low, form) if low == high else f"{low:{form}}-{high:{form}}"


def compare(steps: int, repeat: int) -> None:
    sim = str(BIN / "rsstp-sim")
    walk = ["three-joint", "--strategy", "random", "--seed", "1", "--steps", str(steps)]
    load_before = os.getloadavg()[0]
    runs, records = [], []
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run.mcap"
        for _ in range(repeat):
            runs.append(measure_cpu([sim, "run", *walk, "--quiet"]))
            records.append(
                measure_cpu([sim, "record", *walk, "-o", str(out), "--force", "--quiet"])
            )
        per_step = out.stat().st_size / (steps + 1)
    ratios = [r[0] / w[0] for w, r in zip(runs, records, strict=True)]
    rates = [steps / r[0] for r in records]
    print(f"{steps:,} steps, {repeat} pairs, load {load_before:.1f} -> {os.getloadavg()[0]:.1f}")
    for name, found in (("run", runs), ("record", records)):
        print(
            f"  {name:<7} wall {_span([f[0] for f in found], '.2f')} s, "
            f"CPU {_span([f[1] for f in found], '.2f')} s, "
            f"peak {_span([f[2] * 1024 for f in found], '.0f')} MiB"
        )
    verdict = {True: "met", False: "NOT met"}
    rate_target = (
        f" (target >= {RECORD_RATE:,} at 1,000,000 steps: {verdict[min(rates) >= RECORD_RATE]})"
        if steps == 1_000_000
        else ""
    )
    print(
        f"  record {_span(rates, ',.0f')} steps/s{rate_target}, {_span(ratios, '.2f')} x the "
        f"run (target <= {RECORD_OVER_RUN:g}: {verdict[max(ratios) <= RECORD_OVER_RUN]}), "
        f"{per_step:.1f} bytes/step (target <= {BYTES_PER_STEP}: "
        f"{verdict[per_step <= BYTES_PER_STEP]})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, nargs="+", default=[100_000, 1_000_000, 10_000_000])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    for steps in args.steps:
        compare(steps, args.repeat)


if __name__ == "__main__":
    main()
