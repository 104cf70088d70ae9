"""Explaining a long failed run, cold: ``rsstp-replay audit --truth`` of a learner run that never
learned, in a fresh process (wall and CPU seconds, peak RSS), and the explanation it printed.

    python bench/explain.py                      # 30,000,000 steps (recorded once, ~2 hours)
    python bench/explain.py --steps 1000000      # a shorter run of the same world
    python bench/explain.py --mcap RUN.mcap      # a recording at hand

The world (issue 32, point 5): ``world-0-36`` of ``bench/worlds.py --max-n 2000`` (family 0),
the boolean form: links (0.8, 2.03) at 8 degrees, one obstacle, the first joint turning
counter-clockwise only (actions 0, 2, 3: a one-way world), 1,936 true classes. The ``learner``
senses its target at step 2,346 and then spends nearly every step in its ``home`` phase,
searching for the sensed pose, its landmark, which in this one-way world it cannot go back to
at will: after 1,000,000 steps (seed 0) 98.7 % of the steps were in ``home``, its model has
93 states for 1,936 classes and grows by about 0.0001 states a step. It is recorded once with
``rsstp-sim record WORLD --strategy learner --seed 0 --steps N`` into the temporary folder
(``/tmp/rsstp-bench-one-way-learner-N.mcap``; about 60 bytes a step; 300,000 steps took 21.5 s
at a load of 5, 30,000,000 nearly two hours at a load of 5 to 12). The truth cache lives in a
temporary ``XDG_CACHE_HOME``, so the truth is computed too (a fraction of a second for this
world). At 15,093,472 steps the run is still in ``home`` (98.7 %), 1,185 states.

Targets (issue 32, point 5): ``audit --truth`` of a 30,000,000-step failed run in at most 2
minutes and 2 GiB (before: 844 s and 8.3 GB for 38.6 M steps, most in the consistency audit's
suffix sort). On 2026-11-28, at a load of 5 to 9 on 2 cores: 471 s wall, 231 s CPU, 4.81 GiB
(the code before this bench: 1,065 s, 365 s CPU, 6.14 GiB): missed, see docs/performance.md.
Those figures are of the world this bench had before (links (2, 1) at 5 degrees between two
obstacles, float feedback), which the learner has learned since the same day's fix of its
climb.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from _recordings import recorded

ONE_WAY = """\
name = "world-0-36"

[arm]
lengths = [0.8, 2.03]
initial_deg = [336, 280]
step_deg = 8
actions = [0, 2, 3]

[[obstacles]]
center = [1.93, 1.909]
radius = 0.713

[feedback]
target_deg = [208, 320]
"""
"""The learner's failed world: ``bench/worlds.py --max-n 2000 --only world-0-36 --write DIR``
writes the same file (``world-0-36.toml``)."""

TARGET_S, TARGET_GIB = 120.0, 2.0

_RUNNER = """
import resource, subprocess, sys, time
began = time.perf_counter()
with open(sys.argv[1], "wb") as out:
    done = subprocess.run(sys.argv[2:], stdout=out, stderr=subprocess.PIPE)
seconds = time.perf_counter() - began
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
stderr = done.stderr.decode().strip().replace(chr(10), " | ")
print(done.returncode, seconds, usage.ru_utime + usage.ru_stime, usage.ru_maxrss, stderr)
"""


def measure(command: list[str], out: Path) -> tuple[float, float, float]:
    """Wall seconds, CPU seconds and peak RSS (GiB) of ``command`` in a fresh process, its
    standard output written to ``out``."""
    done = subprocess.run(
        [sys.executable, "-c", _RUNNER, str(out), *command],
        capture_output=True,
        text=True,
        check=True,
    )
    code, seconds, cpu, peak_kib, stderr = done.stdout.split(" ", 4)
    if int(code) not in (0, 1):
        sys.exit(f"{' '.join(command)} failed ({code}): {stderr}")
    return float(seconds), float(cpu), int(peak_kib) / 2**20


def failed_run(steps: int) -> Path:
    world = Path(tempfile.gettempdir()) / "rsstp-bench-world-0-36.toml"
    world.write_text(ONE_WAY)
    return recorded(
        f"one-way-learner-{steps}", str(world), "--strategy", "learner", "--seed", "0",
        "--steps", str(steps), "--quiet",
    )  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=30_000_000)
    parser.add_argument("--mcap", type=Path, help="audit this recording instead")
    parser.add_argument(
        "--consistency-steps", type=int, help="passed to audit (default: the audit's)"
    )
    args = parser.parse_args()
    mcap = args.mcap or failed_run(args.steps)
    command = [sys.executable, "-m", "rsstp_cli.replay", "audit", "--truth", "--quiet"]
    if args.consistency_steps is not None:
        command += ["--consistency-steps", str(args.consistency_steps)]
    print(
        f"{mcap}: {mcap.stat().st_size / 1e6:,.0f} MB; load average {os.getloadavg()[0]:.2f}; "
        f"{os.cpu_count()} cores"
    )
    with tempfile.TemporaryDirectory() as home:
        os.environ["XDG_CACHE_HOME"] = home
        out = Path(home) / "audit.txt"
        seconds, cpu, gib = measure([*command, str(mcap)], out)
        text = out.read_text()
    print(
        f"audit --truth, cold: {seconds:.1f} s wall, {cpu:.1f} s CPU, {gib:.2f} GiB peak RSS "
        f"(target <= {TARGET_S:g} s, {TARGET_GIB:g} GiB: "
        f"{'met' if seconds <= TARGET_S and gib <= TARGET_GIB else 'not met'})"
    )
    head, _, rest = text.partition("== where the steps went ==\n")
    print(head.strip())
    print("== where the steps went ==")
    print(rest.split("\n\n")[0])
    for line in text.splitlines():
        if line.startswith(("within each model version", "contradictions:", "sampled:")):
            print(line)


if __name__ == "__main__":
    main()
