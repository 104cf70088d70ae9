"""A long learner run and where its steps go: progress every ``--every`` steps, up to a budget.

    PYTHONPATH=src python bench/long_learner.py three-joint --budget 153914982 --minutes 50
    PYTHONPATH=src python bench/long_learner.py world.toml --budget 5000000 --every 500000

For a run too long to wait for (issue 32, point 3: ``three-joint``, boolean, within 0.1 N^2 =
153,914,982 steps), the ``learner`` through the :class:`~rsstp_sim.runner.Runner` in this
process (no recording), its ground truth computed first. Every ``--every`` steps, and at the
end (done, the budget spent, or ``--minutes`` of CPU time used): the steps (and as N^2), the
CPU seconds and steps per CPU second, the hypothesis's states, the share of the steps in each
phase so far (home: searching for the landmark; explore; identify), and the learner's
counters of new states, twins, counterexamples. At the end, whether the model is the truth's
minimal model, judged from where the run ended as `bench/worlds.py` judges it.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rsstp_sim.runner import Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies._learner_walk import PHASES
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.truth import compute_truth
from worlds import learned_exactly


def progress(runner: Runner, learner: LearnerStrategy, n: int, started: float) -> str:
    steps = runner.step_index
    seconds = time.process_time() - started
    stats = learner.stats()
    shares: dict[str, int] = {}
    for phase, kind in PHASES.items():
        shares[kind] = shares.get(kind, 0) + stats.get(f"steps_{phase}", 0)
    total = max(steps, 1)
    shown = ", ".join(f"{kind} {100 * count / total:.0f} %" for kind, count in shares.items())
    counters = ", ".join(
        f"{key} {stats.get(key, 0):,}" for key in ("new_states", "twins", "counterexamples")
    )
    return (
        f"{steps:>12,} steps ({steps / n**2:.4f} N^2) {seconds:8.0f} s CPU "
        f"({steps / max(seconds, 1e-9):,.0f}/s): {len(runner.model):,} states; {shown}; {counters}"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", help="a built-in scenario name or a scenario .toml file")
    parser.add_argument("--budget", type=int, required=True, help="the run's steps at most")
    parser.add_argument("--minutes", type=float, default=60.0, help="CPU minutes at most")
    parser.add_argument("--every", type=int, default=5_000_000, help="progress every K steps")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    path = Path(args.scenario)
    scenario = (
        parse_scenario(path.read_text(encoding="utf-8"), origin=path.name)
        if path.suffix == ".toml"
        else load_scenario(args.scenario)
    )
    truth = compute_truth(scenario)
    n = truth.n_classes
    print(f"{scenario.name}: N = {n:,}, budget {args.budget:,} ({args.budget / n**2:.3f} N^2)")
    learner = LearnerStrategy()
    runner = Runner(scenario, learner, seed=args.seed)
    started = time.process_time()
    limit = started + 60 * args.minutes
    while not learner.done and runner.stopped is None and runner.step_index < args.budget:
        for _ in range(min(args.every, args.budget - runner.step_index)):
            runner.step()
            if learner.done or runner.stopped is not None:
                break
        print(progress(runner, learner, n, started), flush=True)
        if time.process_time() > limit:
            print(f"stopped: {args.minutes:g} CPU minutes used")
            break
    exact = learned_exactly(runner, learner, truth)
    print(f"done: {learner.done}; the truth's minimal model: {'yes' if exact else 'no'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
