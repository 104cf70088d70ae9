"""Worlds nobody tuned for: a seeded generator of arm worlds, and the learner on them (Dask).

    PYTHONPATH=src python bench/worlds.py --list                       # the worlds, no runs
    PYTHONPATH=src python bench/worlds.py --max-n 2000 --seeds 1       # the small ones, seed 0
    PYTHONPATH=src python bench/worlds.py --worlds 60 --seeds 3 --aalpy-seconds 120
    PYTHONPATH=src python bench/worlds.py --scheduler tcp://host:8786  # an existing cluster
    PYTHONPATH=src python bench/worlds.py --write worlds/              # the scenario files, no runs

The generator (:func:`generate`) draws world ``i`` of family seed ``--family`` (default 0)
from its own generator, ``default_rng([family, i])``: 2 to 4 joints, a step of 5 to 30
degrees, link lengths of 0.5 to 2.5, 0 to 4 obstacles of random size anywhere within the
arm's reach (the larger ones block whole regions of the joint space), a random start pose the
obstacles leave free, and a one-way world one time in six (the first joint turns
counter-clockwise only). The world is kept when its boolean minimal model has ``--min-n`` to
``--max-n`` classes (500 to 15,000) and, one-way, when every reachable pose can still reach
every other (the learner learns without reset). Its feedback target is a reachable pose drawn
at random, other than the start. Each world has a boolean form and a float twin (``mode =
"float"``).

Each (world, seed, feedback) is one Dask task (a ``distributed.LocalCluster`` of ``--workers``
processes on 127.0.0.1, or ``--scheduler``): the ``learner`` strategy with a budget of 4 N^2
steps (``--budget-cap`` lowers it, and a run stopped by the cap says so), then the check that
its final model is the truth's minimal model from the start (``check_equivalence``). With
``--aalpy-seconds S`` AALpy's reset-free ``run_hW`` runs beside it on seed 0 of the boolean
world (S seconds each, in a subprocess; bench/learning.py).

Prints a table (one line per world: N, joints, step, obstacles, one-way, and per feedback the
steps, steps / N^2 and whether the model is exact, for each seed; the float's steps as a share
of the boolean's) and writes ``--out`` (default ``bench-worlds/``): ``runs.csv`` and
``steps-per-n2.png`` (steps / N^2 against N, boolean and float); ``runs.csv`` is rewritten as
each run ends, so a bench stopped early keeps what it measured. Targets (issue 32): every
run exact within 4 N^2; the float twin within half the boolean's steps on each world.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from rsstp_sim.errors import RsstpError  # noqa: E402
from rsstp_sim.scenario import parse_scenario  # noqa: E402
from rsstp_sim.truth import GroundTruth, compute_truth  # noqa: E402
from scenarios import arm_toml  # noqa: E402 (the test suite's folder goes on the path first)

if TYPE_CHECKING:
    from rsstp_sim.runner import Runner
    from rsstp_sim.strategies.learner import LearnerStrategy

STEPS_DEG = (5, 6, 8, 9, 10, 12, 15, 18, 20, 24, 30)
"""The steps drawn from: divisors of 360 from 5 to 30 degrees."""


@dataclass(frozen=True)
class World:
    """A generated world: its name, its boolean scenario file, and what it was drawn as."""

    name: str
    source: str
    n: int
    poses: int
    joints: int
    step_deg: int
    obstacles: int
    one_way: bool

    def twin(self) -> str:
        """The float twin's scenario file."""
        return self.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)


def _strongly_connected(truth: GroundTruth) -> bool:
    """Whether every reachable pose reaches the start again (so every pose reaches every
    other): a backward search from the start over the pose machine."""
    next_pose = np.asarray(truth.next_pose)
    back = np.zeros(len(next_pose), dtype=bool)
    back[truth.start_index] = True
    while True:
        grown = back | back[next_pose].any(axis=1)
        if grown.sum() == back.sum():
            return bool(back.all())
        back = grown


def _draw(rng: np.random.Generator, name: str) -> dict[str, Any] | None:
    """One candidate world's arm and obstacles (:func:`arm_toml`'s arguments), sensed at its
    start; None when its start pose is blocked."""
    joints = int(rng.integers(2, 5))
    # Keep the pose space (360 / step)^joints between about 500 and 40,000 before obstacles.
    fitting = [s for s in STEPS_DEG if 500 <= (360 // s) ** joints <= 40_000]
    step = int(rng.choice(fitting))
    lengths = [round(float(v), 2) for v in rng.uniform(0.5, 2.5, joints)]
    reach = sum(lengths)
    obstacles = []
    for _ in range(int(rng.integers(0, 5))):
        distance = float(rng.uniform(0.2, 1.1)) * reach
        angle = float(rng.uniform(0, 2 * math.pi))
        radius = round(float(rng.uniform(0.03, 0.3)) * reach, 3)
        center = (round(distance * math.cos(angle), 3), round(distance * math.sin(angle), 3))
        obstacles.append((center, radius))
    initial = [int(v) * step for v in rng.integers(0, 360 // step, joints)]
    one_way = bool(rng.random() < 1 / 6)
    actions = [0, *range(2, 2 * joints)] if one_way else None
    drawn = {
        "lengths": lengths,
        "initial_deg": initial,
        "step_deg": step,
        "obstacles": obstacles,
        "name": name,
        "actions": actions,
    }
    try:
        parse_scenario(arm_toml(**drawn), origin=name)
    except RsstpError:
        return None
    return drawn


def generate(family: int, index: int, *, min_n: int, max_n: int, tries: int = 200) -> World:
    """World ``index`` of family ``family``: drawn until one fits (see the module docstring)."""
    rng = np.random.default_rng([family, index])
    name = f"world-{family}-{index}"
    for _ in range(tries):
        drawn = _draw(rng, name)
        if drawn is None:
            continue
        try:
            truth = compute_truth(parse_scenario(arm_toml(**drawn), origin=name))
        except RsstpError:
            continue
        poses = len(truth.pose_codes)
        if not min_n <= poses <= max_n or poses < 2:
            continue
        one_way = drawn["actions"] is not None
        if one_way and not _strongly_connected(truth):
            continue
        others = [p for p in range(poses) if p != truth.start_index]
        target = truth.pose_values[int(rng.choice(others))].tolist()
        text = arm_toml(**drawn, feedback={"target_deg": target})
        world_truth = compute_truth(parse_scenario(text, origin=name))
        n = world_truth.n_classes
        if not min_n <= n <= max_n:
            continue
        joints, step = len(drawn["lengths"]), drawn["step_deg"]
        return World(name, text, n, poses, joints, step, len(drawn["obstacles"]), one_way)
    raise RuntimeError(f"{name}: no world of {min_n}..{max_n} classes in {tries} draws")


# ------------------------------------------------------------------ one run (a Dask task)


@dataclass(frozen=True)
class Run:
    world: str
    n: int
    seed: int
    mode: str
    budget: int
    steps: int
    exact: bool
    done: bool
    capped: bool
    seconds: float
    states: int
    phases: str


def learned_exactly(runner: Runner, learner: LearnerStrategy, truth: GroundTruth) -> bool:
    """Whether the learner is done with the truth's minimal model. Judged from where the run
    ended: the model's current state against the class of the arm's pose (the start may be
    left open by the steps before the landmark was seen; in a world where every pose reaches
    every other, the model then has the start's state too)."""
    from rsstp_sim.truth import check_equivalence

    model = runner.model
    pose = int(np.searchsorted(truth.pose_codes, runner.world.pose_code))
    return (
        learner.done
        and len(model) == truth.n_classes
        and check_equivalence(
            model, learner.labels(), truth, start_state=model.current,
            start_class=int(truth.true_class[pose]),
        ) is None
    )  # fmt: skip


def learn(world: World, seed: int, mode: str, cap: int | None) -> Run:
    """The learner on ``world`` (``mode``: bool or float) with seed ``seed``, 4 N^2 steps at
    most (``cap`` lower); whether its final model is the truth's minimal one from the start."""
    from rsstp_sim.runner import Runner
    from rsstp_sim.strategies.learner import LearnerStrategy

    source = world.source if mode == "bool" else world.twin()
    scenario = parse_scenario(source, origin=world.name)
    truth = compute_truth(parse_scenario(world.source, origin=world.name))
    budget = 4 * world.n**2
    limit = budget if cap is None else min(budget, cap)
    learner = LearnerStrategy()
    runner = Runner(scenario, learner, seed=seed)
    step = runner.step
    started = time.perf_counter()
    steps = 0
    while not learner.done and runner.stopped is None and steps < limit:
        step()
        steps += 1
    seconds = time.perf_counter() - started
    exact = learned_exactly(runner, learner, truth)
    stats = learner.stats()
    spent = {k.removeprefix("steps_"): v for k, v in stats.items() if k.startswith("steps_")}
    phases = " ".join(f"{k}={v / max(steps, 1):.2f}" for k, v in sorted(spent.items()))
    return Run(
        world.name, world.n, seed, mode, budget, steps, exact, learner.done,
        steps >= limit and limit < budget, seconds, len(runner.model), phases,
    )  # fmt: skip


# ------------------------------------------------------------------ the report


def _table(worlds: Sequence[World], runs: Sequence[Run], seeds: int) -> str:
    by = {(r.world, r.seed, r.mode): r for r in runs}
    head = f"{'world':12s} {'N':>6s} {'j':>1s} {'deg':>3s} {'obs':>3s} {'1w':>2s}"
    lines = [head + "  per seed: bool steps (x N^2, exact) | float steps (x N^2, exact) /bool"]
    for w in worlds:
        cells = []
        for seed in range(seeds):
            parts = []
            for mode in ("bool", "float"):
                r = by.get((w.name, seed, mode))
                if r is None:
                    parts.append("not run")
                    continue
                verdict = "yes" if r.exact else ("CAP" if r.capped else "NO")
                parts.append(f"{r.steps:>11,} ({r.steps / w.n**2:5.2f}, {verdict})")
            b, f = by.get((w.name, seed, "bool")), by.get((w.name, seed, "float"))
            share = f" {f.steps / max(b.steps, 1):4.2f}" if b and f else ""
            cells.append(" | ".join(parts) + share)
        lines.append(
            f"{w.name:12s} {w.n:>6,} {w.joints:>1d} {w.step_deg:>3d} {w.obstacles:>3d} "
            f"{'y' if w.one_way else '':>2s}  " + " ; ".join(cells)
        )
    exact = sum(r.exact for r in runs)
    lines.append(f"{exact} of {len(runs)} runs exact within their budget")
    return "\n".join(lines)


def _write_runs(runs: Sequence[Run], hw: dict[str, dict[str, Any]], path: Path) -> None:
    """``runs.csv``: one row per run, smallest world first, AALpy's result beside (if run)."""
    with path.open("w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=[*Run.__dataclass_fields__, "hw"])
        writer.writeheader()
        for r in sorted(runs, key=lambda r: (r.n, r.world, r.seed, r.mode)):
            writer.writerow({**asdict(r), "hw": hw.get(r.world, {}).get("result", "")})


def _plot(runs: Sequence[Run], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(7, 4.5))
    for mode, colour in (("bool", "tab:blue"), ("float", "tab:orange")):
        mine = [r for r in runs if r.mode == mode]
        for exact, marker in ((True, "o"), (False, "x")):
            chosen = [r for r in mine if r.exact == exact]
            if chosen:
                axes.scatter(
                    [r.n for r in chosen],
                    [r.steps / r.n**2 for r in chosen],
                    c=colour,
                    marker=marker,
                    label=f"{mode}, {'exact' if exact else 'not learned'}",
                )
    axes.axhline(4, color="grey", linestyle="--", linewidth=1, label="budget 4 N²")
    from matplotlib.ticker import FuncFormatter, NullFormatter

    sizes = [r.n for r in runs]
    if max(sizes) >= 10 * min(sizes):  # (a narrow range reads better on a linear axis)
        axes.set_xscale("log")
        axes.xaxis.set_minor_formatter(NullFormatter())
    axes.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:,.0f}"))
    axes.set_yscale("log")
    axes.set_xlabel("N (classes of the boolean world)")
    axes.set_ylabel("steps / N²")
    axes.set_title("The learner on generated worlds")
    axes.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--worlds", type=int, default=60)
    parser.add_argument("--family", type=int, default=0)
    parser.add_argument("--min-n", type=int, default=500)
    parser.add_argument("--max-n", type=int, default=15_000)
    parser.add_argument("--seeds", type=int, default=3, help="seeds 0 .. K-1")
    parser.add_argument("--mode", choices=("bool", "float", "both"), default="both")
    parser.add_argument("--budget-cap", type=int, help="at most this many steps a run")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scheduler", help="an existing Dask scheduler's address")
    parser.add_argument("--aalpy-seconds", type=float, default=0.0)
    parser.add_argument("--list", action="store_true", help="the worlds only, no runs")
    parser.add_argument(
        "--write", type=Path, help="write the scenario files to this folder, no runs"
    )
    parser.add_argument("--only", nargs="*", help="these worlds only (by name)")
    parser.add_argument("--out", type=Path, default=Path("bench-worlds"))
    args = parser.parse_args(argv)

    from distributed import Client, LocalCluster, as_completed

    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(
            n_workers=args.workers, threads_per_worker=1, host="127.0.0.1", dashboard_address=None
        )
        client = Client(cluster)
    try:
        started = time.perf_counter()
        futures = client.map(
            generate,
            [args.family] * args.worlds,
            range(args.worlds),
            min_n=args.min_n,
            max_n=args.max_n,
            pure=False,
        )
        worlds = sorted(client.gather(futures), key=lambda w: w.n)
        if args.only:
            worlds = [w for w in worlds if w.name in set(args.only)]
        print(f"{len(worlds)} worlds generated in {time.perf_counter() - started:.1f} s")
        for w in worlds:
            print(
                f"  {w.name:12s} N {w.n:>6,} poses {w.poses:>6,} joints {w.joints} "
                f"step {w.step_deg:>2d} obstacles {w.obstacles} {'one-way' if w.one_way else ''}"
            )
        if args.write:
            args.write.mkdir(parents=True, exist_ok=True)
            for w in worlds:
                (args.write / f"{w.name}.toml").write_text(w.source, encoding="utf-8")
                (args.write / f"{w.name}-float.toml").write_text(w.twin(), encoding="utf-8")
        if args.list or args.write:  # (the worlds only: no runs)
            return 0
        modes = ("bool", "float") if args.mode == "both" else (args.mode,)
        tasks = [(w, s, m) for w in worlds for s in range(args.seeds) for m in modes]
        # The largest first, so that the longest runs do not start last.
        tasks.sort(key=lambda t: -t[0].n)
        futures = [client.submit(learn, w, s, m, args.budget_cap, pure=False) for w, s, m in tasks]
        args.out.mkdir(parents=True, exist_ok=True)
        runs: list[Run] = []
        for future in as_completed(futures):
            run = future.result()
            runs.append(run)
            _write_runs(runs, {}, args.out / "runs.csv")  # (kept if the bench is stopped)
            print(
                f"  {run.world:12s} seed {run.seed} {run.mode:5s} {run.steps:>11,} steps "
                f"({run.steps / run.n**2:.3f} N^2) {'exact' if run.exact else 'NOT exact'} "
                f"{run.seconds:.0f} s  {run.phases}",
                flush=True,
            )
        hw: dict[str, dict[str, Any]] = {}
        if args.aalpy_seconds > 0:
            from learning import _hw_on

            for w in worlds:
                scenario = parse_scenario(w.source, origin=w.name)
                hw[w.name] = _hw_on(w.name, scenario, args.aalpy_seconds, 0, 8.0)
                print(f"  AALpy hW on {w.name}: {hw[w.name]}", flush=True)
        print(_table(worlds, runs, args.seeds))
        _write_runs(runs, hw, args.out / "runs.csv")
        _plot(runs, args.out / "steps-per-n2.png")
        print(f"wrote {args.out / 'runs.csv'} and {args.out / 'steps-per-n2.png'}")
        return 0 if all(r.exact for r in runs) else 1
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


if __name__ == "__main__":
    sys.exit(main())
