"""Simulation speed: world moves and coupled steps per second (issue: the simulator).

Targets on ``three-joint`` with the ``random`` strategy, float feedback and the
obstacle distances read every step: world moves >= 200,000/s and coupled steps
>= 100,000/s with a warm pose cache; the cold-cache figures are reported too.
The original platform: 19,000 moves/s, 9,300 coupled steps/s (printing off).

Run: ``python bench/step_rate.py [--steps N]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from rsstp_sim import RandomStrategy, Runner, World, load_scenario, parse_scenario
from rsstp_sim.arm.scenario import Scenario


def float_mode(name: str) -> Scenario:
    base = load_scenario(name)
    text = base.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    if "[feedback]" not in base.source:
        text += '\n[feedback]\nmode = "float"\n'
    return parse_scenario(text, origin=f"{name} (float feedback)")


def world_moves(scenario: Scenario, steps: int) -> tuple[float, float]:
    actions = np.random.default_rng(1).choice(scenario.actions, size=steps).tolist()
    world = World(scenario)
    rates = []
    for _ in range(2):  # cold, then warm over the same walk
        world.reset()
        move = world.move
        started = time.perf_counter()
        for action in actions:
            move(action)
        rates.append(steps / (time.perf_counter() - started))
    return rates[0], rates[1]


def coupled_steps(scenario: Scenario, steps: int) -> tuple[float, float]:
    runner = Runner(scenario, RandomStrategy(), seed=1)
    rates = []
    for _ in range(2):  # cold, then warm (same seed, same walk)
        runner.reset()
        step, world = runner.step, runner.world
        started = time.perf_counter()
        for _ in range(steps):
            step()
            world.current.distances  # noqa: B018 - the obstacle sensor, read every step
        rates.append(steps / (time.perf_counter() - started))
    return rates[0], rates[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000)
    args = parser.parse_args()
    print(f"{'scenario':<28} {'measure':<15} {'cold /s':>12} {'warm /s':>12}  target (warm)")
    for name in ("three-joint", "thesis-algo"):
        scenario = float_mode(name)
        cold, warm = world_moves(scenario, args.steps)
        print(
            f"{scenario.origin:<28} {'world moves':<15} {cold:>12,.0f} {warm:>12,.0f}  >= 200,000"
        )
        cold, warm = coupled_steps(scenario, args.steps)
        print(
            f"{scenario.origin:<28} {'coupled steps':<15} {cold:>12,.0f} {warm:>12,.0f}  >= 100,000"
        )


if __name__ == "__main__":
    main()
