"""The world: swept collision against shapely, the pose cache, reset, peek and bad actions."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, event, example, given, settings
from hypothesis import strategies as st

from conftest import THIN_OBSTACLE_TOML
from rsstp_sim.arm import geometry
from rsstp_sim.arm.geometry import Blocker
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.table import WorldTable
from rsstp_sim.arm.world import World
from rsstp_sim.errors import ActionError
from rsstp_sim.scenario import load_scenario, parse_scenario
from scenarios import arm_toml

SAMPLE_DEG = 0.25
"""Angular spacing of the intermediate poses checked along a move."""


# -- an independent reference: float kinematics and shapely ------------------------------------


def reference_positions(angles_deg: np.ndarray, lengths: tuple[float, ...]) -> np.ndarray:
    """Positions ``(S, n + 1, 2)`` of poses with float angles, by plain trigonometry."""
    phi = np.deg2rad(np.cumsum(angles_deg, axis=1))
    steps = np.stack([np.cos(phi), np.sin(phi)], axis=-1) * np.asarray(lengths)[:, None]
    return np.concatenate([np.zeros((len(angles_deg), 1, 2)), np.cumsum(steps, axis=1)], axis=1)


def link_segments(positions: np.ndarray, i: int) -> np.ndarray:
    """Link ``i`` of every pose as shapely LineStrings."""
    return shapely.linestrings(positions[:, i : i + 2])


def obstacle_gaps(scenario: Scenario, positions: np.ndarray) -> np.ndarray:
    """``(S, n, m)`` shapely distance from every link to every obstacle's surface."""
    gaps = np.empty((len(positions), scenario.n_joints, len(scenario.obstacles)))
    for i in range(scenario.n_joints):
        segments = link_segments(positions, i)
        for j, obstacle in enumerate(scenario.obstacles):
            gaps[:, i, j] = shapely.distance(segments, shapely.Point(obstacle.center))
            gaps[:, i, j] -= obstacle.radius
    return gaps


def link_gaps(scenario: Scenario, positions: np.ndarray) -> dict[tuple[int, int], np.ndarray]:
    """Shapely distance between every pair of non-adjacent links, per pose."""
    n = scenario.n_joints
    return {
        (i, j): shapely.distance(link_segments(positions, i), link_segments(positions, j))
        for i in range(n)
        for j in range(i + 2, n)
    }


def path(scenario: Scenario, start: tuple[int, ...], action: int) -> np.ndarray:
    """Poses ``(S, n)`` along a move, every :data:`SAMPLE_DEG` degrees, both ends included."""
    joint = action // 2
    delta = scenario.step_deg if action % 2 == 0 else -scenario.step_deg
    offsets = np.linspace(0.0, delta, int(round(abs(delta) / SAMPLE_DEG)) + 1)
    poses = np.tile(np.asarray(start, dtype=np.float64), (len(offsets), 1))
    poses[:, joint] += offsets
    return poses


def end_pose(scenario: Scenario, start: tuple[int, ...], action: int) -> tuple[int, ...]:
    joint = action // 2
    delta = scenario.step_deg if action % 2 == 0 else -scenario.step_deg
    return tuple((v + delta) % 360 if k == joint else v for k, v in enumerate(start))


def folds(poses: np.ndarray) -> np.ndarray:
    """``(S, n - 1)``: joint ``k >= 1`` at a relative angle of exactly 180 degrees."""
    return np.asarray(poses[:, 1:] % 360 == 180.0)


def assert_free(scenario: Scenario, poses: np.ndarray) -> None:
    """No sampled pose has a link on an obstacle's disk, crossing links or a fold."""
    positions = reference_positions(poses, scenario.lengths)
    assert not (obstacle_gaps(scenario, positions) <= 0).any()
    for pair, gaps in link_gaps(scenario, positions).items():
        assert (gaps > 0).all(), pair
    assert not folds(poses).any()


def assert_blocked_by(scenario: Scenario, poses: np.ndarray, blocker: Blocker) -> None:
    """Some sampled pose really collides the way ``blocker`` says (up to the sampling error)."""
    # Between samples a point of the arm moves at most total_length * SAMPLE_DEG (in radians).
    slack = scenario.total_length * math.radians(SAMPLE_DEG) / 2 + 1e-9 * scenario.total_length
    positions = reference_positions(poses, scenario.lengths)
    if blocker.kind == "obstacle":
        link, obstacle = blocker.indices
        assert obstacle_gaps(scenario, positions)[:, link, obstacle].min() <= slack
    elif blocker.kind == "links":
        assert link_gaps(scenario, positions)[blocker.indices].min() <= slack
    else:
        (joint,) = blocker.indices
        assert joint >= 1
        assert folds(poses)[:, joint - 1].any()


# -- random small scenarios ------------------------------------------------------------------


@st.composite
def small_scenarios(
    draw: st.DrawFn, collision: str | None = None, links: int | None = None, obstacles: int = 3
) -> Scenario:
    """1-3 links (or ``links``), up to ``obstacles`` disks near the arm, a valid start pose."""
    n = links or draw(st.integers(1, 3))
    lengths = [draw(st.floats(0.3, 2.5)) for _ in range(n)]
    initial = [draw(st.integers(0, 359))]
    initial += [draw(st.integers(0, 359).filter(lambda a: a != 180)) for _ in range(n - 1)]
    step = draw(st.sampled_from([1, 5, 10, 30, 45, 90, 135, 179]) | st.integers(1, 359))
    mode = collision or draw(st.sampled_from(["swept", "swept", "endpoint"]))
    reach = sum(lengths)
    positions = reference_positions(np.array([initial], dtype=np.float64), tuple(lengths))
    pairs = [(i, j) for i in range(n) for j in range(i + 2, n)]
    start_links = [shapely.LineString(positions[0, i : i + 2]) for i in range(n)]
    assume(all(start_links[i].distance(start_links[j]) > 1e-6 for i, j in pairs))
    disks = []
    for _ in range(draw(st.integers(0, obstacles))):
        center = (draw(st.floats(-reach, reach)), draw(st.floats(-reach, reach)))
        radius = draw(st.floats(0.05, 1.0))
        # Keep only obstacles clear of the start pose (an invalid start is a scenario error).
        if min(s.distance(shapely.Point(center)) for s in start_links) > radius + 1e-6:
            disks.append(
                f"[[obstacles]]\ncenter = [{center[0]!r}, {center[1]!r}]\nradius = {radius!r}\n"
            )
    text = (
        f"[arm]\nlengths = {lengths!r}\ninitial_deg = {initial!r}\nstep_deg = {step}\n"
        + "".join(disks)
        + f'[motion]\ncollision = "{mode}"\n'
    )
    return parse_scenario(text, origin="hypothesis.toml")


def walks(scenario: Scenario) -> st.SearchStrategy[list[int]]:
    return st.lists(st.sampled_from(scenario.actions), min_size=1, max_size=20)


def check_walk(data: st.DataObject, collision: str) -> None:
    """A random walk in a random small scenario of ``collision`` mode, each move checked
    against shapely on the poses that mode checks (the whole swept path, or the end pose
    alone): a free move ends at its end pose, a blocked one stays where it was and its blocker
    is real there; every reached pose is valid."""
    scenario = data.draw(small_scenarios(collision=collision), label="scenario")
    world = World(scenario, per_move=False)
    alone = World(scenario, per_move=True)  # each move checked on its own, in plain floats
    for action in data.draw(walks(scenario), label="actions"):
        assert alone.move(action) == world.peek(action)[1]
        start = world.angles_deg
        end = end_pose(scenario, start, action)
        if collision == "swept":
            poses = path(scenario, start, action)
        else:
            poses = np.array([end], dtype=np.float64)
        blocker = world.move(action)
        assert world.last_blocker == blocker
        if blocker is None:
            assert world.angles_deg == end
            assert_free(scenario, poses)
        else:
            event(f"blocked: {blocker.kind}")
            assert world.angles_deg == start
            assert_blocked_by(scenario, poses, blocker)
        assert_free(scenario, np.array([world.angles_deg], dtype=np.float64))
        assert alone.current.feedback == world.current.feedback
        assert alone.current.sensation == world.current.sensation
        assert np.array_equal(alone.joint_positions, world.joint_positions)


@pytest.mark.slow
@settings(max_examples=150, deadline=None)
@given(st.data())
def test_swept_moves_against_shapely(data: st.DataObject) -> None:
    """Every reached pose is valid; free moves are free all along; blockers are real."""
    check_walk(data, "swept")


FIXED_END_ON_MOVING_LINK = """
[arm]
lengths = [1.3, 1.3, 0.6]
initial_deg = [0, 170, 20]
step_deg = 90
"""
"""Joint 2 turning +90 sweeps link 2's middle across the base, the end of link 0."""


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(small_scenarios(collision="swept", links=3, obstacles=0))
@example(parse_scenario(FIXED_END_ON_MOVING_LINK))
def test_swept_link_contacts_against_shapely(scenario: Scenario) -> None:
    """Every move of three links from a random pose: links meet however they touch first."""
    world = World(scenario, per_move=False)
    alone = World(scenario, per_move=True)
    start = world.angles_deg
    for action in scenario.actions:
        pose, blocker = world.peek(action)
        assert alone.peek(action)[1] == blocker
        poses = path(scenario, start, action)
        if blocker is None:
            assert pose.angles_deg == end_pose(scenario, start, action)
            assert_free(scenario, poses)
        else:
            assert pose.angles_deg == start
            assert_blocked_by(scenario, poses, blocker)


def test_fixed_link_end_meeting_the_moving_link_blocks() -> None:
    world = World(parse_scenario(FIXED_END_ON_MOVING_LINK))
    assert world.move(4) == Blocker("links", (0, 2))
    assert world.angles_deg == (0, 170, 20)


@pytest.mark.parametrize("mode", ["swept", "endpoint"])
def test_touching_counts_as_meeting(mode: str) -> None:
    # One link of length 2 turning from 0 to 90 degrees ends with its tip (0, 2) exactly on
    # the circle of the disk at (0, 3) of radius 1; a radius a hair smaller lets it through.
    def disk_above(radius: float) -> str:
        return arm_toml([2.0], [0], 90, [((0.0, 3.0), radius)], motion={"collision": mode})

    touching = World(parse_scenario(disk_above(1.0)))
    assert touching.move(0) == Blocker("obstacle", (0, 0))
    clear = World(parse_scenario(disk_above(0.999)))
    assert clear.move(0) is None
    # Four links: turning the last one down puts its tip exactly on link 0, at (1, 0).
    four = World(
        parse_scenario(
            f"[arm]\nlengths = [2.0, 1.0, 1.0, 1.0]\ninitial_deg = [0, 90, 90, 0]\n"
            f'step_deg = 90\n[motion]\ncollision = "{mode}"\n'
        )
    )
    assert four.move(6) == Blocker("links", (0, 3))


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_endpoint_moves_against_shapely(data: st.DataObject) -> None:
    """In endpoint mode only the end pose counts, and every blocker is real there."""
    check_walk(data, "endpoint")


@pytest.mark.slow
@settings(max_examples=40, deadline=None)
@given(small_scenarios(collision="swept"))
def test_swept_blocks_at_least_what_endpoint_blocks(scenario: Scenario) -> None:
    """Swept mode checks the end pose too: a move free when swept is free at its end."""
    swept = World(scenario)
    endpoint = World(dataclasses.replace(scenario, collision="endpoint"))
    for action in scenario.actions:
        _, swept_blocker = swept.peek(action)
        _, endpoint_blocker = endpoint.peek(action)
        if swept_blocker is None:
            assert endpoint_blocker is None


def test_large_step_cannot_jump_over_a_thin_obstacle_unless_endpoint() -> None:
    text = THIN_OBSTACLE_TOML
    swept = World(parse_scenario(text.format(mode="swept")))
    assert swept.move(0) == Blocker("obstacle", (0, 0))
    assert swept.angles_deg == (0,)
    endpoint = World(parse_scenario(text.format(mode="endpoint")))
    assert endpoint.move(0) is None
    assert endpoint.angles_deg == (90,)


# -- the cache ----------------------------------------------------------------------------------


@pytest.mark.slow
@settings(max_examples=50, deadline=None)
@given(st.data())
def test_cached_answers_equal_a_fresh_computation(data: st.DataObject) -> None:
    scenario = data.draw(small_scenarios(), label="scenario")
    world = World(scenario, per_move=data.draw(st.booleans(), label="per_move"))
    visited = {world.pose_code}
    for action in data.draw(walks(scenario), label="actions"):
        world.move(action)
        visited.add(world.pose_code)
    geo = world.geometry
    tolerance = scenario.tolerance * scenario.total_length
    for code in sorted(visited):
        pose = world.pose(code)
        angles = pose.angles_deg
        assert pose.code == code
        # The pose's own data, computed for this pose alone.
        positions = geometry.joint_positions(angles, scenario.lengths)
        assert np.array_equal(pose.joint_positions, positions)
        sensed, closeness = geometry.feedback(
            positions[1:], scenario.feedback_points, scenario.lengths, tolerance
        )
        assert pose.sensation == bool(sensed)
        assert pose.feedback == float(closeness)
        distances = geometry.obstacle_distances(positions[1:], geo.centers, geo.radii)
        assert np.array_equal(pose.distances, distances)
        # Its moves, one geometry call per action, and from a brand-new world started there.
        fresh = World(dataclasses.replace(scenario, initial_deg=angles))
        for action in scenario.actions:
            joint, delta = action // 2, scenario.step_deg * (1 if action % 2 == 0 else -1)
            code_alone = int(geometry.move_blockers(geo, [angles], [joint], [delta])[0])
            expected = angles if code_alone else end_pose(scenario, angles, action)
            table, row = world.table, world.table.row_of(code)
            at = row * len(scenario.actions) + scenario.actions.index(action)
            if table.next_row[at] < 0:  # a move the walk did not make
                table.step(row, scenario.actions.index(action))
            target = table.codes[table.next_row[at]]
            blocker = geo.decode(table.blocker[at])
            assert blocker == geo.decode(code_alone)
            assert world.pose(target).angles_deg == expected
            fresh_pose, fresh_blocker = fresh.peek(action)
            assert fresh_blocker == blocker
            assert fresh_pose.angles_deg == expected
            assert fresh_pose.feedback == world.pose(target).feedback


def test_seven_links_keep_exact_poses(scenario_text) -> None:
    # The most links a scenario may have: pose codes of large angles must not overflow.
    angles = [359, 10, 10, 10, 10, 10, 359]
    arm = {"lengths": [1.0] * 7, "initial_deg": angles, "step_deg": 1, "actions": [12, 13]}
    world = World(parse_scenario(scenario_text({"arm": arm})))
    assert world.angles_deg == tuple(angles)
    assert world.move(13) is None
    assert world.angles_deg == (*angles[:6], 358)
    world.reset()
    assert world.angles_deg == tuple(angles)


@pytest.mark.slow
def test_a_small_pose_space_grows_in_doubling_blocks() -> None:
    world = World(load_scenario("three-joint"))
    assert world.cache_info() == (1, 0)  # the start pose, no moves computed yet
    world.move(0)
    poses, moves = world.cache_info()
    assert moves == 256  # the first block, breadth first around the start
    world.move(1)
    assert world.cache_info() == (poses, moves)  # back at the start: nothing new
    rng = np.random.default_rng(0)
    for action in rng.integers(0, 6, size=200_000).tolist():
        world.move(action)
    poses, moves = world.cache_info()
    assert 39_000 < moves <= poses <= 39_232  # reachable poses only, nearly all of them
    world.table.complete()
    assert world.cache_info() == (39_232, 39_232)


def test_a_large_pose_space_grows_with_the_walk(scenario_text) -> None:
    """Seven links at 5 degrees (72**7 lattice poses): the table grows move by move and holds
    the poses the walk stood on, no other."""
    arm = {"lengths": [1.0] * 7, "initial_deg": [0, 30, 30, 30, 30, 30, 30], "step_deg": 5}
    world = World(parse_scenario(scenario_text({"arm": arm})))
    assert world.per_move
    assert world.cache_info() == (1, 0)
    rng = np.random.default_rng(3)
    visited, moves = {world.pose_code}, set()
    for action in rng.integers(0, 14, size=200).tolist():
        moves.add((world.pose_code, action))
        world.move(action)
        visited.add(world.pose_code)
    assert len(visited) > 150  # the walk keeps finding new poses
    table = world.table
    assert sorted(table.codes) == sorted(visited)
    assert np.count_nonzero(table.next_array() >= 0) == len(moves)  # the moves made, no other
    assert len(table.positions) == len(visited) * table.width


def test_a_table_grown_move_by_move_completes_to_the_whole_table() -> None:
    """Moves computed one at a time, then the rest in blocks: the same reachable poses and
    moves as a table computed whole."""
    scenario = load_scenario("two-joint-30")
    world = World(scenario, per_move=True)
    rng = np.random.default_rng(5)
    for action in rng.choice(scenario.actions, size=300).tolist():
        world.move(action)
    grown, whole = world.table, WorldTable(scenario)
    computed = grown.next_array() >= 0
    assert (computed.any(axis=1) & ~computed.all(axis=1)).any()  # poses with some moves known
    grown.complete()
    whole.complete()

    def moves(table: WorldTable) -> dict[tuple[int, int], tuple[int, int]]:
        codes = np.frombuffer(table.codes, dtype=np.int64)
        targets = codes[table.next_array()]
        return {
            (int(code), k): (int(targets[row, k]), int(table.blocker_array()[row, k]))
            for row, code in enumerate(codes.tolist())
            for k in range(table.n_actions)
        }

    assert (grown.next_array() >= 0).all()
    assert moves(grown) == moves(whole)


# -- reset, peek, actions -----------------------------------------------------------------------


def test_moves_follow_the_action_convention() -> None:
    world = World(load_scenario("three-joint"))  # 330, 3, 357; step 5
    expected = {
        0: ((335, 3, 357), None),
        # Turning the base clockwise swings link 0 into the obstacle at (1.5, -1.5).
        1: ((330, 3, 357), Blocker("obstacle", (0, 1))),
        2: ((330, 8, 357), None),
        3: ((330, 358, 357), None),
        4: ((330, 3, 2), None),
        5: ((330, 3, 352), None),
    }
    for action, (angles, blocker) in expected.items():
        world.reset()
        assert world.move(action) == blocker
        assert world.angles_deg == angles


def test_reset_returns_to_the_start_pose() -> None:
    scenario = load_scenario("three-joint")
    world = World(scenario)
    start = world.current
    for action in (0, 0, 2, 5, 5):
        world.move(action)
    assert world.angles_deg != scenario.initial_deg
    pose = world.reset()
    assert pose is world.current
    assert world.angles_deg == scenario.initial_deg == (330, 3, 357)
    assert world.pose_code == start.code
    assert world.sensation is True
    assert world.feedback == 1.0
    assert world.last_blocker is None
    assert np.array_equal(world.joint_positions, start.joint_positions)


def test_peek_does_not_move() -> None:
    world = World(load_scenario("three-joint"))
    start = world.angles_deg
    pose, blocker = world.peek(2)
    assert blocker is None
    assert pose.angles_deg == (330, 8, 357)
    assert world.angles_deg == start
    assert world.last_blocker is None
    world.move(2)
    assert world.current is pose


def test_blocked_move_keeps_the_pose_and_reports_why() -> None:
    world = World(load_scenario("thesis-obstacles"))  # one link from 95 degrees, step 1
    blockers = []
    for _ in range(100):  # turn clockwise into the obstacle at (1, 2)
        blockers.append(world.move(1))
    assert blockers[0] is None
    stop = world.angles_deg
    assert blockers[-1] == Blocker("obstacle", (0, 0))
    assert world.last_blocker == blockers[-1]
    peeked, blocker = world.peek(1)
    assert blocker == Blocker("obstacle", (0, 0))
    assert peeked.angles_deg == stop
    assert world.move(0) is None  # backing off is free
    assert world.angles_deg == ((stop[0] + 1) % 360,)


def test_sensation_and_distances_of_the_current_pose() -> None:
    world = World(load_scenario("three-joint"))
    assert world.sensation is True and world.feedback == 1.0
    assert world.distances.shape == (3, 2)
    tips = world.joint_positions[1:]
    expected = np.hypot(*(tips[:, None, :] - np.array([[1.5, 1.0], [1.5, -1.5]])).T).T - 0.5
    np.testing.assert_allclose(world.distances, expected, rtol=0, atol=1e-12)
    world.move(0)
    assert world.sensation is False and 0.0 < world.feedback < 1.0


def test_roulette_cycles_through_four_poses() -> None:
    world = World(load_scenario("thesis-roulette"))
    seen = []
    for _ in range(4):
        assert world.move(0) is None
        seen.append((world.angles_deg, world.sensation))
    assert seen == [((90,), False), ((180,), False), ((270,), False), ((0,), True)]


@pytest.mark.parametrize("action", [1, 2, -1, 99])
def test_action_not_in_the_scenario(action: int) -> None:
    world = World(load_scenario("thesis-roulette"))  # actions: [0]
    message = rf"^action {action} is not one of the scenario's actions \[0\]$"
    with pytest.raises(ActionError, match=message):
        world.peek(action)
    with pytest.raises(ActionError, match=message):
        world.move(action)
    assert world.angles_deg == (0,)


def test_pose_data_is_read_only() -> None:
    world = World(load_scenario("three-joint"))
    with pytest.raises(ValueError, match="read-only"):
        world.joint_positions[1, 0] = 0.0
    with pytest.raises(ValueError, match="read-only"):
        world.distances[0, 0] = 0.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        world.current.sensation = False  # type: ignore[misc]


def test_a_bool_is_not_an_action() -> None:
    world = World(load_scenario("thesis-algo"))
    with pytest.raises(ActionError, match="action True is not one of the scenario's actions"):
        world.move(True)
    assert world.angles_deg == (95,)


def test_peek_refuses_what_move_refuses() -> None:
    world = World(load_scenario("thesis-algo"))
    for action in (True, 7):
        with pytest.raises(ActionError, match="is not one of the scenario's actions"):
            world.peek(action)
