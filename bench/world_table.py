"""The world table: build times, memory, and cold walks of arms with many links.

    python bench/world_table.py [--steps N]

Every figure comes from a fresh Python process (cold: nothing computed before; the
imports are timed apart):

- ``three-joint``: the whole reachable table (``WorldTable.complete``), target <= 0.5 s;
- a 5-joint 30-degree arm (12**5 = 248,832 lattice poses), the whole table, targets
  <= 3 s and <= 500 MiB peak;
- 5, 6 and 7 links of length 1 at 5-degree steps (72**7 lattice poses for 7: never
  tabulated whole), ``N`` random moves from a fresh world (the table grows move by move),
  target >= 50,000 cold steps/s with memory bounded by the poses visited; then the same
  arms end to end, ``rsstp-sim run ARM.toml --strategy random --steps N`` in a fresh
  process (imports, scenario and report included).

Each figure is given in wall time and in the process's own CPU time: on a loaded machine
(other processes sharing its cores) the wall figure is the CPU figure stretched by the wait.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from scenarios import arm_toml  # noqa: E402 (the test suite's folder goes on the path first)

_ARMS = {
    "five-joint-30": arm_toml(
        [2.0, 1.5, 1.0, 1.0, 0.5],
        [0, 30, 30, 30, 30],
        30,
        [((2.0, 3.0), 0.6), ((-3.0, -1.0), 0.8)],
        name="five-joint-30",
    ),
}


def _links(n: int) -> str:
    disks = [((1.5, 1.0), 0.5), ((1.5, -1.5), 0.5)]
    return arm_toml([1.0] * n, [0] + [30] * (n - 1), 5, disks, name=f"links-{n}")


_TABLE = """
import json, resource, time
began = time.perf_counter()
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.arm.table import WorldTable
imported = time.perf_counter() - began
scenario = load_scenario(NAME) if TOML is None else parse_scenario(TOML, origin=NAME)
began = time.perf_counter()
table = WorldTable(scenario)
table.complete()
seconds = time.perf_counter() - began
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"imports": imported, "seconds": seconds, "poses": len(table), "peak": peak}))
"""

_WALK = """
import json, resource, time
import numpy as np
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.arm.world import World
scenario = parse_scenario(TOML, origin=NAME)
actions = np.random.default_rng(1).choice(scenario.actions, size=STEPS).tolist()
began, cpu = time.perf_counter(), time.process_time()
world = World(scenario)
move = world.move
for a in actions:
    move(a)
seconds, cpu = time.perf_counter() - began, time.process_time() - cpu
poses, moves = world.cache_info()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"seconds": seconds, "cpu": cpu, "poses": poses, "moves": moves, "peak": peak}))
"""

_RUN = """
import json, resource, subprocess, sys, time
began = time.perf_counter()
subprocess.run(COMMAND, check=True, stdout=subprocess.DEVNULL)
seconds = time.perf_counter() - began
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"seconds": seconds, "cpu": usage.ru_utime + usage.ru_stime,
                  "peak": usage.ru_maxrss / 1024}))
"""


def _fresh(program: str, **names: object) -> dict[str, float]:
    head = "".join(f"{key} = {value!r}\n" for key, value in names.items())
    done = subprocess.run(
        [sys.executable, "-c", head + program], capture_output=True, text=True, check=False
    )
    if done.returncode != 0:
        sys.exit(done.stderr.strip().splitlines()[-1])
    result: dict[str, float] = json.loads(done.stdout)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=100_000, help="moves per many-link walk")
    args = parser.parse_args()
    for name, toml, limit in (
        ("three-joint", None, 0.5),
        ("five-joint-30", _ARMS["five-joint-30"], 3.0),
    ):
        r = _fresh(_TABLE, NAME=name, TOML=toml)
        print(
            f"{name:14} whole table {r['poses']:>9,.0f} poses  {r['seconds']:6.2f} s "
            f"(target <= {limit} s)  peak {r['peak']:5.0f} MiB  imports {r['imports']:.2f} s"
        )
    for n in (5, 6, 7):
        r = _fresh(_WALK, NAME=f"links-{n}", TOML=_links(n), STEPS=args.steps)
        print(
            f"links-{n:<8} {args.steps:,} cold moves {args.steps / r['seconds']:>9,.0f} steps/s "
            f"wall, {args.steps / r['cpu']:>7,.0f} CPU (target >= 50,000)  "
            f"{r['poses']:,.0f} poses, {r['moves']:,.0f} with moves  peak {r['peak']:.0f} MiB"
        )
    with tempfile.TemporaryDirectory() as folder:
        for n in (5, 6, 7):
            toml = Path(folder, f"links-{n}.toml")
            toml.write_text(_links(n))
            command = [sys.executable, "-m", "rsstp_cli.sim", "run", str(toml), "--strategy"]
            command += ["random", "--steps", str(args.steps), "--seed", "1"]
            r = _fresh(_RUN, COMMAND=command)
            print(
                f"links-{n:<8} rsstp-sim run, {args.steps:,} random steps, cold "
                f"{args.steps / r['seconds']:>9,.0f} steps/s wall, "
                f"{args.steps / r['cpu']:>7,.0f} CPU  peak {r['peak']:.0f} MiB"
            )


if __name__ == "__main__":
    main()
