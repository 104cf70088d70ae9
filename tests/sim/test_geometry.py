"""Geometry: kinematics, distances against shapely, the exact arc distance, feedback, blockers."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point

from conftest import THIN_OBSTACLE_TOML
from rsstp_sim.arm import geometry
from rsstp_sim.arm.geometry import ArmGeometry, Blocker
from rsstp_sim.arrays import IntArray
from rsstp_sim.scenario import parse_scenario
from scenarios import arm_toml

SQRT3_2 = math.sqrt(3.0) / 2.0
COS_27, SIN_27 = 0.8910065241883679, 0.45399049973954675  # cos and sin of 27 degrees

coordinate = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False, allow_subnormal=False)
point = st.tuples(coordinate, coordinate)


# -- kinematics -------------------------------------------------------------------------------


def test_three_joint_start_pose_by_hand() -> None:
    # phi = 330, 333, 330 (330 + 3 + 357 = 690 = 330 mod 360); lengths 3, 2, 1.
    p1 = (3 * SQRT3_2, -1.5)
    p2 = (p1[0] + 2 * COS_27, p1[1] - 2 * SIN_27)
    p3 = (p2[0] + SQRT3_2, p2[1] - 0.5)
    positions = geometry.joint_positions([330, 3, 357], [3.0, 2.0, 1.0])
    assert positions.shape == (4, 2)
    assert positions.dtype == np.float64
    assert positions[0].tolist() == [0.0, 0.0]
    np.testing.assert_allclose(positions[1:], [p1, p2, p3], rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    ("angles", "lengths", "expected"),
    [
        ([0], [2.0], [[2.0, 0.0]]),
        ([90], [2.0], [[0.0, 2.0]]),
        ([180], [2.0], [[-2.0, 0.0]]),
        ([270], [2.0], [[0.0, -2.0]]),
        ([90, 90], [1.0, 1.0], [[0.0, 1.0], [-1.0, 1.0]]),
        ([270, 180, 270], [1.0, 2.0, 3.0], [[0.0, -1.0], [0.0, 1.0], [3.0, 1.0]]),
    ],
)
def test_positions_on_the_axes_are_exact(
    angles: list[int], lengths: list[float], expected: list[list[float]]
) -> None:
    # Exact, not approximately equal: 90 degrees gives x == 0.0, not 1.2e-16.
    assert geometry.joint_positions(angles, lengths)[1:].tolist() == expected


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 359), st.floats(0.1, 5.0)), min_size=1, max_size=4),
    st.integers(1, 5),
)
def test_kinematics_against_float_trigonometry(joints: list[tuple[int, float]], batch: int) -> None:
    angles = np.array([a for a, _ in joints])
    lengths = np.array([length for _, length in joints])
    phi = np.deg2rad(np.cumsum(angles))
    expected = np.cumsum(lengths[:, None] * np.stack([np.cos(phi), np.sin(phi)], axis=1), axis=0)
    positions = geometry.joint_positions(angles, lengths)
    np.testing.assert_allclose(positions[1:], expected, rtol=0, atol=1e-12)
    # Every link keeps its length.
    link_lengths = np.hypot(*np.diff(positions, axis=0).T)
    np.testing.assert_allclose(link_lengths, lengths, rtol=1e-12)
    # A batch gives the same rows as one pose at a time.
    rows = np.stack([(angles + 37 * i) % 360 for i in range(batch)])
    batched = geometry.joint_positions(rows, lengths)
    assert batched.shape == (batch, len(joints) + 1, 2)
    for row, got in zip(rows, batched, strict=True):
        assert np.array_equal(got, geometry.joint_positions(row, lengths))


# -- distances --------------------------------------------------------------------------------


@settings(max_examples=100, deadline=None)
@given(point, point, point)
def test_point_segment_distance_matches_shapely(x, a, b) -> None:
    assume(a == b or math.dist(a, b) > 1e-6)  # shapely mishandles near-degenerate segments
    reference = Point(a).distance(Point(x)) if a == b else LineString([a, b]).distance(Point(x))
    assert geometry.point_segment_distance(x, a, b) == pytest.approx(reference, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(point, point, point, point)
def test_segment_distance_matches_shapely(a, b, c, d) -> None:
    assume(math.dist(a, b) > 1e-6 and math.dist(c, d) > 1e-6)
    # Shapely 2.0's GEOS can leave the floating-point "invalid" flag raised for nearly
    # collinear segments, which numpy reports as a RuntimeWarning; the distance is right.
    with np.errstate(invalid="ignore"):
        reference = LineString([a, b]).distance(LineString([c, d]))
    assert geometry.segment_distance(a, b, c, d) == pytest.approx(reference, abs=1e-9)


def test_segment_distance_of_nearly_collinear_segments() -> None:
    """The example that made shapely 2.0 warn (see above): the two segments share a point
    but for rounding, so their distance is that rounding."""
    a, b, c, d = (
        (0.0, -1.0),
        (-1.0, 0.0),
        (-1.0, 1.1102230246251565e-16),
        (-5.551115123125783e-17, -1.0),
    )
    assert geometry.segment_distance(a, b, c, d) == pytest.approx(0.0, abs=1e-15)


def test_segment_distance_is_zero_for_crossing_and_touching_segments() -> None:
    assert geometry.segment_distance([0, 0], [2, 2], [0, 2], [2, 0]) == 0.0  # crossing
    assert geometry.segment_distance([0, 0], [2, 0], [1, 0], [1, 3]) == 0.0  # T-junction
    assert geometry.segment_distance([0, 0], [2, 0], [1, 0], [3, 0]) == 0.0  # overlapping
    assert geometry.segment_distance([0, 0], [2, 0], [0, 1], [2, 1]) == 1.0  # parallel


def test_distances_broadcast_over_leading_axes() -> None:
    x = np.array([[0.0, 1.0], [3.0, 0.0], [-1.0, -1.0]])
    got = geometry.point_segment_distance(x, [0.0, 0.0], [2.0, 0.0])
    np.testing.assert_allclose(got, [1.0, 1.0, math.sqrt(2.0)])


def _sampled_arc_distance(
    pivot: np.ndarray, q: np.ndarray, delta: float, a: tuple, b: tuple, samples: int
) -> float:
    """Minimum shapely distance from the segment to ``samples`` points along the arc."""
    angles = np.linspace(0.0, delta, samples)
    v = q - pivot
    cos, sin = np.cos(angles), np.sin(angles)
    points = pivot + np.stack([v[0] * cos - v[1] * sin, v[0] * sin + v[1] * cos], axis=1)
    return float(shapely.distance(shapely.points(points), LineString([a, b])).min())


@settings(max_examples=100, deadline=None)
@given(point, point, st.integers(-359 * 8, 359 * 8), point, point)
def test_arc_segment_distance_matches_dense_sampling(pivot, q, delta_eighths, a, b) -> None:
    assume(math.dist(a, b) > 1e-3)
    delta = math.radians(delta_eighths / 8)  # signed, up to 359 degrees either way
    p, q_ = np.array(pivot), np.array(q)
    samples = 4001
    sampled = _sampled_arc_distance(p, q_, delta, a, b, samples)
    exact = float(geometry.arc_segment_distance(p, q_, delta, a, b))
    rho = float(np.hypot(*(q_ - p)))
    # The true minimum is within half a sample spacing (along the arc) of a sample.
    chord_error = rho * abs(delta) / (samples - 1) / 2
    assert exact <= sampled + 1e-9
    assert exact >= sampled - chord_error - 1e-9


def test_arc_segment_distance_sees_the_middle_of_the_arc() -> None:
    # A quarter turn of (2, 0) about the origin passes just outside a short segment near
    # (sqrt2, sqrt2), whose ends are the closest to the circle; the arc's ends are far.
    a, b = (1.3, 1.5), (1.5, 1.3)
    exact = float(geometry.arc_segment_distance([0, 0], [2, 0], math.pi / 2, a, b))
    ends = min(LineString([a, b]).distance(Point(2, 0)), LineString([a, b]).distance(Point(0, 2)))
    assert exact == pytest.approx(2.0 - math.hypot(*a), abs=1e-12)
    assert exact < 0.2 < ends
    # Turning the other way (-90 degrees) never comes near it.
    backwards = float(geometry.arc_segment_distance([0, 0], [2, 0], -math.pi / 2, a, b))
    assert backwards == pytest.approx(ends, abs=1e-12)


# -- feedback and obstacle distances ----------------------------------------------------------


def test_sensation_is_true_exactly_at_the_target_pose() -> None:
    lengths = [3.0, 2.0, 1.0]
    points = geometry.joint_positions([330, 3, 357], lengths)[1:]
    sensed, closeness = geometry.feedback(points, points, lengths, 1e-6 * 6.0)
    assert bool(sensed) is True
    assert float(closeness) == 1.0
    away = geometry.joint_positions([330, 3, 352], lengths)[1:]
    sensed, closeness = geometry.feedback(away, points, lengths, 1e-6 * 6.0)
    assert bool(sensed) is False
    assert 0.0 < float(closeness) < 1.0


def test_sensation_needs_every_tip_within_the_tolerance() -> None:
    points = np.array([[1.0, 0.0], [2.0, 0.0]])
    lengths = [1.0, 1.0]
    on_edge = points + [[0.0, 0.5], [0.5, 0.0]]
    assert bool(geometry.feedback(on_edge, points, lengths, 0.5)[0]) is True  # within: <=
    one_off = points + [[0.0, 0.0], [0.5000001, 0.0]]
    assert bool(geometry.feedback(one_off, points, lengths, 0.5)[0]) is False


def test_closeness_formula_by_hand() -> None:
    # Two links of length 1; tips at (0, 1) and (0, 2); points at (1, 0) and (2, 0).
    # Joint 0: 1 - sqrt(2) / (1 + 1); joint 1: 1 - sqrt(8) / (2 + 2).
    tips = [[0.0, 1.0], [0.0, 2.0]]
    points = [[1.0, 0.0], [2.0, 0.0]]
    _, closeness = geometry.feedback(tips, points, [1.0, 1.0], 1e-6)
    expected = ((1 - math.sqrt(2) / 2) + (1 - math.sqrt(8) / 4)) / 2
    assert float(closeness) == pytest.approx(expected, rel=1e-12)


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 359), st.floats(0.1, 5.0)), min_size=1, max_size=4),
    st.data(),
)
def test_closeness_is_in_unit_interval(joints, data) -> None:
    angles = [a for a, _ in joints]
    lengths = [length for _, length in joints]
    tips = geometry.joint_positions(angles, lengths)[1:]
    points = np.array(data.draw(st.lists(point, min_size=len(joints), max_size=len(joints))))
    sensed, closeness = geometry.feedback(tips, points, lengths, 1e-6)
    assert 0.0 <= float(closeness) <= 1.0
    if bool(sensed):
        assert float(closeness) > 0.999


def test_feedback_is_vectorised_over_poses() -> None:
    lengths = [1.0, 1.0]
    points = geometry.joint_positions([0, 90], lengths)[1:]
    tips = geometry.joint_positions([[0, 90], [10, 90], [0, 90]], lengths)[:, 1:]
    sensed, closeness = geometry.feedback(tips, points, lengths, 1e-6)
    assert sensed.tolist() == [True, False, True]
    assert closeness.shape == (3,)
    assert closeness[0] == closeness[2] == 1.0 > closeness[1]


def test_obstacle_distances_are_to_the_surface() -> None:
    tips = np.array([[3.0, 4.0], [0.0, 1.0]])
    centers = np.array([[0.0, 0.0], [0.0, 3.0]])
    radii = np.array([1.0, 0.5])
    got = geometry.obstacle_distances(tips, centers, radii)
    assert got.shape == (2, 2)
    expected = [[5.0 - 1.0, math.hypot(3.0, 1.0) - 0.5], [1.0 - 1.0, 2.0 - 0.5]]
    np.testing.assert_allclose(got, expected, rtol=1e-15)
    batched = geometry.obstacle_distances(np.stack([tips, tips + 1.0]), centers, radii)
    assert batched.shape == (2, 2, 2)
    np.testing.assert_array_equal(batched[0], got)


# -- blockers ---------------------------------------------------------------------------------


THREE_LINKS = arm_toml([2.0, 1.0, 2.0], [0, 90, 90], 30, [((5.0, 5.0), 0.5), ((0.5, -1.5), 0.5)])


def test_blocker_codes_decode_to_what_they_name() -> None:
    geo = ArmGeometry.from_scenario(parse_scenario(THREE_LINKS))
    assert (geo.n, geo.m) == (3, 2)
    assert geo.decode(0) is None
    assert geo.decode(1) == Blocker("fold", (1,))
    assert geo.decode(2) == Blocker("fold", (2,))
    assert geo.decode(3 + 0 * 2 + 1) == Blocker("obstacle", (0, 1))
    assert geo.decode(3 + 2 * 2 + 0) == Blocker("obstacle", (2, 0))
    assert geo.decode(3 + 6 + 0 * 3 + 2) == Blocker("links", (0, 2))


@pytest.mark.parametrize(
    ("pose", "blocker", "text"),
    [
        ([0, 90, 90], None, None),
        ([0, 180, 90], Blocker("fold", (1,)), "joint 1 would fold back onto link 0"),
        ([0, 90, 180], Blocker("fold", (2,)), "joint 2 would fold back onto link 1"),
        ([300, 10, 90], Blocker("obstacle", (0, 1)), "link 0 meets obstacle 1"),
        ([0, 120, 120], Blocker("links", (0, 2)), "links 0 and 2 intersect"),
    ],
)
def test_pose_blocker(pose: list[int], blocker: Blocker | None, text: str | None) -> None:
    scenario = parse_scenario(THREE_LINKS)
    got = geometry.pose_blocker(scenario, pose)
    assert got == blocker
    if got is not None:
        assert got.describe() == text


def test_pose_blockers_batch_matches_single_poses() -> None:
    scenario = parse_scenario(THREE_LINKS)
    geo = ArmGeometry.from_scenario(scenario)
    rng = np.random.default_rng(0)
    poses = rng.integers(0, 360, size=(200, 3))
    codes = geometry.pose_blockers(geo, poses)
    assert {geo.decode(int(c)).kind for c in codes if c} == {"fold", "obstacle", "links"}
    for pose, code in zip(poses.tolist(), codes.tolist(), strict=True):
        assert geometry.pose_blocker(scenario, pose) == geo.decode(code)


def test_move_blockers_swept_and_endpoint() -> None:
    # One link of length 2 at 0 degrees; a small disk on the diagonal at distance 1.98.
    text = THIN_OBSTACLE_TOML
    swept = ArmGeometry.from_scenario(parse_scenario(text.format(mode="swept")))
    endpoint = ArmGeometry.from_scenario(parse_scenario(text.format(mode="endpoint")))
    poses, joints, deltas = [[0], [0], [90]], [0, 0, 0], [90, -90, 90]
    assert geometry.move_blockers(swept, poses, joints, deltas).tolist() == [1, 0, 0]
    assert swept.decode(1) == Blocker("obstacle", (0, 0))
    assert geometry.move_blockers(endpoint, poses, joints, deltas).tolist() == [0, 0, 0]


def test_move_blockers_fold_only_for_joints_after_the_first() -> None:
    geo = ArmGeometry.from_scenario(
        parse_scenario("[arm]\nlengths = [1.0, 1.0]\ninitial_deg = [170, 170]\nstep_deg = 20\n")
    )
    # Joint 0 passes 180 freely; joint 1 turning +20 from 170 passes 180 (fold), -20 does not.
    got = geometry.move_blockers(geo, [[170, 170]] * 3, [0, 1, 1], [20, 20, -20])
    assert [geo.decode(c) for c in got.tolist()] == [None, Blocker("fold", (1,)), None]


# -- one pose, one move, in plain floats -------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(st.integers(0, 359), st.floats(0.1, 5.0)), min_size=1, max_size=7),
    st.integers(0, 6),
)
def test_pose_points_equal_joint_positions_bit_for_bit(
    joints: list[tuple[int, float]], first: int
) -> None:
    angles = [a for a, _ in joints]
    lengths = [length for _, length in joints]
    expected = geometry.joint_positions(angles, lengths).ravel().tolist()
    assert geometry.pose_points(angles, lengths) == expected
    # From the points of a pose that differs in the joints from ``first`` on.
    first = min(first, len(angles) - 1)
    other = angles[:first] + [(a + 90) % 360 for a in angles[first:]]
    known = geometry.pose_points(other, lengths)
    assert geometry.pose_points(angles, lengths, known=known, first=first) == expected


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(point, st.floats(0.1, 5.0)), min_size=1, max_size=7),
    st.lists(point, min_size=7, max_size=7),
)
def test_pose_feedback_equals_feedback_bit_for_bit(
    joints: list[tuple[tuple[float, float], float]], points: list[tuple[float, float]]
) -> None:
    tips = np.array([tip for tip, _ in joints])
    lengths = [length for _, length in joints]
    feedback_points = np.array(points[: len(joints)])
    flat = [0.0, 0.0, *tips.ravel().tolist()]
    reach = geometry.feedback_reach(feedback_points, lengths).tolist()
    for tolerance in (0.5, 3.0, 30.0):
        sensed, closeness = geometry.feedback(tips, feedback_points, lengths, tolerance)
        got = geometry.pose_feedback(flat, feedback_points.ravel(), reach, tolerance)
        assert got == (bool(sensed), float(closeness))


def _crowded_arm(n: int, mode: str) -> ArmGeometry:
    """``n`` unit links and two disks in their reach: many moves pass near a contact."""
    disks = [((1.5, 1.0), 0.5), ((1.5, -1.5), 0.5), ((-1.0, 0.5), 0.3)]
    toml = arm_toml([1.0] * n, [0] + [30] * (n - 1), 5, disks, motion={"collision": mode})
    return ArmGeometry.from_scenario(parse_scenario(toml))


@pytest.mark.parametrize("mode", ["swept", "endpoint"])
@pytest.mark.parametrize("n", [2, 4, 7])
def test_move_blocker_equals_move_blockers(mode: str, n: int) -> None:
    """One move in plain floats gives the vectorised batch's blocker, over valid random poses
    of a crowded arm and turns small and large (a twentieth or more of them blocked)."""
    geo = _crowded_arm(n, mode)
    rng = np.random.default_rng(n)
    poses = rng.integers(0, 360, size=(6000, n))
    poses = poses[geometry.pose_blockers(geo, poses) == 0][:1500]
    joints = rng.integers(0, n, size=len(poses))
    deltas = rng.choice([1, -1, 5, -5, 30, -30, 90, -135], size=len(poses))
    expected = geometry.move_blockers(geo, poses, joints, deltas).tolist()
    got = [
        geometry.move_blocker(geo, pose, geometry.pose_points(pose, geo.link_lengths), j, d)
        for pose, j, d in zip(poses.tolist(), joints.tolist(), deltas.tolist(), strict=True)
    ]
    assert got == expected
    assert sum(map(bool, expected)) > len(expected) // 20


@pytest.mark.parametrize("mode", ["swept", "endpoint"])
def test_move_blocker_leaves_a_contact_at_the_threshold_to_numpy(
    mode: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A link of length 2 turning 90 degrees ends with its tip at distance 1 from the centre
    # of a disk of radius 1 - eps: exactly the contact threshold (radius + eps), up to a
    # rounding that plain floats cannot settle against numpy's.
    eps = geometry.CONTACT_EPS * 2.0
    disk = [((0.0, 3.0), 1.0 - eps)]
    geo = ArmGeometry.from_scenario(
        parse_scenario(arm_toml([2.0], [0], 90, disk, motion={"collision": mode}))
    )
    batches: list[tuple[object, ...]] = []
    vectorised = geometry.move_blockers

    def counted(*args: Any) -> IntArray:
        batches.append(args)
        return vectorised(*args)

    monkeypatch.setattr(geometry, "move_blockers", counted)
    points = geometry.pose_points([0], geo.link_lengths)
    expected = int(vectorised(geo, [[0]], [0], [90])[0])
    assert geometry.move_blocker(geo, [0], points, 0, 90) == expected
    assert len(batches) == 1  # numpy decided
    batches.clear()
    assert geometry.move_blocker(geo, [0], points, 0, -90) == 0  # far from the disk
    assert batches == []  # plain floats decided
