"""The learner's own speed at 5,000 and 15,000 classes: steps per second in ``rsstp-sim run``.

    PYTHONPATH=src python bench/learner_rate.py                  # both worlds, both modes
    PYTHONPATH=src python bench/learner_rate.py --steps 300000 --mode bool
    PYTHONPATH=src python bench/learner_rate.py --mode float --size 5000

Two generated worlds (bench/worlds.py's generator, family 1: the first of 4,500..5,500 classes
and the first of 14,000..16,000), each run cold in a fresh process: ``rsstp-sim run WORLD
--strategy learner --steps S --quiet``; printed: the run's own time and rate (its steps, not
the process start), the process's wall and CPU seconds and the steps per CPU second (the
figure a loaded machine changes least), and the load average (1 minute) before the run.

- ``bool``: the boolean form of each world for its first ``--steps`` steps (default 1,000,000),
  not a whole run: on these worlds the boolean learner does not finish in any budget we can
  wait for (it stays in its homing phase).
- ``float``: the float twin (``mode = "float"``), a whole run, start to done: a budget of
  ``--float-budget`` times N^2 steps (default 1), which the learner does not use up (it is done
  in about 0.01 to 0.04 N^2 steps); ``done`` says whether it ended the run.

Target (issue 32): >= 50,000 steps/s over a whole run.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from worlds import generate  # noqa: E402

SIZES = {5000: (4_500, 5_500), 15000: (14_000, 16_000)}

_TIMED = """
import resource, subprocess, sys, time
began = time.perf_counter()
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
seconds = time.perf_counter() - began
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
print(done.returncode, seconds, usage.ru_utime + usage.ru_stime)
print(done.stdout + done.stderr)
"""


def timed(command: list[str]) -> tuple[float, float, str]:
    """Wall and CPU seconds of ``command`` in a fresh process (measured by a fresh runner, so
    that no earlier child counts), and what it printed."""
    done = subprocess.run(
        [sys.executable, "-c", _TIMED, *command], capture_output=True, text=True, check=True
    )
    first, output = done.stdout.split("\n", 1)
    code, wall, cpu = first.split()
    if int(code) != 0:
        sys.exit(f"{' '.join(command)} failed ({code}): {output}")
    return float(wall), float(cpu), output


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1_000_000, help="boolean: steps per run")
    parser.add_argument("--float-budget", type=float, default=1.0, help="float: x N^2 steps")
    parser.add_argument("--mode", choices=("bool", "float", "both"), default="both")
    parser.add_argument("--size", choices=("5000", "15000", "both"), default="both")
    args = parser.parse_args()
    modes = ("bool", "float") if args.mode == "both" else (args.mode,)
    sizes = list(SIZES) if args.size == "both" else [int(args.size)]
    print(
        f"{'world':10s} {'N':>7s} {'mode':5s} {'steps':>10s} {'done':>4s} {'run s':>7s} "
        f"{'steps/s':>8s} {'wall s':>7s} {'cpu s':>7s} {'steps/cpu s':>11s} {'load':>5s}"
    )
    rsstp_sim = str(Path(sys.executable).parent / "rsstp-sim")
    with tempfile.TemporaryDirectory() as folder:
        for size in sizes:
            low, high = SIZES[size]
            world = generate(1, 0, min_n=low, max_n=high)
            for mode in modes:
                path = Path(folder) / f"{world.name}-{mode}.toml"
                path.write_text(world.source if mode == "bool" else world.twin(), encoding="utf-8")
                budget = args.steps if mode == "bool" else int(args.float_budget * world.n**2)
                command = [rsstp_sim, "run", str(path), "--strategy", "learner",
                           "--steps", str(budget), "--quiet"]  # fmt: skip
                load = os.getloadavg()[0]
                wall, cpu, output = timed(command)
                found = re.search(r"time: ([\d.]+) s \(([\d,]+) steps/s\)", output)
                steps = re.search(r"^steps: ([\d,]+)", output, re.MULTILINE)
                if found is None or steps is None:
                    print(output)
                    return 1
                done = "yes" if "stopped by the strategy" in output else "no"
                count = int(steps.group(1).replace(",", ""))
                print(
                    f"{world.name:10s} {world.n:>7,} {mode:5s} {count:>10,} {done:>4s} "
                    f"{found.group(1):>7s} {found.group(2):>8s} {wall:>7.1f} {cpu:>7.1f} "
                    f"{count / cpu:>11,.0f} {load:>5.1f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
