"""Time the ground truth (enumeration and minimisation) on two- and three-joint arms.

    PYTHONPATH=src python bench/truth.py

Scenarios (defined inline):

- ``bench-two-joint``: links (2, 1), 5-degree steps, one obstacle: 5,053 reachable poses;
- ``bench-three-joint``: links (3, 2, 1), 10-degree steps, two obstacles: 41,987 reachable poses.

Targets (2-core machine): about 5,000 poses <= 2 s, about 40,000 poses <= 20 s.
"""

from __future__ import annotations

from rsstp_sim.scenario import Scenario, parse_scenario
from rsstp_sim.truth import compute_truth

TWO_JOINT = """
name = "bench-two-joint"
[arm]
lengths = [2.0, 1.0]
initial_deg = [0, 0]
step_deg = 5
[[obstacles]]
center = [0.0, 2.6]
radius = 0.2
"""

THREE_JOINT = """
name = "bench-three-joint"
[arm]
lengths = [3.0, 2.0, 1.0]
initial_deg = [330, 3, 357]
step_deg = 10
[[obstacles]]
center = [0.0, 4.5]
radius = 0.6
[[obstacles]]
center = [-4.5, -1.0]
radius = 0.5
"""

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
