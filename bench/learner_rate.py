"""The learner's own speed at 5,000 and 15,000 classes: steps per second in ``rsstp-sim run``.

    PYTHONPATH=src python bench/learner_rate.py                  # 1,000,000 steps each
    PYTHONPATH=src python bench/learner_rate.py --steps 300000

Two generated worlds (bench/worlds.py's generator, family 1: the first of 4,500..5,500 classes
and the first of 14,000..16,000), each run cold in a fresh process: ``rsstp-sim run WORLD
--strategy learner --steps S --quiet``, its own printed time and rate (the run's steps, not
the process start), with the process's wall and CPU seconds beside. The boolean form of each
world; a run of ``S`` steps is its first ``S`` steps, not a whole run (a whole run at 15,000
classes is tens of millions of steps). Target (issue 32): >= 50,000 steps/s over a whole run.
"""

from __future__ import annotations

import argparse
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from worlds import generate  # noqa: E402

SIZES = ((4_500, 5_500), (14_000, 16_000))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    args = parser.parse_args()
    print(f"{'world':14s} {'N':>7s} {'steps':>10s} {'run s':>7s} {'steps/s':>9s} {'cpu s':>7s}")
    with tempfile.TemporaryDirectory() as folder:
        for low, high in SIZES:
            world = generate(1, 0, min_n=low, max_n=high)
            path = Path(folder) / f"{world.name}.toml"
            path.write_text(world.source, encoding="utf-8")
            command = [
                str(Path(sys.executable).parent / "rsstp-sim"), "run", str(path),
                "--strategy", "learner",
                "--steps", str(args.steps), "--quiet",
            ]  # fmt: skip
            started = time.perf_counter()
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            output = subprocess.run(command, capture_output=True, text=True, check=True).stdout
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
            wall = time.perf_counter() - started
            found = re.search(r"time: ([\d.]+) s \(([\d,]+) steps/s\)", output)
            steps = re.search(r"steps: ([\d,]+)", output)
            if found is None:
                print(output)
                return 1
            print(
                f"{world.name:14s} {world.n:>7,} {steps.group(1) if steps else '?':>10s} "
                f"{found.group(1):>7s} {found.group(2):>9s} {cpu:>7.1f}  (process {wall:.1f} s)",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
