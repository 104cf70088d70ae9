"""The rover's figures: its ground truth, its steps, and the learner in its worlds.

    PYTHONPATH=src python bench/rover.py                  # the built-ins, and small rooms
    PYTHONPATH=src python bench/rover.py --no-cold --no-built-ins --seeds 3   # rooms, seeds 0-2
    PYTHONPATH=src python bench/rover.py --budget 400000  # the learner's budget on the built-ins

Worlds: the three built-in rover scenarios (``rover-room``, ``rover-two-rooms``,
``rover-one-way``, each sensed in one pose); open square rooms generated here (``--sides``,
default 3 x 3 to 8 x 8 cells, four headings, sensed in the north-east cell facing north); and
``--generated K`` rooms drawn by :func:`generated_room` (seeded: room ``i`` is drawn from seed
``i``), with a wall and pillars, which nobody tuned anything on.

For each built-in, cold (a fresh process each, as a user runs them; ``--no-cold`` skips it):

- ``rsstp-sim truth NAME``: the reachable poses, the true classes N, the seconds it prints
  and the process's wall time;
- ``rsstp-sim run NAME --strategy random --steps 1000000``: its printed steps per second;
- ``rsstp-sim record NAME --strategy random --steps 100000``, then ``rsstp-replay audit
  --truth`` and ``rsstp-replay view --save`` of that recording: each one's wall time, and the
  file's size.

Then the learner, in this process, for each seed of ``--seeds`` (default 1: seed 0): on each
room with a budget of ``--factor`` N^2 steps (default 4), on each built-in with ``--budget``
steps (``--no-built-ins`` skips them); the steps it took, its model's states, and whether the
model is equivalent to the truth (:func:`rsstp_sim.truth.check_equivalence`) from the state
the learner says the run started in (:attr:`LearnerStrategy.start_state
<rsstp_sim.strategies.learner.LearnerStrategy.start_state>`); and, when it is not, whether it
is from some state of the model (``right model, start unknown``: walls can bring two starts
to one pose before the sensation is first seen, and then no trajectory tells them apart).

``--mode float``: the float twin of each world (``mode = "float"`` in its ``[feedback]``).

``--diagnose``: after each run, what the learner's hypothesis got wrong against the truth
(:func:`diagnose`): duplicate states, and confirmed transitions that lead to the wrong class.

Targets (issue 31): thousands of classes per built-in; the learner learns every rover world
exactly within 4 N^2 steps (missed, 2026-11-28: docs/strategies.md).
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

import numpy as np

from rsstp_sim.runner import Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.truth import GroundTruth, check_equivalence, compute_truth

BUILT_INS = ("rover-room", "rover-two-rooms", "rover-one-way")
RSSTP_SIM = str(Path(sys.executable).with_name("rsstp-sim"))
RSSTP_REPLAY = str(Path(sys.executable).with_name("rsstp-replay"))


def small_room(side: int) -> str:
    return (
        f'name = "open-{side}x{side}"\n[rover]\nroom = [{side}, {side}]\nstart = [0, 0]\n'
        f"[feedback]\ncenter = [{side - 0.5}, {side - 0.5}]\nheading_deg = 90\n"
    )


def generated_room(seed: int) -> str:
    """A rover room drawn from ``seed``: 4 to 7 cells a side, four headings, a wall from one
    edge with a gap, one or two pillars, the start and the sensed cell (facing north) drawn
    among the cells every pose of the room reaches (checked with the ground truth: redrawn
    until one pose senses and the world is strongly connected)."""
    rng = np.random.default_rng(seed)
    while True:
        width, height = (int(v) for v in rng.integers(4, 8, size=2))
        x = int(rng.integers(1, width))
        gap = int(rng.integers(0, height - 1))
        walls = [(x, 0.0, x, float(gap)), (x, float(gap + 1), x, float(height))]
        walls = [w for w in walls if w[1] != w[3]]
        pillars = [
            (float(rng.integers(1, width)), float(rng.integers(1, height)), 0.3)
            for _ in range(int(rng.integers(1, 3)))
        ]
        start = [int(rng.integers(width)), int(rng.integers(height))]
        sensed = [int(rng.integers(width)), int(rng.integers(height))]
        text = (
            f'name = "room-{seed}"\n[rover]\nroom = [{width}, {height}]\nstart = {start}\n'
            + "".join(f"[[walls]]\nfrom = [{a}, {b}]\nto = [{c}, {d}]\n" for a, b, c, d in walls)
            + "".join(f"[[obstacles]]\ncenter = [{a}, {b}]\nradius = {r}\n" for a, b, r in pillars)
            + f"[feedback]\ncenter = [{sensed[0] + 0.5}, {sensed[1] + 0.5}]\nheading_deg = 90\n"
        )
        truth = compute_truth(parse_scenario(text))
        if truth.n_sensed == 1 and truth.classes_reached_from(truth.n_classes - 1).all():
            return text


def diagnose(learner: LearnerStrategy, truth: GroundTruth) -> str:
    """What the learner's hypothesis got wrong, against the truth: each state stands for the
    class its access word (from the sensed pose) reaches; the classes it stands for twice or
    more (duplicates, waiting for the merge at the end), and the confirmed transitions that
    lead to a state standing for another class than the truth's (wrong, waiting for a
    counterexample or the final verification). Reads the learner's internals: a bench tool."""
    learning = learner._learning  # noqa: SLF001 - a diagnosis, not an API
    if learning is None or not learning.found:
        return "diagnosis: the sensed pose never seen"
    h = learning.h
    column = {a: k for k, a in enumerate(truth.actions)}
    (sensed,) = np.flatnonzero(truth.class_sensation).tolist()
    stands_for: dict[int, int] = {}
    for s, word in h.access.items():
        c = sensed
        for a in word:
            c = int(truth.class_next[c, column[a]])
        stands_for[s] = c
    states = list(stands_for)
    wrong = confirmed = 0
    for s in states:
        for a in truth.actions:
            t = int(h.next[s, h.column[a]])
            if t >= 0:
                confirmed += 1
                wrong += stands_for.get(t) != int(truth.class_next[stands_for[s], column[a]])
    classes = len(set(stands_for.values()))
    return (
        f"  diagnosis: {len(states):,} states for {classes:,} of {truth.n_classes:,} classes "
        f"({len(states) - classes:,} duplicates); {confirmed:,} confirmed transitions, "
        f"{wrong:,} wrong"
    )


def cold(*args: str) -> tuple[str, float]:
    started = time.perf_counter()
    done = subprocess.run([RSSTP_SIM, *args], capture_output=True, text=True, check=True)
    return done.stdout, time.perf_counter() - started


def cold_replay(*args: str) -> float:
    started = time.perf_counter()
    subprocess.run([RSSTP_REPLAY, *args], capture_output=True, text=True, check=True)
    return time.perf_counter() - started


def learn(
    text_or_name: str,
    budget: int | None,
    *,
    seed: int = 0,
    factor: float = 4.0,
    diagnosis: bool = False,
    mode: str = "bool",
) -> str:
    text = load_scenario(text_or_name).source if "\n" not in text_or_name else text_or_name
    if mode == "float":
        text = text.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    scenario = parse_scenario(text)
    truth = compute_truth(scenario)
    n = truth.n_classes
    budget = int(factor * n * n) if budget is None else budget
    learner = LearnerStrategy()
    runner = Runner(scenario, learner, seed=seed)
    started = time.perf_counter()
    steps = 0
    while not learner.done and runner.stopped is None and steps < budget:
        runner.step()
        steps += 1
    seconds = time.perf_counter() - started
    start = learner.start_state
    labels = learner.labels()
    equivalent = (
        start is not None
        and len(runner.model) == n
        and check_equivalence(runner.model, labels, truth, start_state=start) is None
    )
    verdict = "equivalent"
    if not equivalent:
        right = len(runner.model) == n and any(
            check_equivalence(runner.model, labels, truth, start_state=s) is None
            for s in runner.model.states
        )
        verdict = "NOT equivalent (right model, start unknown)" if right else "NOT equivalent"
    return (
        f"{scenario.name} ({mode}) seed {seed}: N = {n:,}, "
        f"budget {budget:,} ({budget / n**2:.2f} N^2): "
        f"{steps:,} steps ({steps / n**2:.2f} N^2) in {seconds:.1f} s, "
        f"{len(runner.model):,} model states, {verdict}"
        + (f" ({runner.stopped})" if runner.stopped else "")
        + (f"\n{diagnose(learner, truth)}" if diagnosis else "")
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--budget", type=int, default=200_000, help="the learner's steps on a built-in"
    )
    parser.add_argument("--sides", type=int, nargs="*", default=[3, 4, 5, 6, 7, 8])
    parser.add_argument("--generated", type=int, default=3, help="generated rooms (seeds 0..K-1)")
    parser.add_argument("--seeds", type=int, default=1, help="the learner's seeds 0..K-1")
    parser.add_argument("--factor", type=float, default=4.0, help="the rooms' budget, x N^2")
    parser.add_argument("--no-cold", action="store_true", help="skip the cold subprocess runs")
    parser.add_argument("--no-built-ins", action="store_true", help="the learner on rooms only")
    parser.add_argument(
        "--diagnose", action="store_true", help="duplicates and wrong transitions at the end"
    )
    parser.add_argument(
        "--mode", choices=("bool", "float"), default="bool", help="the learner's feedback"
    )
    args = parser.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f}")
    for name in () if args.no_cold else BUILT_INS:
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
    rooms = [small_room(side) for side in args.sides]
    rooms += [generated_room(i) for i in range(args.generated)]
    for seed in range(args.seeds):
        for room in rooms:
            print(
                learn(room, None, seed=seed, factor=args.factor, diagnosis=args.diagnose,
                      mode=args.mode),
                flush=True,
            )  # fmt: skip
        for name in () if args.no_built_ins else BUILT_INS:
            print(
                learn(name, args.budget, seed=seed, diagnosis=args.diagnose, mode=args.mode),
                flush=True,
            )


if __name__ == "__main__":
    main()
