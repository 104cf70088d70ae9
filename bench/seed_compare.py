"""Ours beside the original platform, on the original's own three-joint test setup, in one run.

    python bench/seed_compare.py --seed-src DIR     # DIR: the original's source (see below)

The original RSSTP (public repository filkata123/RSSTP, branch merge/Teemu_Rafi_Upgrades) is
never copied into this repository: export that branch somewhere (``git archive
merge/Teemu_Rafi_Upgrades | tar -x -C DIR``) and pass the folder; its ``src`` is imported from
there. It needs shapely and matplotlib.

The setup is its ``tests/external_test.py`` fixture: 3 joints of lengths [3, 2, 1] from
[330, 3, 357], obstacles at (1.5, 1) and (1.5, -1.5) of radius 0.5, 5-degree steps, feedback
points at the start pose; actions drawn by ``random.Random(12345)`` from 0..5, the same
sequence for both. Every figure is measured in a fresh Python process (cold: imports done,
nothing cached, the world built inside the timing), the warm ones after the same actions once
more in that process:

- world moves: the original's ``External.update`` against our ``World.move``;
- the thesis facade: the original's ``robot_arm.update_position`` (its prints sent to
  /dev/null) against ``rsstp_sim.compat.robot_arm.update_position``;
- our whole run, end to end: ``rsstp-sim run three-joint --strategy random --steps 1000000``;
- the yardstick: a pure-Python loop that draws a random action, follows a precomputed
  next-state table of three-joint's size and appends both to arrays.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from scenarios import arm_toml  # noqa: E402 (the test suite's folder goes on the path first)

BIN = Path(sys.executable).parent
SETUP = {
    "lengths": [3, 2, 1],
    "start": [330, 3, 357],
    "obstacles": [[[1.5, 1], 0.5], [[1.5, -1.5], 0.5]],
    "step": 5,
    "feedback": [(2.6, -1.5), (4.38, -2.41), (5.25, -2.91)],
}

_TIMED = """
import contextlib, os, random, time
actions = [random.Random(12345).randrange(6) for _ in range(N)]
with open(os.devnull, "w") as sink, contextlib.redirect_stdout(sink):  # the original prints
    began = time.perf_counter()
    act = build()  # the world is built inside the cold figure
    for a in actions:
        act(a)
    cold = warm = time.perf_counter() - began
    if WARM:
        began = time.perf_counter()
        for a in actions:
            act(a)
        warm = time.perf_counter() - began
print(cold, warm)
"""
"""The tail of every program but the yardstick: ``N`` actions, cold from a fresh ``build()``,
then warm (when ``WARM``) on the same world."""

_PROGRAMS = {
    "original-world": """
import sys
sys.path.insert(0, SRC)
from external import External
def build():
    return External(*ARGS).update
""",
    "ours-world": """
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.arm.world import World
scenario = parse_scenario(TOML)
def build():
    return World(scenario).move  # builds the world's table
""",
    "original-facade": """
import sys
sys.path.insert(0, SRC)
import matplotlib
matplotlib.use("Agg")
from msrgym import robot_arm
def build():
    return robot_arm(*ARGS, list(range(6))).update_position
WARM = False
""",
    "ours-facade": """
from rsstp_sim.compat import robot_arm
def build():
    return robot_arm(*ARGS, list(range(6))).update_position
""",
    "yardstick": """
import random, time
from array import array
rng = random.Random(1)
poses, n_actions = 39_232, 6
table = [[rng.randrange(poses) for _ in range(n_actions)] for _ in range(poses)]
actions, states = array("b"), array("l")
draw, here = rng.randrange, 0
began = time.perf_counter()
for _ in range(N):
    a = draw(n_actions)
    here = table[here][a]
    actions.append(a)
    states.append(here)
seconds = time.perf_counter() - began
print(seconds, seconds)
""",
}

_ARGS = (
    len(SETUP["lengths"]),
    SETUP["start"],
    SETUP["lengths"],
    [part for obstacle in SETUP["obstacles"] for part in obstacle],
    SETUP["step"],
    SETUP["feedback"],
)
"""The original's arguments (joints, start, lengths, obstacles flattened, step, feedback)."""

_TOML = arm_toml([3.0, 2.0, 1.0], [330, 3, 357], 5, [((1.5, 1.0), 0.5), ((1.5, -1.5), 0.5)])


def measure(name: str, n: int, src: Path) -> tuple[float, float]:
    """Cold and warm seconds for ``n`` actions of program ``name`` in a fresh process."""
    head = f"N = {n}\nSRC = {str(src)!r}\nTOML = {_TOML!r}\nARGS = {_ARGS!r}\nWARM = True\n"
    code = head + _PROGRAMS[name] + ("" if name == "yardstick" else _TIMED)
    done = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=False,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    if done.returncode != 0:
        sys.exit(f"{name} failed: {done.stderr.strip().splitlines()[-1]}")
    cold, warm = map(float, done.stdout.split())
    return cold, warm


def end_to_end(steps: int) -> float:
    began = time.perf_counter()
    subprocess.run(
        [str(BIN / "rsstp-sim"), "run", "three-joint", "--strategy", "random", "--steps",
         str(steps), "--seed", "1", "--quiet"],
        check=True,
        stdout=subprocess.DEVNULL,
    )  # fmt: skip
    return time.perf_counter() - began


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seed-src", type=Path, required=True, metavar="DIR")
    parser.add_argument("--moves", type=int, default=20_000)
    parser.add_argument("--facade-moves", type=int, default=2_000)
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()
    src = args.seed_src / "src"
    if not (src / "external.py").exists():
        sys.exit(f"{src}: the original's external.py is not there")
    print(f"load {os.getloadavg()[0]:.1f}; {args.moves:,} world moves, {args.facade_moves:,} "
          f"facade updates, actions from random.Random(12345)")  # fmt: skip
    rates: dict[str, tuple[float, float]] = {}
    for name, n in (
        ("original-world", args.moves),
        ("ours-world", args.moves),
        ("original-facade", args.facade_moves),
        ("ours-facade", args.facade_moves),
        ("yardstick", 1_000_000),
    ):
        cold, warm = measure(name, n, src)
        rates[name] = (n / cold, n / warm)
        print(f"{name:<16} cold {n / cold:>12,.0f} /s   warm {n / warm:>12,.0f} /s")
    run_s = end_to_end(1_000_000)
    rates["ours-run"] = (1_000_000 / run_s, 1_000_000 / run_s)
    print(f"{'ours-run':<16} {1_000_000 / run_s:,.0f} steps/s end to end ({run_s:.2f} s, fresh "
          f"process, 1,000,000 random steps of three-joint)")  # fmt: skip
    world_cold = rates["ours-world"][0] / rates["original-world"][0]
    world_warm = rates["ours-world"][1] / rates["original-world"][1]
    facade = rates["ours-facade"][0] / rates["original-facade"][0]
    run_vs_facade = rates["ours-run"][0] / rates["original-facade"][0]
    run_vs_yardstick = rates["ours-run"][0] / rates["yardstick"][0]
    print(f"cold world moves: {world_cold:.1f}x the original's (target >= 10x); warm "
          f"{world_warm:.0f}x")  # fmt: skip
    print(f"cold facade update_position: {facade:.1f}x the original's")
    print(f"our 1M run: {run_vs_facade:.0f}x the original's update_position (target >= 30x), "
          f"{100 * run_vs_yardstick:.0f}% of the yardstick (target >= 20%)")  # fmt: skip
    if args.json is not None:
        args.json.write_text(json.dumps(rates, indent=2))


if __name__ == "__main__":
    main()
