"""The truth audit at the frontier, cold, end to end: ``audit --truth``, ``audit``, ``view
--save`` and the first ``model_at`` of a learner run on a world of 1,000+ classes, and the truth
cache on a world of about 340,000 poses.

    python bench/truth_frontier.py                      # 1,000,000 steps, then the cache
    python bench/truth_frontier.py --steps 10000000     # the same run ten times longer
    python bench/truth_frontier.py --world three-joint-30 --only frontier
    python bench/truth_frontier.py --only cache

The frontier run is ``rsstp-sim record WORLD --strategy learner --param stop=false --seed 0``
(the learner keeps walking and checking once it is done, so the run has every step of its
budget), recorded once into the temporary folder, on one of two worlds: ``two-joint-10``
(links (2, 1) at 10 degrees, one obstacle: 1,183 true classes; the issue's case) or
``three-joint-30`` (links (3, 2, 1) at 30 degrees, one obstacle: 1,337 true classes, and a
learner model of up to 1,700 states whose every version the file holds whole).
Each command runs in a fresh process (wall time includes Python's start and imports; peak
memory is the child's maximum RSS). The truth cache lives in a temporary ``XDG_CACHE_HOME``:
the first ``audit --truth`` computes the truth and keeps it, the second (another recording of
the same world, in a new process) reads it.

Targets (issue "The truth audit at the frontier"): at 1,000,000 steps ``audit --truth`` <= 15 s
and 1 GiB, ``audit`` and ``view --save`` <= 10 s and 1 GiB (the .rrd at most 1.5 x the .mcap),
the first ``model_at`` <= 2 s; 10,000,000 steps scale linearly; the second ``audit --truth``
of a 322,000-pose world takes at most 40 % of the first.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from _cold import measure
from _recordings import recorded
from viewer import FRONTIER_TOML  # the frontier world, one home for both benches

BIN = Path(sys.executable).parent
FRONTIER = """name = "three-joint-30"
[arm]
lengths = [3.0, 2.0, 1.0]
initial_deg = [0, 30, 30]
step_deg = 30
[[obstacles]]
center = [0.0, 4.0]
radius = 0.8
[feedback]
target_deg = [0, 30, 30]
"""
WORLDS = {
    "two-joint-10": FRONTIER_TOML,
    "three-joint-30": FRONTIER,
}
LARGE = (
    FRONTIER.replace("step_deg = 30", "step_deg = 5")
    .replace("center = [0.0, 4.0]\nradius = 0.8", "center = [0.0, -5.0]\nradius = 0.3")
    .replace('"three-joint-30"', '"three-joint-5-open"')
)
FIRST_MODEL_AT = """
import sys, time
began = time.perf_counter()
from rsstp_replay import open_recording
with open_recording(sys.argv[1]) as recording:
    opened = time.perf_counter()
    recording.model_at(recording.n_steps // 2)
    print(f"{time.perf_counter() - opened:.2f} s after opening ({opened - began:.2f} s to open)")
"""


def scenario_file(text: str) -> Path:
    path = Path(tempfile.gettempdir()) / f"rsstp-bench-{text.split(chr(34))[1]}.toml"
    path.write_text(text)
    return path


def frontier(name: str, steps: int) -> None:
    world = scenario_file(WORLDS[name])
    mcap = recorded(
        f"{name}-learner-{steps}", str(world), "--strategy", "learner", "--param", "stop=false",
        "--steps", str(steps),
    )  # fmt: skip
    print(f"{mcap}: {mcap.stat().st_size / 1e6:.1f} MB; load average {os.getloadavg()[0]:.2f}")
    replay = str(BIN / "rsstp-replay")
    with tempfile.TemporaryDirectory() as home:
        env_cache = {"XDG_CACHE_HOME": home}
        os.environ.update(env_cache)
        for name, command, target in [
            ("audit --truth", [replay, "audit", "--truth", "--quiet", str(mcap)], 15.0),
            (
                "audit --truth (truth cached)",
                [replay, "audit", "--truth", "--quiet", str(mcap)],
                15.0,
            ),
            ("audit", [replay, "audit", "--quiet", str(mcap)], 10.0),
        ]:
            seconds, gib = measure(command)
            print(f"{name:30s} {seconds:6.2f} s {gib:5.2f} GiB   (target <= {target:g} s, 1 GiB)")
        rrd = Path(home) / "frontier.rrd"
        seconds, gib = measure([replay, "view", "--quiet", str(mcap), "--save", str(rrd)])
        ratio = rrd.stat().st_size / mcap.stat().st_size
        print(
            f"{'view --save':30s} {seconds:6.2f} s {gib:5.2f} GiB, .rrd {ratio:.2f} x the .mcap"
            f"   (target <= 10 s, 1 GiB, 1.5 x)"
        )
    import subprocess

    done = subprocess.run(
        [sys.executable, "-c", FIRST_MODEL_AT, str(mcap)],
        capture_output=True,
        text=True,
        check=True,
    )
    print(f"{'first model_at':30s} {done.stdout.strip()}   (target <= 2 s)")


def cache() -> None:
    world = scenario_file(LARGE)
    runs = [
        recorded(f"large-random-{seed}", str(world), "--strategy", "random", "--seed", str(seed),
                 "--steps", "2000")
        for seed in (1, 2)
    ]  # fmt: skip
    replay = str(BIN / "rsstp-replay")
    print(f"cache: {world.name}; load average {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as home:
        os.environ["XDG_CACHE_HOME"] = home
        first, first_gib = measure([replay, "audit", "--truth", "--quiet", str(runs[0])])
        second, second_gib = measure([replay, "audit", "--truth", "--quiet", str(runs[1])])
    print(
        f"audit --truth, empty cache: {first:.2f} s {first_gib:.2f} GiB; another recording, "
        f"new process: {second:.2f} s {second_gib:.2f} GiB: {second / first:.0%} of the first "
        f"(target <= 40 %)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--only", choices=["frontier", "cache"])
    parser.add_argument("--world", choices=sorted(WORLDS), default="two-joint-10")
    args = parser.parse_args()
    if args.only in (None, "frontier"):
        frontier(args.world, args.steps)
    if args.only in (None, "cache"):
        cache()


if __name__ == "__main__":
    main()
