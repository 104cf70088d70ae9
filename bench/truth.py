"""Time the ground truth (enumeration and minimisation) on two- and three-joint arms.

    PYTHONPATH=src python bench/truth.py

Scenarios (defined inline):

- ``bench-two-joint``: links (2, 1), 5-degree steps, one obstacle: 5,053 reachable poses;
- ``bench-three-joint``: links (3, 2, 1), 10-degree steps, two obstacles: 41,987 reachable poses.

Targets (2-core machine): about 5,000 poses <= 2 s, about 40,000 poses <= 20 s.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.scenario import parse_scenario  # noqa: E402
from rsstp_sim.truth import compute_truth  # noqa: E402
from scenarios import arm_toml  # noqa: E402 (the test suite's folder goes on the path first)

TWO_JOINT = arm_toml([2.0, 1.0], [0, 0], 5, [((0.0, 2.6), 0.2)], name="bench-two-joint")
THREE_JOINT = arm_toml(
    [3.0, 2.0, 1.0],
    [330, 3, 357],
    10,
    [((0.0, 4.5), 0.6), ((-4.5, -1.0), 0.5)],
    name="bench-three-joint",
)

CASES: list[tuple[str, float]] = [(TWO_JOINT, 2.0), (THREE_JOINT, 20.0)]


def run(scenario: Scenario, target_s: float) -> bool:
    truth = compute_truth(scenario)
    ok = truth.seconds <= target_s
    print(
        f"{scenario.name:18s} poses {truth.n_poses:>8,}  classes {truth.n_classes:>8,}  "
        f"sensed {truth.n_sensed:>3,}  {truth.seconds:7.2f} s  (target <= {target_s:g} s: "
        f"{'ok' if ok else 'SLOW'})"
    )
    return ok


def main() -> int:
    results = [run(parse_scenario(text), target) for text, target in CASES]
    return 0 if all(results) else 1


if __name__ == "__main__":
    raise SystemExit(main())
