"""Pure numpy geometry of the arm: kinematics, blocked moves, feedback, distances.

Everything here is vectorised over a batch of poses so that the world (one
pose at a time, cached) and the ground-truth enumeration (whole frontiers at
once) share one implementation. A world too large to tabulate in blocks asks
one move at a time: :func:`pose_points`, :func:`pose_feedback` and
:func:`move_blocker` give the same answers, bit for bit, in plain Python floats
(a numpy call costs more than a whole move's arithmetic), and
:func:`move_blocker` leaves to :func:`move_blockers` every contact too near its
threshold to be settled without numpy's own rounding.

Conventions (``docs/world.md``): joint angles are integer
degrees in ``[0, 360)``; angle ``i`` is relative to link ``i-1`` (the first to
the +x axis); the base is at the origin; coordinates are float64. Positions
arrays have ``n + 1`` rows: the base, then the tip of every link.

Swept collision is exact: turning joint ``k`` rotates links ``k..n-1`` rigidly
about joint ``k``. A moving link meets a disk during the turn exactly when the
disk's centre, turned the opposite way, comes within the radius of the link's
start position: the minimum distance between an *arc* and a *segment*. Two
segments that start apart first touch with an endpoint of one on the other,
so moving-versus-fixed link contacts reduce to the same arc-segment test.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rsstp_format.vocabulary import BlockerKind
from rsstp_sim.arrays import FloatArray, IntArray

__all__ = [
    "ARM_BLOCKER_KINDS",
    "ArmGeometry",
    "Blocker",
    "COS_DEG",
    "SIN_DEG",
    "arc_segment_distance",
    "feedback",
    "feedback_reach",
    "joint_positions",
    "move_blocker",
    "move_blockers",
    "obstacle_distances",
    "point_segment_distance",
    "pose_points",
    "pose_blocker",
    "pose_blockers",
    "pose_feedback",
    "segment_distance",
]


def _trig_tables() -> tuple[FloatArray, FloatArray]:
    # libm (math) rather than numpy's SIMD kernels: the same table on every CPU,
    # so recordings are byte-identical across machines.
    radians = [math.radians(d) for d in range(360)]
    cos = np.array([math.cos(r) for r in radians], dtype=np.float64)
    sin = np.array([math.sin(r) for r in radians], dtype=np.float64)
    # Exact values where they exist, so poses on the axes compare exactly.
    cos[[90, 270]] = 0.0
    sin[[0, 180]] = 0.0
    cos[180], sin[270] = -1.0, -1.0
    cos.flags.writeable = False
    sin.flags.writeable = False
    return cos, sin


COS_DEG, SIN_DEG = _trig_tables()
"""Cosine and sine of every integer degree 0..359 (exact on the axes)."""
_COS_LIST: list[float] = COS_DEG.tolist()
_SIN_LIST: list[float] = SIN_DEG.tolist()

_TWO_PI = 2.0 * np.pi
_ANGLE_SLACK = 1e-12
CONTACT_EPS = 1e-9
"""Contacts closer than this fraction of the total arm length count as touching."""


def joint_positions(angles_deg: ArrayLike, lengths: ArrayLike) -> FloatArray:
    """Positions of the base and of every link tip, shape ``(..., n + 1, 2)``.

    ``p_k = sum_{i<=k} L_i (cos phi_i, sin phi_i)`` with ``phi_i = sum_{j<=i} theta_j``.
    """
    theta = np.asarray(angles_deg, dtype=np.int64)
    lengths_arr = np.asarray(lengths, dtype=np.float64)
    phi = np.cumsum(theta, axis=-1) % 360
    steps = np.stack([COS_DEG[phi], SIN_DEG[phi]], axis=-1) * lengths_arr[:, None]
    zeros = np.zeros((*theta.shape[:-1], 1, 2), dtype=np.float64)
    return np.concatenate([zeros, np.cumsum(steps, axis=-2)], axis=-2)


def pose_points(
    angles_deg: Sequence[int],
    lengths: Sequence[float],
    *,
    known: Sequence[float] = (),
    first: int = 0,
) -> list[float]:
    """:func:`joint_positions` of one pose in plain floats, ``[x0, y0, x1, y1, ...]``.

    Equal bit for bit to :func:`joint_positions` (the same products of the same table
    entries, summed in the same order), without numpy's per-call cost: the world's
    per-move path computes a new pose with it. ``known``: the points of a pose whose links
    before ``first`` are this pose's (a move of joint ``first``), kept as they are.
    """
    cos, sin = _COS_LIST, _SIN_LIST
    points = list(known[: 2 * first + 2]) if first else [0.0, 0.0]
    phi = sum(angles_deg[:first]) % 360
    x, y = points[-2], points[-1]
    for k in range(first, len(lengths)):
        phi = (phi + angles_deg[k]) % 360
        length = lengths[k]
        dx, dy = cos[phi] * length, sin[phi] * length
        if k:
            x, y = x + dx, y + dy
        else:  # numpy's cumsum starts from the first term itself, not from 0.0 + it
            x, y = dx, dy
        points += (x, y)
    return points


def point_segment_distance(x: ArrayLike, a: ArrayLike, b: ArrayLike) -> FloatArray:
    """Distance from points ``x`` to segments ``a``-``b`` (broadcast over leading axes)."""
    x_, a_, b_ = (np.asarray(v, dtype=np.float64) for v in (x, a, b))
    ab = b_ - a_
    denom = np.einsum("...i,...i->...", ab, ab)
    t = np.einsum("...i,...i->...", x_ - a_, ab) / np.where(denom > 0, denom, 1.0)
    t = np.clip(t, 0.0, 1.0)
    foot = a_ + t[..., None] * ab
    return np.asarray(np.hypot(*np.moveaxis(x_ - foot, -1, 0)), dtype=np.float64)


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    return np.asarray(u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0], dtype=np.float64)


def segment_distance(a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike) -> FloatArray:
    """Distance between segments ``a``-``b`` and ``c``-``d``; 0 when they cross or touch."""
    a_, b_, c_, d_ = (np.asarray(v, dtype=np.float64) for v in (a, b, c, d))
    o1, o2 = _cross(b_ - a_, c_ - a_), _cross(b_ - a_, d_ - a_)
    o3, o4 = _cross(d_ - c_, a_ - c_), _cross(d_ - c_, b_ - c_)
    crossing = (o1 * o2 < 0) & (o3 * o4 < 0)
    ends = np.minimum(
        np.minimum(point_segment_distance(a_, c_, d_), point_segment_distance(b_, c_, d_)),
        np.minimum(point_segment_distance(c_, a_, b_), point_segment_distance(d_, a_, b_)),
    )
    return np.where(crossing, 0.0, ends)


def _in_arc(direction: FloatArray, start: FloatArray, delta: FloatArray) -> NDArray[np.bool_]:
    """Whether angles ``direction`` lie on the arc from ``start`` turning by signed ``delta``."""
    rel = np.where(delta >= 0, direction - start, start - direction) % _TWO_PI
    return np.asarray(rel <= np.abs(delta) + _ANGLE_SLACK)


def arc_segment_distance(
    pivot: ArrayLike, point: ArrayLike, delta_rad: ArrayLike, a: ArrayLike, b: ArrayLike
) -> FloatArray:
    """Minimum distance between segment ``a``-``b`` and the arc that ``point`` traces
    when turned about ``pivot`` by every angle between 0 and ``delta_rad`` (signed, CCW > 0).

    Exact: the minimum is attained at an arc end, a segment end, a crossing of
    the segment's line with the circle, or a point of the circle whose normal is
    the line's normal; every candidate inside the arc is measured.
    """
    p, q, a_, b_ = (np.asarray(v, dtype=np.float64) for v in (pivot, point, a, b))
    delta = np.asarray(delta_rad, dtype=np.float64)
    p, q, a_, b_ = np.broadcast_arrays(p, q, a_, b_)
    delta = np.broadcast_to(delta, p.shape[:-1])

    v = q - p
    rho = np.hypot(v[..., 0], v[..., 1])
    start = np.arctan2(v[..., 1], v[..., 0])
    cos_d, sin_d = np.cos(delta), np.sin(delta)
    q_end = p + np.stack(
        [v[..., 0] * cos_d - v[..., 1] * sin_d, v[..., 0] * sin_d + v[..., 1] * cos_d], axis=-1
    )

    best = np.minimum(point_segment_distance(q, a_, b_), point_segment_distance(q_end, a_, b_))

    # Segment ends against the arc.
    for end in (a_, b_):
        w = end - p
        r_end = np.hypot(w[..., 0], w[..., 1])
        inside = _in_arc(np.arctan2(w[..., 1], w[..., 0]), start, delta)
        to_ends = np.minimum(
            np.hypot(*np.moveaxis(end - q, -1, 0)), np.hypot(*np.moveaxis(end - q_end, -1, 0))
        )
        best = np.minimum(best, np.where(inside, np.abs(r_end - rho), to_ends))

    # Interior candidates on the circle, relative to the segment's line.
    ab = b_ - a_
    ab_len2 = np.einsum("...i,...i->...", ab, ab)
    t = np.einsum("...i,...i->...", p - a_, ab) / ab_len2
    foot = a_ + t[..., None] * ab
    to_foot = foot - p
    h = np.hypot(to_foot[..., 0], to_foot[..., 1])
    unit_ab = ab / np.sqrt(ab_len2)[..., None]
    safe_h = np.where(h > 0, h, 1.0)[..., None]
    normal = to_foot / safe_h
    half_chord = np.sqrt(np.maximum(rho * rho - h * h, 0.0))
    crosses = rho >= h
    candidates = (
        (p + rho[..., None] * normal, h > 0),
        (p - rho[..., None] * normal, h > 0),
        (foot + half_chord[..., None] * unit_ab, crosses),
        (foot - half_chord[..., None] * unit_ab, crosses),
    )
    for x, valid in candidates:
        w = x - p
        inside = valid & _in_arc(np.arctan2(w[..., 1], w[..., 0]), start, delta)
        best = np.where(inside, np.minimum(best, point_segment_distance(x, a_, b_)), best)
    return np.asarray(best, dtype=np.float64)


ARM_BLOCKER_KINDS: tuple[BlockerKind, ...] = ("fold", "obstacle", "links")
"""The kinds of :data:`~rsstp_sim.interface.BlockerKind` that block an arm."""


@dataclass(frozen=True, slots=True)
class Blocker:
    """Why a move was blocked.

    ``fold``: ``indices == (joint,)``, the joint whose relative angle would reach 180.
    ``obstacle``: ``indices == (link, obstacle)``.
    ``links``: ``indices == (link_i, link_j)`` with ``link_i < link_j - 1``.
    """

    kind: BlockerKind
    indices: tuple[int, ...]

    def describe(self) -> str:
        if self.kind == "fold":
            return f"joint {self.indices[0]} would fold back onto link {self.indices[0] - 1}"
        if self.kind == "obstacle":
            return f"link {self.indices[0]} meets obstacle {self.indices[1]}"
        return f"links {self.indices[0]} and {self.indices[1]} intersect"


class _ScenarioLike(Protocol):
    @property
    def lengths(self) -> Sequence[float]: ...
    @property
    def obstacles(self) -> Sequence[object]: ...
    @property
    def collision(self) -> str: ...


@dataclass(frozen=True)
class ArmGeometry:
    """The numeric view of a scenario that the geometry functions need.

    Blocker codes (one int per move, 0 = free) are laid out as: ``k`` for a fold
    at joint ``k`` (1..n-1), then ``n + i*m + j`` for link ``i`` meeting
    obstacle ``j``, then ``n + n*m + i*n + j`` for links ``i < j``.
    """

    lengths: FloatArray
    centers: FloatArray
    radii: FloatArray
    swept: bool
    eps: float
    n: int = field(init=False)
    """Links (one per joint): ``len(lengths)``."""
    m: int = field(init=False)
    """Obstacles: ``len(radii)``."""
    link_lengths: tuple[float, ...] = field(init=False, repr=False, compare=False)
    """``lengths`` in plain floats (for :func:`move_blocker`)."""
    half_lengths: tuple[float, ...] = field(init=False, repr=False, compare=False)
    """Half of every link's length in plain floats (for :func:`move_blocker`)."""
    disks: tuple[tuple[float, float, float], ...] = field(init=False, repr=False, compare=False)
    """Every obstacle's ``(x, y, radius)`` in plain floats (for :func:`move_blocker`)."""

    def __post_init__(self) -> None:
        object.__setattr__(self, "n", int(self.lengths.shape[0]))
        object.__setattr__(self, "m", int(self.radii.shape[0]))
        object.__setattr__(self, "link_lengths", tuple(self.lengths.tolist()))
        object.__setattr__(self, "half_lengths", tuple((self.lengths * 0.5).tolist()))
        centers, radii = self.centers.tolist(), self.radii.tolist()
        disks = tuple((x, y, r) for (x, y), r in zip(centers, radii, strict=True))
        object.__setattr__(self, "disks", disks)

    @classmethod
    def from_scenario(cls, scenario: _ScenarioLike) -> ArmGeometry:
        lengths = np.asarray(scenario.lengths, dtype=np.float64)
        centers = np.array(
            [o.center for o in scenario.obstacles],  # type: ignore[attr-defined]
            dtype=np.float64,
        ).reshape(-1, 2)
        radii = np.array(
            [o.radius for o in scenario.obstacles],  # type: ignore[attr-defined]
            dtype=np.float64,
        )
        return cls(
            lengths,
            centers,
            radii,
            scenario.collision == "swept",
            CONTACT_EPS * float(lengths.sum()),
        )

    def decode(self, code: int) -> Blocker | None:
        n, m = self.n, self.m
        if code == 0:
            return None
        if code < n:
            return Blocker("fold", (code,))
        code -= n
        if code < n * m:
            return Blocker("obstacle", divmod(code, m))
        return Blocker("links", divmod(code - n * m, n))

    def _pairs(self) -> tuple[IntArray, IntArray]:
        i, j = np.triu_indices(self.n, k=2)
        return i.astype(np.int64), j.astype(np.int64)


def _first_codes(
    geo: ArmGeometry,
    fold: NDArray[np.bool_],
    obstacle: NDArray[np.bool_],
    links: NDArray[np.bool_],
    fold_joint: IntArray,
) -> IntArray:
    """Combine per-category hits into one blocker code per row (fold, obstacle, links)."""
    n, m = geo.n, geo.m
    batch = fold.shape[0]
    codes = np.zeros(batch, dtype=np.int64)
    pi, pj = geo._pairs()
    if pi.size:
        hit = links.any(axis=1)
        first = np.argmax(links, axis=1)
        codes = np.where(hit, n + n * m + pi[first] * n + pj[first], codes)
    if m:
        flat = obstacle.reshape(batch, n * m)
        hit = flat.any(axis=1)
        codes = np.where(hit, n + np.argmax(flat, axis=1), codes)
    return np.where(fold, fold_joint, codes)


def pose_blockers(geo: ArmGeometry, angles_deg: ArrayLike) -> IntArray:
    """Static validity of a batch of poses ``(B, n)``: blocker code per pose (0 = valid)."""
    theta = np.atleast_2d(np.asarray(angles_deg, dtype=np.int64))
    pos = joint_positions(theta, geo.lengths)
    a, b = pos[:, :-1], pos[:, 1:]
    folded = theta[:, 1:] == 180
    fold = folded.any(axis=1)
    fold_joint = np.argmax(folded, axis=1) + 1 if geo.n > 1 else np.zeros(len(theta), np.int64)
    obstacle = (
        point_segment_distance(geo.centers[None, None], a[:, :, None], b[:, :, None])
        <= geo.radii + geo.eps
    )
    pi, pj = geo._pairs()
    links = segment_distance(a[:, pi], b[:, pi], a[:, pj], b[:, pj]) <= geo.eps
    return _first_codes(geo, fold, obstacle, links, fold_joint)


def pose_blocker(scenario: _ScenarioLike, angles_deg: Sequence[int]) -> Blocker | None:
    """Why a single pose is invalid, or None when it is valid."""
    geo = ArmGeometry.from_scenario(scenario)
    return geo.decode(int(pose_blockers(geo, [list(angles_deg)])[0]))


def move_blockers(
    geo: ArmGeometry, angles_deg: ArrayLike, joints: ArrayLike, delta_deg: ArrayLike
) -> IntArray:
    """Blocker code for turning ``joints[b]`` by ``delta_deg[b]`` from pose ``angles_deg[b]``.

    The start poses must be valid. Swept mode checks the whole motion; endpoint
    mode (the thesis behaviour) only the end pose.
    """
    theta = np.atleast_2d(np.asarray(angles_deg, dtype=np.int64))
    batch, n = theta.shape
    joint = np.broadcast_to(np.asarray(joints, dtype=np.int64), (batch,))
    delta = np.broadcast_to(np.asarray(delta_deg, dtype=np.int64), (batch,))
    rows = np.arange(batch)
    end = theta.copy()
    end[rows, joint] = (end[rows, joint] + delta) % 360
    if not geo.swept:
        return pose_blockers(geo, end)

    # Fold: the turning joint (not the base) passes through or stops at 180.
    rel = np.where(delta >= 0, 180 - theta[rows, joint], theta[rows, joint] - 180) % 360
    fold = (joint >= 1) & (rel <= np.abs(delta))
    fold_joint = joint

    pos = joint_positions(theta, geo.lengths)
    a, b = pos[:, :-1], pos[:, 1:]
    pivot = pos[rows, joint]  # (B, 2)
    delta_rad = np.deg2rad(delta.astype(np.float64))
    link = np.arange(n)
    moving = link[None, :] >= joint[:, None]  # (B, n)

    # Every point of a moving link stays within ``sweep`` (its farthest distance from the
    # pivot times the turn) of where it starts, and a link lies within half its length of
    # its midpoint. Contacts that these bounds rule out are never tested exactly: the
    # bounds are filters, with slack, and must never miss a contact.
    near = point_segment_distance(pivot[:, None, :], a, b)  # (B, n)
    far = np.maximum(
        np.hypot(*np.moveaxis(a - pivot[:, None, :], -1, 0)),
        np.hypot(*np.moveaxis(b - pivot[:, None, :], -1, 0)),
    )
    sweep = far * np.abs(delta_rad)[:, None] + 2 * geo.eps  # (B, n)
    mid = (a + b) * 0.5
    half = geo.lengths * 0.5

    # Moving links against obstacles: centres turned the opposite way. Turning keeps every
    # point's distance to the pivot, so a link sweeps only the ring between its nearest and
    # farthest distance from the pivot; an obstacle disk off that ring, or farther from the
    # link than its sweep, cannot be met. The exact arc test runs only for the (move, link,
    # obstacle) triples that pass both.
    if geo.m:
        reach = geo.radii + geo.eps
        slack = reach + geo.eps
        centre = np.hypot(*np.moveaxis(geo.centers[None] - pivot[:, None, :], -1, 0))  # (B, m)
        to_mid = np.hypot(*np.moveaxis(geo.centers[None, None] - mid[:, :, None], -1, 0))
        ring = (
            moving[:, :, None]
            & (centre[:, None, :] + slack >= near[:, :, None])
            & (centre[:, None, :] - slack <= far[:, :, None])
            & (to_mid - half[None, :, None] <= slack + sweep[:, :, None])
        )
        at_row, at_link, at_obstacle = np.nonzero(ring)
        if len(at_row):  # the link's own distance to the disk, the tighter bound
            static = point_segment_distance(
                geo.centers[at_obstacle], a[at_row, at_link], b[at_row, at_link]
            )
            close = static <= slack[at_obstacle] + sweep[at_row, at_link]
            at_row, at_link, at_obstacle = at_row[close], at_link[close], at_obstacle[close]
        obstacle = np.zeros((batch, n, geo.m), dtype=bool)
        if len(at_row):
            dist = arc_segment_distance(
                pivot[at_row],
                geo.centers[at_obstacle],
                -delta_rad[at_row],
                a[at_row, at_link],
                b[at_row, at_link],
            )
            obstacle[at_row, at_link, at_obstacle] = dist <= reach[at_obstacle]
    else:
        obstacle = np.zeros((batch, n, 0), dtype=bool)

    # Moving link j against fixed link i (i < j - 1): ends of the moving link on
    # the fixed one, or ends of the fixed link (turned back) on the moving one. Only the
    # pairs of a fixed link and a moving one within the moving link's sweep can meet.
    pi, pj = geo._pairs()
    links = np.zeros((batch, pi.size), dtype=bool)
    if pi.size:
        rows, pairs = np.nonzero((pi[None, :] < joint[:, None]) & (pj[None, :] >= joint[:, None]))
        fixed, moved = pi[pairs], pj[pairs]
        gap = np.hypot(*np.moveaxis(mid[rows, fixed] - mid[rows, moved], -1, 0))
        close = gap - half[fixed] - half[moved] <= sweep[rows, moved] + geo.eps
        rows, pairs, fixed, moved = rows[close], pairs[close], fixed[close], moved[close]
        if len(rows):  # the links' own distance, the tighter bound
            fixed_a, fixed_b = a[rows, fixed], b[rows, fixed]
            static = segment_distance(fixed_a, fixed_b, a[rows, moved], b[rows, moved])
            close = static <= sweep[rows, moved] + geo.eps
            rows, pairs, fixed, moved = rows[close], pairs[close], fixed[close], moved[close]
        if len(rows):
            pv, d = pivot[rows], delta_rad[rows]
            fixed_a, fixed_b = a[rows, fixed], b[rows, fixed]
            move_a, move_b = a[rows, moved], b[rows, moved]
            contact = np.minimum.reduce(
                [
                    arc_segment_distance(pv, move_a, d, fixed_a, fixed_b),
                    arc_segment_distance(pv, move_b, d, fixed_a, fixed_b),
                    arc_segment_distance(pv, fixed_a, -d, move_a, move_b),
                    arc_segment_distance(pv, fixed_b, -d, move_a, move_b),
                ]
            )
            links[rows, pairs] = contact <= geo.eps
    return _first_codes(geo, fold, obstacle, links, fold_joint)


def _gap(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """:func:`point_segment_distance` of one point in plain floats (a bound's input only)."""
    abx, aby = bx - ax, by - ay
    denom = abx * abx + aby * aby
    t = ((px - ax) * abx + (py - ay) * aby) / denom if denom > 0 else 0.0
    t = 0.0 if t < 0.0 else 1.0 if t > 1.0 else t
    return math.hypot(px - ax - t * abx, py - ay - t * aby)


def _segments_gap(seg: Sequence[float], other: Sequence[float]) -> float:
    """:func:`segment_distance` of two segments ``(ax, ay, bx, by)`` in plain floats."""
    ax, ay, bx, by = seg
    cx, cy, dx, dy = other
    o1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    o2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    o3 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    o4 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    if o1 * o2 < 0 and o3 * o4 < 0:
        return 0.0
    return min(
        _gap(ax, ay, cx, cy, dx, dy),
        _gap(bx, by, cx, cy, dx, dy),
        _gap(cx, cy, ax, ay, bx, by),
        _gap(dx, dy, ax, ay, bx, by),
    )


def _arc_gap(
    px: float, py: float, qx: float, qy: float, delta: float, seg: Sequence[float]
) -> float:
    """:func:`arc_segment_distance` of one arc (``(qx, qy)`` turned about ``(px, py)`` by
    ``delta``) and one segment ``(ax, ay, bx, by)`` in plain floats: the same candidates,
    measured the same way."""
    ax, ay, bx, by = seg
    atan2, hypot = math.atan2, math.hypot
    vx, vy = qx - px, qy - py
    rho = hypot(vx, vy)
    start = atan2(vy, vx)
    span = abs(delta) + _ANGLE_SLACK
    forward = delta >= 0
    c, s = math.cos(delta), math.sin(delta)
    ex, ey = px + (vx * c - vy * s), py + (vx * s + vy * c)
    best = min(_gap(qx, qy, ax, ay, bx, by), _gap(ex, ey, ax, ay, bx, by))
    for x, y in ((ax, ay), (bx, by)):
        wx, wy = x - px, y - py
        direction = atan2(wy, wx)
        if (direction - start if forward else start - direction) % _TWO_PI <= span:
            best = min(best, abs(hypot(wx, wy) - rho))
        else:
            best = min(best, hypot(x - qx, y - qy), hypot(x - ex, y - ey))
    abx, aby = bx - ax, by - ay
    ab2 = abx * abx + aby * aby
    t = ((px - ax) * abx + (py - ay) * aby) / ab2
    fx, fy = ax + t * abx, ay + t * aby
    h = hypot(fx - px, fy - py)
    candidates = []
    if h > 0:
        nx, ny = (fx - px) / h, (fy - py) / h
        candidates += [(px + rho * nx, py + rho * ny), (px - rho * nx, py - rho * ny)]
    if rho >= h:
        chord = math.sqrt(max(rho * rho - h * h, 0.0)) / math.sqrt(ab2)
        candidates += [(fx + chord * abx, fy + chord * aby), (fx - chord * abx, fy - chord * aby)]
    for x, y in candidates:
        direction = atan2(y - py, x - px)
        if (direction - start if forward else start - direction) % _TWO_PI <= span:
            best = min(best, _gap(x, y, ax, ay, bx, by))
    return best


def _meets(distance: float, threshold: float, margin: float) -> bool | None:
    """Whether a contact is met; None when the plain-float distance is within ``margin`` of
    its threshold, too near to decide against numpy's rounding."""
    if abs(distance - threshold) <= margin:
        return None
    return distance <= threshold


def move_blocker(
    geo: ArmGeometry, angles_deg: Sequence[int], points: Sequence[float], joint: int, delta_deg: int
) -> int:
    """The blocker code of one move, equal to :func:`move_blockers` on a batch of one.

    ``points`` are the start pose's :func:`pose_points`. The same tests as
    :func:`move_blockers` (the fold; in swept mode each moving link against each obstacle and
    each fixed link, first through the sweep bounds, then exactly; in endpoint mode the end
    pose's links against the obstacles and each other), in the same order, in plain floats:
    a new pose costs a few dozen float operations, not numpy's per-call cost. A distance
    within a hair (:data:`_UNSURE` of the arm's length) of its threshold, where plain floats
    and numpy could round to different sides, is left to :func:`move_blockers` itself, so
    the answer is always numpy's.
    """
    code = _move_blocker(geo, angles_deg, points, joint, delta_deg)
    if code is None:  # too near a threshold: numpy decides
        return int(move_blockers(geo, [list(angles_deg)], [joint], [delta_deg])[0])
    return code


_UNSURE = 1e-11
"""The band around a contact threshold (a fraction of the arm's length, a hundredth of
:data:`CONTACT_EPS`) in which :func:`move_blocker` defers to :func:`move_blockers`."""


def _move_blocker(
    geo: ArmGeometry, angles_deg: Sequence[int], points: Sequence[float], joint: int, delta_deg: int
) -> int | None:
    """:func:`move_blocker` in plain floats; None when a distance is too near its threshold."""
    n, m, halves, eps = geo.n, geo.m, geo.half_lengths, geo.eps
    unsure = eps * (_UNSURE / CONTACT_EPS)
    hypot = math.hypot
    swept = geo.swept
    if swept:
        if joint:
            theta = angles_deg[joint]
            rel = (180 - theta) % 360 if delta_deg >= 0 else (theta - 180) % 360
            if rel <= abs(delta_deg):
                return joint  # the fold, which move_blockers reports before any contact
        px, py = points[2 * joint], points[2 * joint + 1]
        delta = math.radians(delta_deg)
    else:  # only the end pose counts: every link against everything
        end = list(angles_deg)
        end[joint] = (end[joint] + delta_deg) % 360
        for k in range(1, n):
            if end[k] == 180:
                return k
        points = pose_points(end, geo.link_lengths)
        px = py = delta = 0.0
        joint = 0
    turn = abs(delta)
    disks = geo.disks
    fixed_links = joint if swept else n  # the links a moving one may meet
    # Each moving link's bound (move_blockers' filters): every point stays within its sweep
    # of where it starts, and the link within half its length of its midpoint. A contact
    # farther than that, with 2 eps to spare for rounding, cannot be met.
    # A moving link's midpoint, half its length, its reach against a fixed link's midpoint
    # (half its length, eps and its sweep), its bound against a fixed link, and its segment.
    mids: list[tuple[float, float, float, float, float, tuple[float, float, float, float]]] = []
    near = 0.0  # the moving link's start from the pivot (the first one starts there)
    ax, ay = points[2 * joint], points[2 * joint + 1]
    for j in range(joint, n):
        bx, by = points[2 * j + 2], points[2 * j + 3]
        mx, my = 0.5 * (ax + bx), 0.5 * (ay + by)
        if turn:
            far = hypot(bx - px, by - py)  # and its end, the next link's start
            sweep = turn * (far if far > near else near) + 4 * eps
            near = far
        else:
            sweep = 4 * eps
        half = halves[j]
        seg = (ax, ay, bx, by)
        if fixed_links:
            mids.append((mx, my, half, half + eps + sweep, eps + sweep, seg))
        for o, (cx, cy, radius) in enumerate(disks):
            bound = radius + eps + sweep
            if hypot(cx - mx, cy - my) - half > bound or _gap(cx, cy, ax, ay, bx, by) > bound:
                continue
            if swept:
                distance = _arc_gap(px, py, cx, cy, -delta, seg)
            else:
                distance = _gap(cx, cy, ax, ay, bx, by)
            met = _meets(distance, radius + eps, unsure)
            if met is None or met:
                return None if met is None else n + j * m + o
        ax, ay = bx, by
    ax, ay = points[0], points[1]
    for i in range(fixed_links):
        bx, by = points[2 * i + 2], points[2 * i + 3]
        first = max(joint, i + 2)
        if first < n:
            fixed = (ax, ay, bx, by)
            fx, fy = 0.5 * (ax + bx), 0.5 * (ay + by)
            half_i = halves[i]
            for j, (mx, my, half_j, reach, bound, seg) in enumerate(mids[first - joint :], first):
                if hypot(fx - mx, fy - my) - half_i > reach:
                    continue
                if _gap(mx, my, ax, ay, bx, by) - half_j > bound:
                    continue  # its midpoint, from the fixed link, less half its length
                if _segments_gap(fixed, seg) > bound:
                    continue
                if swept:
                    distance = min(
                        _arc_gap(px, py, seg[0], seg[1], delta, fixed),
                        _arc_gap(px, py, seg[2], seg[3], delta, fixed),
                        _arc_gap(px, py, ax, ay, -delta, seg),
                        _arc_gap(px, py, bx, by, -delta, seg),
                    )
                else:
                    distance = _segments_gap(fixed, seg)
                met = _meets(distance, eps, unsure)
                if met is None or met:
                    return None if met is None else n + n * m + i * n + j
        ax, ay = bx, by
    return 0


def feedback(
    tips: ArrayLike, points: ArrayLike, lengths: ArrayLike, tolerance_abs: float
) -> tuple[NDArray[np.bool_], FloatArray]:
    """Sensation and float closeness for tips ``(..., n, 2)`` and feedback points ``(n, 2)``.

    Sensation: every tip within ``tolerance_abs`` of its point. Closeness (thesis
    4.6): mean over joints of ``1 - |p_k - f_k| / (|f_k| + sum_{i<=k} L_i)``, in
    [0, 1] and 1 exactly at the point.
    """
    tips_ = np.asarray(tips, dtype=np.float64)
    points_ = np.asarray(points, dtype=np.float64)
    gap = np.hypot(*np.moveaxis(tips_ - points_, -1, 0))
    reach = feedback_reach(points_, lengths)
    sensation = np.all(gap <= tolerance_abs, axis=-1)
    closeness = np.clip(1.0 - gap / reach, 0.0, 1.0).mean(axis=-1)
    return np.asarray(sensation), np.asarray(closeness, dtype=np.float64)


def feedback_reach(points: ArrayLike, lengths: ArrayLike) -> FloatArray:
    """The denominators of :func:`feedback`'s closeness: ``|f_k| + sum_{i<=k} L_i``."""
    points_ = np.asarray(points, dtype=np.float64)
    reach = np.hypot(points_[:, 0], points_[:, 1]) + np.cumsum(np.asarray(lengths, np.float64))
    return np.asarray(reach, dtype=np.float64)


def pose_feedback(
    points: Sequence[float],
    feedback_points: FloatArray,
    reach: Sequence[float],
    tolerance_abs: float,
) -> tuple[bool, float]:
    """:func:`feedback` of one pose given as :func:`pose_points`, equal to it bit for bit.

    ``feedback_points`` is the ``(n, 2)`` array of points raveled (``x0, y0, x1, y1, ...``,
    as the pose's points come), ``reach`` :func:`feedback_reach`. The distances go through
    numpy's ``hypot`` (Python's rounds differently in rare cases); numpy's mean of at most
    seven values adds them in order, as here (a closeness is at most 1, a gap being at least
    0, and one clipped to 0 adds nothing).
    """
    tips = np.array(points[2:]) - feedback_points
    gaps: list[float] = np.hypot(tips[0::2], tips[1::2]).tolist()
    total = 0.0
    for gap, r in zip(gaps, reach, strict=True):
        c = 1.0 - gap / r
        if c > 0.0:
            total += c
    return max(gaps) <= tolerance_abs, total / len(gaps)


def obstacle_distances(tips: ArrayLike, centers: ArrayLike, radii: ArrayLike) -> FloatArray:
    """Distance from every tip to every obstacle's surface, ``|p_k - c_j| - r_j`` (thesis 4.5).

    Shape ``(..., n, m)``; negative would mean inside (never for a valid pose's tips).
    """
    tips_ = np.asarray(tips, dtype=np.float64)[..., :, None, :]
    diff = tips_ - np.asarray(centers, dtype=np.float64)
    return np.asarray(
        np.hypot(diff[..., 0], diff[..., 1]) - np.asarray(radii, np.float64), dtype=np.float64
    )
