"""Bounded work: the largest world a scenario may describe, 1,000 obstacles on a three-joint
arm (5-degree steps), run and recorded end to end, as a user runs it.

    python bench/many_obstacles.py                  # 2,000 steps, 3 runs of each
    python bench/many_obstacles.py --steps 20000

The whole world table of this arm would cost 6.7 billion link-obstacle checks (issue 22: grown
in blocks toward it, ``run`` and ``record --steps 2000`` took 114 s of CPU and 6.7 GB), so the
world computes only the moves the arm makes (``rsstp_sim.arm.table.MAX_TABULATION_CHECKS``)
and ``truth`` refuses it in one line. Each command runs in a fresh process (``rsstp-sim``
beside this interpreter, see ``bench/_cold.py``); the CPU seconds are the figure on a loaded
machine, the wall seconds stretch with the load.

Target: ``run`` and ``record`` of 2,000 random steps within 20 s and 1 GiB each; ``truth``
refused in one line within 20 s.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from _cold import measure_cpu

BIN = Path(sys.executable).parent
TARGET_S = 20.0
TARGET_GIB = 1.0


def scenario_text() -> str:
    """1,000 disks: 500 in a grid far off, 500 in an arc at 4.5 from the base, over 0 to 240
    degrees, which the arm meets as it swings round (the same world as the tests')."""
    import math

    lines = ["[arm]", "lengths = [3.0, 2.0, 1.0]", "initial_deg = [330, 3, 357]", "step_deg = 5"]
    centres = [(40.0 + i % 40, 40.0 + i // 40) for i in range(500)]
    centres += [
        (4.5 * math.cos(4 * math.pi / 3 * i / 499), 4.5 * math.sin(4 * math.pi / 3 * i / 499))
        for i in range(500)
    ]
    for x, y in centres:
        lines += ["[[obstacles]]", f"center = [{x!r}, {y!r}]", "radius = 0.2"]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=2000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    sim = str(BIN / "rsstp-sim")
    print(f"1,000 obstacles, three joints, {args.steps:,} random steps; load {os.getloadavg()}")
    with tempfile.TemporaryDirectory() as folder:
        toml = Path(folder) / "many.toml"
        toml.write_text(scenario_text())
        walk = [str(toml), "--strategy", "random", "--seed", "1", "--steps", str(args.steps)]
        out = Path(folder) / "many.mcap"
        commands = {
            "run": [sim, "run", *walk, "--quiet"],
            "record": [sim, "record", *walk, "-o", str(out), "--force", "--quiet"],
        }
        for name, command in commands.items():
            figures = [measure_cpu(command) for _ in range(args.repeat)]
            met = all(cpu <= TARGET_S and peak <= TARGET_GIB for _, cpu, peak in figures)
            shown = "; ".join(
                f"{wall:.2f} s wall, {cpu:.2f} s CPU, {peak * 1024:.0f} MiB"
                for wall, cpu, peak in figures
            )
            extra = f", {out.stat().st_size / 2**20:.1f} MiB file" if name == "record" else ""
            print(
                f"{name:<7} {shown}{extra} (target <= {TARGET_S:g} s, {TARGET_GIB:g} GiB: "
                f"{'met' if met else 'NOT met'})"
            )
        done = subprocess.run([sim, "truth", str(toml)], capture_output=True, text=True)
        print(f"truth   exit {done.returncode}: {done.stderr.strip()}")
    print(f"load {os.getloadavg()}")


if __name__ == "__main__":
    main()
