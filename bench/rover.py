"""The rover's figures: its ground truth, its steps, and the learner in its worlds.

    PYTHONPATH=src python bench/rover.py                  # the built-ins, and small rooms
    PYTHONPATH=src python bench/rover.py --budget 400000  # the learner's budget on the built-ins

Worlds: the three built-in rover scenarios (``rover-room``, ``rover-two-rooms``,
``rover-one-way``), and open square rooms generated here (3 x 3 to 6 x 6 cells, four
headings, sensed in one cell facing north), which nobody tuned anything on.

For each built-in, cold (a fresh process each, as a user runs them):

- ``rsstp-sim truth NAME``: the reachable poses, the true classes N, the seconds it prints
  and the process's wall time;
- ``rsstp-sim run NAME --strategy random --steps 1000000``: its printed steps per second;
- ``rsstp-sim record NAME --strategy random --steps 100000``, then ``rsstp-replay audit
  --truth`` and ``rsstp-replay view --save`` of that recording: each one's wall time, and the
  file's size.

Then the learner, in this process (seed 0): on each small room with a budget of 4 N^2 steps,
on each built-in with ``--budget`` steps; the steps it took, its model's states, and whether
the model is equivalent to the truth (:func:`rsstp_sim.truth.check_equivalence`).

Targets (issue 31): thousands of classes per built-in; the learner learns every rover world
exactly within 4 N^2 steps.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rsstp_sim.runner import Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.truth import check_equivalence, compute_truth

BUILT_INS = ("rover-room", "rover-two-rooms", "rover-one-way")
RSSTP_SIM = str(Path(sys.executable).with_name("rsstp-sim"))
RSSTP_REPLAY = str(Path(sys.executable).with_name("rsstp-replay"))


def small_room(side: int) -> str:
    return (
        f'name = "open-{side}x{side}"\n[rover]\nroom = [{side}, {side}]\nstart = [0, 0]\n'
        f"[feedback]\ncenter = [{side - 0.5}, {side - 0.5}]\nheading_deg = 90\n"
    )


def cold(*args: str) -> tuple[str, float]:
    started = time.perf_counter()
    done = subprocess.run([RSSTP_SIM, *args], capture_output=True, text=True, check=True)
    return done.stdout, time.perf_counter() - started


def cold_replay(*args: str) -> float:
    started = time.perf_counter()
    subprocess.run([RSSTP_REPLAY, *args], capture_output=True, text=True, check=True)
    return time.perf_counter() - started


def learn(text_or_name: str, budget: int | None) -> str:
    scenario = (
        load_scenario(text_or_name) if "\n" not in text_or_name else parse_scenario(text_or_name)
    )
    truth = compute_truth(scenario)
    n = truth.n_classes
    budget = 4 * n * n if budget is None else budget
    learner = LearnerStrategy()
    runner = Runner(scenario, learner, seed=0)
    started = time.perf_counter()
    steps = 0
    while not learner.done and runner.stopped is None and steps < budget:
        runner.step()
        steps += 1
    seconds = time.perf_counter() - started
    start = learner.start_state
    equivalent = (
        start is not None
        and len(runner.model) == n
        and check_equivalence(runner.model, learner.labels(), truth, start_state=start) is None
    )
    return (
        f"{scenario.name}: N = {n:,}, budget {budget:,} ({budget / n**2:.2f} N^2): "
        f"{steps:,} steps in {seconds:.1f} s, {len(runner.model):,} model states, "
        f"{'equivalent' if equivalent else 'NOT equivalent'}"
        + (f" ({runner.stopped})" if runner.stopped else "")
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--budget", type=int, default=200_000, help="the learner's steps on a built-in"
    )
    parser.add_argument("--sides", type=int, nargs="*", default=[3, 4, 5, 6])
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}")
    for name in BUILT_INS:
        out, wall = cold("truth", name)
        poses = re.search(r"reachable poses: ([\d,]+)", out).group(1)  # type: ignore[union-attr]
        classes = re.search(r"minimal model: ([\d,]+)", out).group(1)  # type: ignore[union-attr]
        seconds = re.search(r"seconds: ([\d.]+)", out).group(1)  # type: ignore[union-attr]
        out, _ = cold("run", name, "--strategy", "random", "--steps", "1000000", "--quiet")
        rate = re.search(r"\(([\d,]+) steps/s\)", out).group(1)  # type: ignore[union-attr]
        print(
            f"{name}: {poses} poses, N = {classes}; truth {seconds} s computing, "
            f"{wall:.2f} s cold end to end; random run {rate} steps/s cold"
        )
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / f"{name}.mcap"
            _, recorded = cold(
                "record", name, "--strategy", "random", "--steps", "100000", "-o", str(path),
                "--quiet",
            )  # fmt: skip
            audited = cold_replay("audit", "--truth", str(path))
            viewed = cold_replay("view", str(path), "--save", str(path.with_suffix(".rrd")))
            print(
                f"  100,000 random steps: record {recorded:.2f} s ({path.stat().st_size:,} "
                f"bytes), audit --truth {audited:.2f} s, view --save {viewed:.2f} s, cold"
            )
    with tempfile.TemporaryDirectory():
        for side in args.sides:
            print(learn(small_room(side), None))
        for name in BUILT_INS:
            print(learn(name, args.budget))


if __name__ == "__main__":
    main()
