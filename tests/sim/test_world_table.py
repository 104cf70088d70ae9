"""The world table's quick look at the feedback point: a scenario whose point no pose can
sense is named, with why; every built-in scenario's point can be sensed. A world too costly
to tabulate (many obstacles) is computed only where the arm goes."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from builtin_worlds import builtins_of
from rsstp_sim.arm.table import MAX_TABULATION_CHECKS, tabulation_checks, unsensable
from rsstp_sim.arm.world import World
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.truth import compute_truth
from scenarios import arm_toml
from waiting import HANG_S

ARM = arm_toml([2.0, 1.0], [0, 0], 30, [((0.0, 2.5), 0.5)])


@pytest.mark.parametrize("name", builtins_of("arm"))
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
        capture_output=True, text=True, timeout=HANG_S,
    )  # fmt: skip
    assert done.returncode == 0
    assert done.stderr.startswith("rsstp-sim: warning: no pose can sense the feedback point")
    assert len(done.stderr.splitlines()) == 1


# ------------------------------------------------------------------------ bounded work


def _many_obstacles(count: int) -> str:
    """Three joints (3, 2, 1) at 5 degrees among ``count`` small disks: half in a grid far
    off, half in an arc at 4.5 from the base over 0 to 240 degrees, which the arm (pointing
    at -30 degrees at the start) meets when it swings round."""
    far = [(40.0 + i % 40, 40.0 + i // 40) for i in range(count // 2)]
    n_arc = count - len(far)
    arc = [(4.5 * math.cos(a), 4.5 * math.sin(a)) for a in np.linspace(0, 4 * math.pi / 3, n_arc)]
    return arm_toml([3.0, 2.0, 1.0], [330, 3, 357], 5, [(centre, 0.2) for centre in far + arc])


def test_the_cost_of_a_whole_table_is_known_before_any_geometry() -> None:
    scenario = parse_scenario(_many_obstacles(1000))
    lattice = 72**3  # three joints at 5 degrees
    assert tabulation_checks(scenario) == lattice * 6 * 3 * 1000 == 6_718_464_000
    assert tabulation_checks(load_scenario("three-joint")) == lattice * 6 * 3 * 2


def test_a_world_too_costly_to_tabulate_grows_only_where_the_arm_goes() -> None:
    """1,000 obstacles on three joints: the whole table is 6.7 billion link-obstacle checks
    (blocks grown toward it took 114 s and 6.7 GB for 2,000 steps), so the world computes the
    moves the arm makes and the poses it reaches, nothing else, and keeps no row of 3,000
    distances: 2,000 steps in well under 20 s, a few hundred bytes a pose."""
    scenario = parse_scenario(_many_obstacles(1000))
    assert tabulation_checks(scenario) > MAX_TABULATION_CHECKS
    rng = np.random.default_rng(0)
    began = time.process_time()
    world = World(scenario)
    assert world.per_move
    path = [world.reset()]
    kinds = set()
    for action in rng.integers(0, 6, size=2000).tolist():
        blocker = world.move(action)
        kinds.add(None if blocker is None else blocker.kind)
        path.append(world.current)
    assert time.process_time() - began < 20
    table = world.table
    visited = {pose.code for pose in path}
    assert set(table.codes) == visited  # no pose the arm did not stand on
    assert table.moves_computed() <= len(visited)
    assert len(table.distances) == 0 and len(table.positions) == len(table) * 8
    # The answers are the geometry's, computed here from the angles and the disks.
    centres = np.array([o.center for o in scenario.obstacles])
    radii = np.array([o.radius for o in scenario.obstacles])
    lengths = np.array(scenario.lengths)
    for pose in path[:: len(path) // 40]:
        phi = np.radians(np.cumsum(pose.angles_deg))
        tips = np.cumsum(lengths[:, None] * np.stack([np.cos(phi), np.sin(phi)], 1), axis=0)
        expected = np.hypot(*(tips[:, None, :] - centres[None]).transpose(2, 0, 1)) - radii
        np.testing.assert_allclose(pose.distances, expected, rtol=0, atol=1e-9)
    assert "obstacle" in kinds  # the arc is met: the moves were tested, not only bounded


@pytest.mark.slow
def test_a_costly_world_runs_and_records_from_the_command_line(tmp_path: Path) -> None:
    from rsstp_cli.sim import main
    from rsstp_replay import open_recording

    toml = tmp_path / "many.toml"
    toml.write_text(_many_obstacles(1000))
    began = time.process_time()
    assert main(["run", str(toml), "--steps", "2000", "--quiet"]) == 0
    out = tmp_path / "many.mcap"
    assert main(["record", str(toml), "--steps", "300", "--quiet", "-o", str(out)]) == 0
    assert time.process_time() - began < 30
    with open_recording(out) as recording:
        steps = recording.steps()
    scenario = parse_scenario(toml.read_text())
    tip = steps[["joint3_x", "joint3_y"]].to_numpy()
    centre, radius = scenario.obstacles[-1].center, scenario.obstacles[-1].radius
    expected = np.hypot(tip[:, 0] - centre[0], tip[:, 1] - centre[1]) - radius
    np.testing.assert_allclose(steps["dist_2_999"], expected, rtol=0, atol=1e-9)
