"""Benchmark: the physics check, ``rsstp-replay check --physics``, on a million steps.

    PYTHONPATH=bench python bench/physics.py [--steps 1000000] [--repeat 3]

The recording is ``rsstp-sim record three-joint --strategy random --steps N --seed 1`` (made
once under the temporary folder). Target: at least 1,000,000 steps re-simulated and compared
in 10 s. Each repeat runs in a fresh process (cold: Python's start, the imports, opening the
file, the re-simulation from an empty world table and every comparison) and reports its wall
and CPU seconds; the check alone is then timed again in that process (warm: the world table
and the decoded steps already there are not reused, so warm differs only by the imports).
On a loaded machine the CPU seconds are the honest figure: the load average is printed.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys

from _recordings import random_three_joint

_CHILD = """
import sys, time
began, cpu = time.perf_counter(), time.process_time()
from rsstp_replay import open_recording
from rsstp_replay.audits.physics import check_physics
with open_recording(sys.argv[1]) as recording:
    found = check_physics(recording)
cold = (time.perf_counter() - began, time.process_time() - cpu)
assert found.holds, found.to_text()
with open_recording(sys.argv[1]) as recording:
    began, cpu = time.perf_counter(), time.process_time()
    check_physics(recording)
    warm = (time.perf_counter() - began, time.process_time() - cpu)
print(*cold, *warm)
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    path = random_three_joint(args.steps)
    print(f"{path}: {args.steps:,} steps; load average {os.getloadavg()[0]:.1f}")
    rows = []
    for _ in range(args.repeat):
        done = subprocess.run(
            [sys.executable, "-c", _CHILD, str(path)], capture_output=True, text=True, check=True
        )
        rows.append([float(v) for v in done.stdout.split()])
        wall, cpu, warm_wall, warm_cpu = rows[-1]
        print(
            f"cold {wall:.2f} s wall, {cpu:.2f} s CPU; warm (the check alone) "
            f"{warm_wall:.2f} s wall, {warm_cpu:.2f} s CPU; load {os.getloadavg()[0]:.1f}",
            flush=True,
        )
    for k, what in enumerate(("cold wall", "cold CPU", "warm wall", "warm CPU")):
        values = [row[k] for row in rows]
        print(f"{what}: {min(values):.2f}-{max(values):.2f} s over {len(values)} runs")


if __name__ == "__main__":
    main()
