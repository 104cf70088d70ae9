"""The learner in one-way worlds: it ends the run, and its steps run at full speed.

    PYTHONPATH=src python bench/one_way.py            # 3 cold runs of each
    PYTHONPATH=src python bench/one_way.py --runs 5

Worlds (defined inline): a two- or three-joint arm whose first joint turns one way only
(``actions`` without the first joint's clockwise turn) beside an obstacle: the arm ends jammed
against it, in a part of the world it cannot leave and that never senses.

For each world, cold (a fresh ``rsstp-sim run`` process each time, its own printed rate):

- the learner as it is (it stops): the steps it used of a budget of 400,000, and the seconds
  (jammed early, it has seen no move it cannot undo, and searches 16 x 16,384 steps before it
  takes itself as confined);
- ``--param stop=false`` (it goes on searching for the whole 400,000): steps per second, the
  rate of a one-way world's steps.

Targets: the run ends before the budget, saying it is confined; >= 30,000 steps/s.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from scenarios import arm_toml  # noqa: E402 (the test suite's folder goes on the path first)

OBSTACLE = [((0.0, 2.5), 0.5)]
WORLDS = {
    "one-way-two-joint": arm_toml(
        [2, 1], [0, 0], 30, OBSTACLE, name="one-way-two-joint", actions=[0, 1, 2],
        feedback={"target_deg": [0, 90]},
    ),
    "one-way-three-joint": arm_toml(
        [2, 1, 0.5], [0, 0, 0], 30, OBSTACLE, name="one-way-three-joint",
        actions=[0, 2, 3, 4, 5], feedback={"target_deg": [0, 0, 0]},
    ),
}  # fmt: skip
BUDGET = 400_000
TARGET_RATE = 30_000
RSSTP_SIM = str(Path(sys.executable).with_name("rsstp-sim"))


def run(path: Path, *params: str) -> tuple[int, float, str]:
    """One cold ``rsstp-sim run``: its steps, seconds and first line."""
    command = [RSSTP_SIM, "run", str(path), "--strategy", "learner", "--steps", str(BUDGET)]
    for param in params:
        command += ["--param", param]
    done = subprocess.run(command, capture_output=True, text=True, check=True)
    out = done.stdout
    found = re.search(r"^steps: ([\d,]+)", out, re.M)  # (thousands separated by commas)
    steps = int(found.group(1).replace(",", ""))  # type: ignore[union-attr]
    seconds = float(re.search(r"^time: ([\d.]+) s", out, re.M).group(1))  # type: ignore[union-attr]
    return steps, seconds, out.splitlines()[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args(argv)
    good = True
    with tempfile.TemporaryDirectory() as folder:
        for name, toml in WORLDS.items():
            path = Path(folder) / f"{name}.toml"
            path.write_text(toml, encoding="utf-8")
            stops = [run(path) for _ in range(args.runs)]
            rates = []
            for _ in range(args.runs):
                steps, seconds, _line = run(path, "stop=false")
                rates.append(steps / seconds)
            used = sorted({s for s, _, _ in stops})
            secs = [s for _, s, _ in stops]
            print(f"{name}: {stops[0][2]}")
            print(
                f"  stops at step {'/'.join(f'{u:,}' for u in used)} of {BUDGET:,} in "
                f"{min(secs):.2f}-{max(secs):.2f} s; stop=false: "
                f"{min(rates):,.0f}-{max(rates):,.0f} steps/s (target >= {TARGET_RATE:,})"
            )
            good &= all(s < BUDGET and "confined" in line for s, _, line in stops)
            good &= min(rates) >= TARGET_RATE
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
