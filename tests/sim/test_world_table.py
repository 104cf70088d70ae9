"""The world table's quick look at the feedback point: a scenario whose point no pose can
sense is named, with why; every built-in scenario's point can be sensed."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from rsstp_sim.scenario import builtin_scenarios, load_scenario, parse_scenario
from rsstp_sim.truth import compute_truth
from rsstp_sim.world_table import unsensable
from scenarios import arm_toml

ARM = arm_toml([2.0, 1.0], [0, 0], 30, [((0.0, 2.5), 0.5)])


@pytest.mark.parametrize("name", sorted(builtin_scenarios()))
def test_every_built_in_feedback_point_can_be_sensed(name: str) -> None:
    assert unsensable(load_scenario(name)) is None


@pytest.mark.parametrize(
    ("feedback", "why"),
    [
        ("target_deg = [90, 0]", r"the pose at the feedback point, \[90, 0\], is blocked: link"),
        ("target_deg = [15, 0]", r"the target pose \[15, 0\] is not on the arm's lattice"),
        ("points = [[2.0, 0.0], [5.0, 0.0]]", r"feedback point 1 is 2 from every place"),
        (
            "points = [[1.93185, 0.51764], [2.89778, 0.77646]]\ntolerance = 0.001",
            r"no pose on the arm.s 30-degree lattice",
        ),
    ],
)
def test_a_point_no_pose_can_sense_is_named(feedback: str, why: str) -> None:
    scenario = parse_scenario(ARM + f"[feedback]\n{feedback}\n")
    problem = unsensable(scenario)
    assert problem is not None
    assert re.search(why, problem), problem
    if "target_deg = [90" in feedback:  # the truth agrees: nothing reachable senses it
        assert not compute_truth(scenario).sensation.any()


def test_run_warns_in_one_line(tmp_path: Path) -> None:
    scenario = tmp_path / "blind.toml"
    scenario.write_text(ARM + "[feedback]\ntarget_deg = [90, 0]\n")
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "run", str(scenario), "--steps", "10"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 0
    assert done.stderr.startswith("rsstp-sim: warning: no pose can sense the feedback point")
    assert len(done.stderr.splitlines()) == 1
