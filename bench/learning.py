"""Learning the minimal model from one trajectory: the ``learner`` strategy against AALpy.

    PYTHONPATH=src python bench/learning.py                 # everything, a few minutes
    PYTHONPATH=src python bench/learning.py --aalpy-seconds 30
    PYTHONPATH=src python bench/learning.py --no-aalpy
    PYTHONPATH=src python bench/learning.py --spread 10     # steps to learn over seeds 0-9
    PYTHONPATH=src python bench/learning.py --curve --max-n 1200 --no-aalpy   # steps / N^2
    PYTHONPATH=src python bench/learning.py --curve --seeds 5 --no-aalpy      # seeds 0-4
    PYTHONPATH=src python bench/learning.py --audit RUN.mcap   # audit --truth of a kept run, cold

For each built-in scenario: the ground truth's minimal model (N states); the ``learner``
strategy run until it is done (or its step budget is spent), its steps, seconds and whether its
final model is equivalent to the truth (:func:`rsstp_sim.truth.check_equivalence` from the state
the run started in, and N states); then AALpy 2.x on the same world:

- ``run_hW`` (hW-inference, reset-free), the world wrapped as an AALpy SUL whose ``step``
  moves the arm and returns the sensation and whose reset refuses (there is none): run in a
  subprocess, stopped after ``--aalpy-seconds`` (default 240);
- the passive learners RPNI and EDSM on one trajectory (the prefixes of a random walk of the
  learner's step budget), on the small cycles only.

An AALpy model is judged equivalent when one of its states is equivalent to the start pose's
class: run_hW is not asked for its initial state (that would need a reset).

Targets: equivalent on every scenario; at most 4 x N^2 steps on the one-joint cycles and 50,000
on two-joint-30; each learner run under a minute.

``--curve``: steps to learn as a multiple of N^2 against N, on worlds of about 36, 119, 360,
1,200 and 5,000 classes (:data:`CURVE`: the built-in one-joint-10, two-joint-30 and
thesis-algo, then two links (2, 1) with one obstacle at 10 and at 5 degrees), each in its
boolean form and its float twin (``mode = "float"``: the learner climbs the closeness and
tells poses apart by it), one line per seed (``--seeds K``: seeds 0 .. K-1, default 1), with
the float's steps as a share of the boolean's, and AALpy's run_hW beside the boolean one on
seed 0 unless ``--no-aalpy`` (a world of the curve is handed to it as a scenario file);
``--max-n`` leaves out larger worlds, ``--min-n`` smaller ones, ``--mode bool`` (or
``float``) runs one twin only. The budget is 4 N^2 steps; the seconds are the
learner's own, warm (the truth is computed first). Targets: every run equivalent within
4 N^2; the float twin of the 1,200-class world in at most half the boolean's steps.

``--record WORLD``: the user's path on a world of the curve (``--record two-links-10``, with
``--float`` its twin, ``--seed``): its scenario file written, then ``rsstp-sim run`` and
``rsstp-sim record`` with the learner and a budget of 4 N^2 steps, ``rsstp-replay audit
--truth`` and ``rsstp-replay view --save`` of the recording, each cold in a fresh process:
wall and CPU seconds, peak memory, ``record`` against ``run``, the recording's size, where the
run stopped and the audit's verdict. ``--keep FILE`` keeps the recording (for
``bench/model_at.py``); ``--compact`` records a compact file (``rsstp-sim record --compact``:
no message indexes, chunks compressed harder). Targets: the record of the 1,200-class world at
most 2 minutes; for the 4,841-class world (``two-links-5``, issue 32): ``record`` at most 1.5 x
``run``, a file of at most 40 MB, ``audit --truth`` within 20 s and 1 GiB, ``view --save``
within 1 GiB.

``--audit FILE``: ``rsstp-replay audit FILE --truth --json --quiet`` alone, cold in a fresh
process, ``--repeat`` times (default 3), on a recording kept with ``--keep`` (the 4,841-class
run takes minutes to record): wall and CPU seconds, peak memory, the load average before each
run, and the verdict. Target for the 4,841-class run: within 20 s and 1 GiB.

``--spread K``: the learner alone on each scenario with seeds ``0 .. K-1``, the steps to learn
(least, median, most, and as multiples of N^2) and how many runs ended equivalent: the seed
reaches every choice the learner makes among equals, so the runs differ.

AALpy is the ``bench`` extra (``pip install aalpy``); without it the AALpy columns say so.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from _cold import measure_cpu
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.world import World
from rsstp_sim.runner import Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.truth import GroundTruth, check_equivalence, compute_truth

SCENARIOS = ("thesis-roulette", "one-joint-10", "thesis-algo", "two-joint-30")
TWO_JOINT_BUDGET = 50_000
PASSIVE_LIMIT = 40
"""Passive learners run on scenarios with at most this many states (the data grows as T^2)."""


def budget_for(name: str, truth: GroundTruth) -> int:
    return TWO_JOINT_BUDGET if truth.n_values > 1 else 4 * truth.n_classes**2


# ------------------------------------------------------------------ judging


def equivalent_states(
    successors: Sequence[Sequence[int]], labels: Sequence[bool], truth: GroundTruth
) -> list[int]:
    """The states of a complete Moore machine equivalent to the truth's start class.

    ``successors[s][k]`` is the state ``s`` reaches by ``truth.actions[k]``. The machine and
    the truth's minimal machine are refined together (Moore's partition refinement over their
    disjoint union); a state is equivalent to the start class when they end in one block.
    """
    n = len(successors)
    nxt = np.concatenate(
        [np.asarray(successors, dtype=np.int64).reshape(n, -1), truth.class_next + n]
    )
    out = np.concatenate([np.asarray(labels, dtype=bool), truth.class_sensation])
    block = out.astype(np.int64)
    count = len(np.unique(block))
    while True:
        signature = np.concatenate([block[:, None], block[nxt]], axis=1)
        block = np.unique(signature, axis=0, return_inverse=True)[1].ravel()
        refined = int(block.max()) + 1
        if refined == count:
            break
        count = refined
    return [s for s in range(n) if block[s] == block[n]]


@dataclass
class Row:
    scenario: str
    n: int
    budget: int
    steps: int
    seconds: float
    states: int
    equivalent: bool
    done: bool
    hw: dict[str, Any] | None = None
    passive: dict[str, str] | None = None


# ------------------------------------------------------------------ the learner


def run_learner(scenario: Scenario, truth: GroundTruth, budget: int, seed: int) -> Row:
    learner = LearnerStrategy()
    runner = Runner(scenario, learner, seed=seed)
    step = runner.step
    started = time.perf_counter()
    steps = 0
    while not learner.done and runner.stopped is None and steps < budget:
        step()
        steps += 1
    seconds = time.perf_counter() - started
    model = runner.model
    start = learner.start_state
    equivalent = (
        start is not None
        and len(model) == truth.n_classes
        and check_equivalence(model, learner.labels(), truth, start_state=start) is None
    )
    return Row(
        scenario.name, truth.n_classes, budget, steps, seconds, len(model), equivalent, learner.done
    )


# ------------------------------------------------------------------ AALpy


def _aalpy_version() -> str | None:
    try:
        from importlib.metadata import version

        return version("aalpy")
    except Exception:
        return None


class _OutOfTime(Exception):
    pass


def _world_sul(scenario: Scenario, deadline: float) -> Any:
    """The arm as an AALpy SUL: ``step(action)`` moves it, ``step(None)`` reads the sensation."""
    from aalpy.base import SUL  # type: ignore[import-untyped,import-not-found,unused-ignore]

    class WorldSUL(SUL):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__()
            self.world = World(scenario)
            self.world.reset()
            self.moves = 0
            self.started = False

        def pre(self) -> None:
            if self.started:
                raise RuntimeError("the arm cannot be reset: a reset-free learner must not ask")
            self.started = True

        def post(self) -> None:
            return None

        def step(self, letter: Any) -> bool:
            if letter is not None:
                self.world.move(letter)
                self.moves += 1
                if self.moves % 65_536 == 0:
                    print(json.dumps({"progress": self.moves}), file=sys.stderr, flush=True)
                    if time.perf_counter() > deadline:
                        raise _OutOfTime
            return self.world.sensation

    return WorldSUL()


def _hw_child(name: str, seconds: float, seed: int, memory_gib: float) -> None:
    """Run hW-inference on one scenario and print one JSON line (the subprocess's job)."""
    from aalpy import RandomWphWOracle, run_hW  # type: ignore[import-untyped,import-not-found,unused-ignore]

    try:  # hW keeps the whole trace: 5 GiB after 80 million steps
        import resource

        limit = int(memory_gib * 2**30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (ImportError, ValueError, OSError):
        pass
    random.seed(seed)
    scenario = load_scenario(name)
    truth = compute_truth(scenario)
    started = time.perf_counter()
    sul = _world_sul(scenario, started + seconds)
    result: dict[str, Any]
    try:
        model = run_hW(
            list(scenario.actions),
            sul,
            RandomWphWOracle(),
            "moore",
            query_for_initial_state=False,
            print_level=0,
        )
    except _OutOfTime:
        result = {"result": f"no model within {seconds:g} s"}
    except MemoryError:
        result = {"result": f"no model: out of its {memory_gib:g} GiB of memory"}
    except Exception as exc:  # report what happened, whatever it is
        result = {"result": f"error: {type(exc).__name__}: {exc}"}
    else:
        states = list(model.states)
        index = {id(s): i for i, s in enumerate(states)}
        try:
            successors = [[index[id(s.transitions[a])] for a in scenario.actions] for s in states]
        except KeyError:
            result = {"result": "incomplete model", "states": len(states)}
        else:
            labels = [bool(s.output) for s in states]
            same = equivalent_states(successors, labels, truth)
            verdict = "equivalent" if same and len(states) == truth.n_classes else "NOT equivalent"
            result = {"result": verdict, "states": len(states)}
    result["steps"] = sul.moves
    result["seconds"] = round(time.perf_counter() - started, 2)
    print(json.dumps(result), flush=True)


def run_hw(name: str, seconds: float, seed: int, memory_gib: float) -> dict[str, Any]:
    """hW-inference in a subprocess, stopped after ``seconds`` (and killed a minute later)."""
    command = [
        sys.executable,
        __file__,
        "--hw-child",
        name,
        "--aalpy-seconds",
        str(seconds),
        "--aalpy-memory-gib",
        str(memory_gib),
        "--seed",
        str(seed),
    ]
    started = time.perf_counter()
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=seconds + 60)
    except subprocess.TimeoutExpired as exc:
        progress = [
            json.loads(line)["progress"]
            for line in (exc.stderr or b"").decode().splitlines()
            if line.startswith('{"progress"')
        ]
        return {
            "result": f"killed after {seconds + 60:g} s",
            "steps": progress[-1] if progress else None,
            "seconds": round(time.perf_counter() - started, 2),
        }
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    if not lines:
        tail = (done.stderr.strip().splitlines() or ["no output"])[-1]
        return {"result": f"error: {tail}", "steps": None, "seconds": None}
    report: dict[str, Any] = json.loads(lines[-1])
    return report


def run_passive(scenario: Scenario, truth: GroundTruth, steps: int, seed: int) -> dict[str, str]:
    """RPNI and EDSM on the prefixes of one random walk of ``steps`` steps."""
    from aalpy.learning_algs import (  # type: ignore[import-untyped,import-not-found,unused-ignore]
        run_EDSM,
        run_RPNI,
    )

    world = World(scenario)
    rng = np.random.default_rng(seed)
    inputs = [int(a) for a in rng.choice(scenario.actions, size=steps)]
    outputs = [world.reset().sensation]
    for a in inputs:
        world.move(a)
        outputs.append(world.sensation)
    data = [(tuple(inputs[:t]), outputs[t]) for t in range(steps + 1)]
    verdicts: dict[str, str] = {}
    for label, learn in (("RPNI", run_RPNI), ("EDSM", run_EDSM)):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "not input-complete": completed below
                model = learn(data, "moore", print_info=False)
        except Exception as exc:
            verdicts[label] = f"error: {type(exc).__name__}"
            continue
        if model is None:
            verdicts[label] = "no model"
            continue
        model.make_input_complete("self_loop")
        states = list(model.states)
        index = {id(s): i for i, s in enumerate(states)}
        successors = [[index[id(s.transitions[a])] for a in scenario.actions] for s in states]
        labels = [bool(s.output) for s in states]
        same = equivalent_states(successors, labels, truth)
        right = index[id(model.initial_state)] in same and len(states) == truth.n_classes
        verdicts[label] = f"{len(states)} states, {'equivalent' if right else 'NOT equivalent'}"
    return verdicts


# ------------------------------------------------------------------ report


def _format(rows: list[Row]) -> str:
    head = (
        f"{'scenario':16s} {'N':>4s} | {'learner steps':>13s} {'x N^2':>6s} {'budget':>8s} "
        f"{'s':>6s} {'equiv':>5s} | {'AALpy hW steps':>14s} {'x N^2':>6s} {'s':>7s}  result"
    )
    lines = [head, "-" * len(head)]
    for r in rows:
        ok = "yes" if r.equivalent else "NO"
        within = "" if r.steps <= r.budget and r.done else " (budget spent)"
        if r.hw is None:
            hw = f"{'-':>14s} {'-':>6s} {'-':>7s}  not run"
        else:
            steps = r.hw.get("steps")
            secs = r.hw.get("seconds")
            hw = (
                f"{'-' if steps is None else format(steps, ','):>14} "
                f"{'-' if steps is None else format(steps / r.n**2, '.1f'):>6} "
                f"{'-' if secs is None else format(secs, '.1f'):>7}  {r.hw['result']}"
                + (f" ({r.hw['states']} states)" if "states" in r.hw else "")
            )
        lines.append(
            f"{r.scenario:16s} {r.n:>4d} | {r.steps:>13,} {r.steps / r.n**2:>6.1f} "
            f"{r.budget:>8,} {r.seconds:>6.2f} {ok:>5s} | {hw}{within}"
        )
    passive = [r for r in rows if r.passive]
    if passive:
        lines.append("")
        lines.append("AALpy passive learners on one random walk of the learner's budget:")
        for r in passive:
            assert r.passive is not None
            found = ", ".join(f"{k}: {v}" for k, v in r.passive.items())
            lines.append(f"  {r.scenario:16s} {r.budget:>8,} steps  {found}")
    return "\n".join(lines)


def _two_links(step_deg: int, *, float_mode: bool = False) -> Scenario:
    """Links (2, 1) from (0, 0), one obstacle at (0, 2.5) of radius 0.5, sensed at (0, 0)."""
    mode = '\nmode = "float"' if float_mode else ""
    return parse_scenario(
        f'name = "two-links-{step_deg}"\n[arm]\nlengths = [2.0, 1.0]\ninitial_deg = [0, 0]\n'
        f"step_deg = {step_deg}\n[[obstacles]]\ncenter = [0.0, 2.5]\nradius = 0.5\n"
        f"[feedback]\ntarget_deg = [0, 0]{mode}\n"
    )


def _twin(scenario: Scenario) -> Scenario:
    """``scenario`` with ``mode = "float"``."""
    if "[feedback]\n" in scenario.source:
        source = scenario.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    else:
        source = scenario.source + '\n[feedback]\nmode = "float"\n'
    return parse_scenario(source)


CURVE: tuple[tuple[str, Any], ...] = (
    ("one-joint-10", lambda: load_scenario("one-joint-10")),
    ("two-joint-30", lambda: load_scenario("two-joint-30")),
    ("thesis-algo", lambda: load_scenario("thesis-algo")),
    ("two-links-10", lambda: _two_links(10)),
    ("two-links-5", lambda: _two_links(5)),
)
"""The worlds of ``--curve``, smallest first."""


def curve(
    max_n: int,
    seeds: int,
    aalpy: bool,
    seconds: float,
    memory_gib: float,
    *,
    min_n: int = 0,
    modes: Sequence[str] = ("bool", "float"),
) -> bool:
    """Steps to learn / N^2 against N (see the module docstring); one line per world and
    seed, the worlds of ``min_n`` to ``max_n`` classes, the boolean world and (or) its
    float twin (``modes``)."""
    head = (
        f"{'world':14s} {'N':>6s} {'seed':>4s} | {'bool steps':>10s} {'x N^2':>6s} {'s':>7s} "
        f"{'eq':>3s} | {'float steps':>11s} {'x N^2':>6s} {'s':>7s} {'eq':>3s} "
        f"{'/bool':>5s} | AALpy hW"
    )
    print(head)
    print("-" * len(head))
    good = True
    for name, make in CURVE:
        scenario = make()
        truth = compute_truth(scenario)
        n = truth.n_classes
        if not min_n <= n <= max_n:
            print(f"{name:14s} {n:>6,} | left out (--min-n {min_n:,} --max-n {max_n:,})")
            continue
        budget = 4 * n**2
        for seed in range(seeds):
            cells = []
            rows = []
            for mode, world in (("bool", scenario), ("float", _twin(scenario))):
                width = 10 if not cells else 11
                if mode not in modes:
                    cells.append(f"{'not run':>{width}s} {'':>6s} {'':>7s} {'':>3s}")
                    continue
                row = run_learner(world, truth, budget, seed)
                rows.append(row)
                good &= row.equivalent and row.done
                cells.append(
                    f"{row.steps:>{width},} {row.steps / n**2:>6.2f} "
                    f"{row.seconds:>7.1f} {'yes' if row.equivalent else 'NO':>3s}"
                )
            share = f"{rows[1].steps / max(rows[0].steps, 1):>5.2f}" if len(rows) == 2 else "    -"
            hw = "not run"
            if aalpy and seed == 0:
                found = _hw_on(name, scenario, seconds, seed, memory_gib)
                hw = (
                    f"{found.get('steps') or 0:,} steps, {found.get('seconds')} s: "
                    f"{found['result']}"
                )
            print(
                f"{name:14s} {n:>6,} {seed:>4d} | {cells[0]} | {cells[1]} {share} | {hw}",
                flush=True,
            )
    return good


def record(
    name: str, seed: int, *, float_mode: bool, keep: Path | None = None, compact: bool = False
) -> bool:
    """``rsstp-sim run``, ``rsstp-sim record``, then ``rsstp-replay audit --truth`` and ``view
    --save`` of a world of the curve, cold; prints one line each, returns whether the
    recording's final model is the truth's. ``keep``: copy the recording there."""
    makers = dict(CURVE)
    if name not in makers:
        sys.exit(f"--record: expected one of {', '.join(makers)}, got {name!r}")
    scenario = makers[name]()
    if float_mode:
        scenario = _twin(scenario)
    n = compute_truth(scenario).n_classes
    sim, replay = (
        str(Path(sys.executable).parent / command) for command in ("rsstp-sim", "rsstp-replay")
    )
    with tempfile.TemporaryDirectory() as folder:
        toml = Path(folder) / f"{scenario.name}.toml"
        toml.write_text(scenario.source, encoding="utf-8")
        mcap = str(Path(folder) / f"{scenario.name}.mcap")
        budget = str(4 * n * n)
        commands = {
            "run": [sim, "run", str(toml), "--strategy", "learner", "--steps", budget]
            + ["--seed", str(seed), "--quiet"],
            "record": [
                sim,
                "record",
                str(toml),
                "--strategy",
                "learner",
                "--steps",
                budget,
                "--seed",
                str(seed),
                "--quiet",
                "-o",
                mcap,
                *(["--compact"] if compact else []),
            ],
            "audit --truth": [replay, "audit", mcap, "--truth", "--json", "--quiet"],
            "view --save": [replay, "view", mcap, "--save", str(Path(folder) / "run.rrd")],
        }
        print(
            f"{scenario.name} ({'float' if float_mode else 'boolean'}), N = {n:,}, seed {seed}, "
            f"load average {os.getloadavg()[0]:.1f}"
        )
        walls = {}
        for what, command in commands.items():
            wall, cpu, peak = measure_cpu(command)
            walls[what] = wall
            print(f"  {what:14s} {wall:7.1f} s wall {cpu:7.1f} s CPU {peak:5.2f} GiB", flush=True)
        print(f"  record / run: {walls['record'] / walls['run']:.2f} x")
        size = Path(mcap).stat().st_size
        if keep is not None:
            shutil.copyfile(mcap, keep)
        done = subprocess.run(
            commands["audit --truth"], capture_output=True, text=True, check=False
        )
    audit = json.loads(done.stdout)
    stopped = audit["summary"]["stopped"]
    stop = "its budget spent" if stopped is None else f"stopped at step {stopped['step']:,}"
    print(f"  {size / 1e6:.0f} MB; {stop}; {audit['verdict']['text']}")
    return bool(audit["truth"]["final_equivalent"])


def audit(mcap: Path, repeat: int) -> bool:
    """``rsstp-replay audit --truth`` of a kept recording, cold, ``repeat`` times; prints one
    line each, returns whether the recording's final model is the truth's."""
    if not mcap.is_file():
        sys.exit(f"--audit: expected a recording, {mcap} is not a file")
    replay = str(Path(sys.executable).parent / "rsstp-replay")
    command = [replay, "audit", str(mcap), "--truth", "--json", "--quiet"]
    print(f"rsstp-replay audit --truth --json of {mcap} ({mcap.stat().st_size / 1e6:.0f} MB)")
    for _ in range(repeat):
        load = os.getloadavg()[0]
        wall, cpu, peak = measure_cpu(command)
        print(
            f"  {wall:7.1f} s wall {cpu:7.1f} s CPU {peak:5.2f} GiB (load average {load:.1f})",
            flush=True,
        )
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    found = json.loads(done.stdout)
    print(f"  {found['verdict']['text']}")
    return bool(found["truth"]["final_equivalent"])


def _hw_on(
    name: str, scenario: Scenario, seconds: float, seed: int, memory_gib: float
) -> dict[str, Any]:
    """:func:`run_hw` on a built-in scenario by name, on another one by a scenario file."""
    if name in SCENARIOS:
        return run_hw(name, seconds, seed, memory_gib)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"{name}.toml"
        path.write_text(scenario.source, encoding="utf-8")
        return run_hw(str(path), seconds, seed, memory_gib)


def spread(names: Sequence[str], seeds: int) -> bool:
    """The learner on each scenario with seeds ``0 .. seeds-1``; prints one line per scenario,
    returns whether every run ended equivalent within its budget."""
    head = (
        f"{'scenario':16s} {'N':>5s} {'seeds':>5s} | {'least':>9s} {'median':>9s} {'most':>9s} "
        f"| {'x N^2':>17s} | equivalent  distinct runs"
    )
    print(head)
    print("-" * len(head))
    good = True
    for name in names:
        scenario = load_scenario(name)
        truth = compute_truth(scenario)
        budget = budget_for(name, truth)
        rows = [run_learner(scenario, truth, budget, seed) for seed in range(seeds)]
        steps = np.array([r.steps for r in rows])
        n2 = truth.n_classes**2
        equivalent = sum(r.equivalent and r.done for r in rows)
        good &= equivalent == len(rows)
        low, mid, high = int(steps.min()), float(np.median(steps)), int(steps.max())
        print(
            f"{name:16s} {truth.n_classes:>5d} {seeds:>5d} | {low:>9,} {mid:>9,.0f} {high:>9,} "
            f"| {low / n2:>5.2f} {mid / n2:>5.2f} {high / n2:>5.2f} | {equivalent:>4d} of "
            f"{len(rows):<4d} {len(set(steps.tolist())):>5d}",
            flush=True,
        )
    return good


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--aalpy-seconds", type=float, default=240.0)
    parser.add_argument("--aalpy-memory-gib", type=float, default=8.0)
    parser.add_argument("--no-aalpy", action="store_true")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--spread", type=int, metavar="K", help="the learner over seeds 0..K-1")
    parser.add_argument("--curve", action="store_true", help="steps / N^2 against N")
    parser.add_argument("--max-n", type=int, default=10_000, help="--curve: the largest N")
    parser.add_argument("--seeds", type=int, default=1, help="--curve: seeds 0 .. K-1")
    parser.add_argument("--min-n", type=int, default=0, help="--curve: the smallest N")
    parser.add_argument(
        "--mode", choices=("both", "bool", "float"), default="both", help="--curve: which twin"
    )
    parser.add_argument("--record", metavar="WORLD", help="record and audit a world of the curve")
    parser.add_argument("--float", action="store_true", help="--record: the float twin")
    parser.add_argument("--keep", type=Path, metavar="FILE", help="--record: keep the recording")
    parser.add_argument("--compact", action="store_true", help="--record: a compact file")
    parser.add_argument(
        "--audit", type=Path, metavar="FILE", help="audit --truth of a recording, cold"
    )
    parser.add_argument("--repeat", type=int, default=3, help="--audit: how many times")
    parser.add_argument("--hw-child", metavar="SCENARIO", help=argparse.SUPPRESS)
    parser.add_argument("scenarios", nargs="*", default=list(SCENARIOS))
    args = parser.parse_args(argv)
    if args.hw_child:
        _hw_child(args.hw_child, args.aalpy_seconds, args.seed, args.aalpy_memory_gib)
        return 0
    if args.audit:
        if args.repeat < 1:
            parser.error(f"--repeat must be >= 1, got {args.repeat}")
        return 0 if audit(args.audit, args.repeat) else 1
    if args.record:
        return (
            0
            if record(
                args.record, args.seed, float_mode=args.float, keep=args.keep, compact=args.compact
            )
            else 1
        )
    if args.curve:
        ok = curve(
            args.max_n,
            args.seeds,
            not args.no_aalpy and _aalpy_version() is not None,
            args.aalpy_seconds,
            args.aalpy_memory_gib,
            min_n=args.min_n,
            modes=("bool", "float") if args.mode == "both" else (args.mode,),
        )
        return 0 if ok else 1
    if args.spread is not None:
        if args.spread < 1:
            parser.error(f"--spread must be >= 1, got {args.spread}")
        return 0 if spread(args.scenarios, args.spread) else 1

    aalpy = None if args.no_aalpy else _aalpy_version()
    if not args.no_aalpy and aalpy is None:
        print("AALpy is not installed (pip install aalpy, the bench extra): its columns are empty")
    elif aalpy is not None:
        print(
            f"AALpy {aalpy}; run_hW with RandomWphWOracle(), capped at {args.aalpy_seconds:g} s "
            f"and {args.aalpy_memory_gib:g} GiB"
        )
    rows: list[Row] = []
    for name in args.scenarios:
        scenario = load_scenario(name)
        truth = compute_truth(scenario)
        budget = budget_for(name, truth)
        row = run_learner(scenario, truth, budget, args.seed)
        if aalpy is not None:
            row.hw = run_hw(name, args.aalpy_seconds, args.seed, args.aalpy_memory_gib)
            if truth.n_classes <= PASSIVE_LIMIT:
                row.passive = run_passive(scenario, truth, budget, args.seed)
        rows.append(row)
        print(f"  {name}: learner {row.steps:,} steps, {row.seconds:.2f} s", flush=True)
    print()
    print(_format(rows))
    good = all(r.equivalent and r.steps <= r.budget and r.seconds < 60 for r in rows)
    return 0 if good else 1


if __name__ == "__main__":
    sys.exit(main())
