"""The world table: the poses an arm can reach, their sensations and their moves, in arrays.

This is the one home of the geometry's answers. The world (one move at a time), the
ground truth (every reachable pose at once) and the Gymnasium env (through the world)
all read the same table, and the table asks :mod:`rsstp_sim.arm.geometry` for whole batches
of poses and moves at once.

- A *pose code* is ``sum(angle_k * 360**k)`` (integer degrees), a *row* the pose's place
  in the table, in the order the poses were reached: the start pose is row 0.
- ``next_row[row * A + k]`` is the row reached by the scenario's ``k``-th action (the row
  itself when the move is blocked), or -1 while that pose's moves are not computed;
  ``blocker[row * A + k]`` is the move's blocker code (0 = free, see
  :class:`~rsstp_sim.arm.geometry.ArmGeometry`). Both are ``array.array`` of C ints: compact,
  growable, and read by Python without numpy's per-call cost.
- Only poses the arm can reach are ever stored: a pose enters the table as the target of
  a free move, never as a neighbour on a lattice, so invalid and unreachable poses cost
  nothing.

The table grows on demand, in one of two ways. By blocks: :meth:`WorldTable.expand`
computes the moves of a block of poses around the one the arm stands on, breadth first, one
vectorised batch per frontier, as many poses as the caller's budget allows, and
:meth:`WorldTable.complete` computes every reachable pose the same way (the ground truth's
enumeration). Or move by move: :meth:`WorldTable.step` computes just the move the arm makes
(one swept check of the joint that turns, see :func:`~rsstp_sim.arm.geometry.move_blocker`) and
the one pose it reaches, in plain floats: the way of a pose space too large to be
tabulated, where nearly every move reaches a new pose, or of a world whose whole table
would cost more than :data:`MAX_TABULATION_CHECKS` link-obstacle checks (many obstacles),
where the blocks would grow to that cost over a long run. A pose space of at most
:data:`DENSE_LIMIT` lattice poses finds rows by pose code in a dense array, a larger one in
a dict of the poses reached.

Every row keeps its pose's :func:`~rsstp_sim.arm.geometry.pose_points` (the base and the link
tips, flat), its sensation and its float feedback, and, when a pose has at most
:data:`KEPT_DISTANCES` tip-obstacle distances, those distances, in growable arrays: a few
hundred bytes a pose, whichever way it was computed. A pose of more distances (three links
among 1,000 obstacles have 3,000, 24 KB) has them computed each time they are read.
"""

from __future__ import annotations

import array
import math
from collections.abc import Sequence

import numpy as np

from rsstp_sim.arm import geometry
from rsstp_sim.arm.geometry import ArmGeometry
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arrays import BoolArray, FloatArray, Int32Array, IntArray, distinct
from rsstp_sim.errors import ScenarioError
from rsstp_sim.interface import PoseMachine

__all__ = [
    "DENSE_LIMIT",
    "KEPT_DISTANCES",
    "MAX_TABULATION_CHECKS",
    "WorldTable",
    "check_start",
    "lattice_sizes",
    "pose_space_size",
    "tabulation_checks",
    "unsensable",
]


DENSE_LIMIT = 4_000_000
"""Pose spaces of at most this many lattice poses index their rows in a dense array."""
MAX_TABULATION_CHECKS = 1_000_000_000
"""The most link-obstacle checks a whole world table may cost (:func:`tabulation_checks`):
about 20 s on this project's machine. A world beyond it is grown move by move (only the moves
the arm makes), and its ground truth is refused. Three joints at 5 degrees among 1,000
obstacles count 6.7 billion: grown in blocks, a 2,000-step run took 114 s and 6.7 GB."""
KEPT_DISTANCES = 256
"""A row keeps its tip-obstacle distances when it has at most this many (2 KB)."""
_CHUNK_MOVES = 65_536
"""Moves per call to :func:`geometry.move_blockers` (bounds the temporaries' memory)."""


def lattice_sizes(scenario: Scenario) -> list[int]:
    """How many angles each joint can take: ``360 / gcd(step, 360)``, or 1 when no
    action turns it (it keeps its initial angle)."""
    values = 360 // math.gcd(scenario.step_deg, 360)
    moving = {a // 2 for a in scenario.actions}
    return [values if k in moving else 1 for k in range(scenario.n_joints)]


def unsensable(scenario: Scenario) -> str | None:
    """Why no pose of the arm can sense its feedback point, when a look at the one pose that
    could tells (the ground truth then counts the reachable poses that sense it): the points
    out of the links' reach, the pose off the arm's lattice, or the pose itself blocked.
    None when that pose exists and is valid (it may still be unreachable behind obstacles)."""
    lengths = np.asarray(scenario.lengths, dtype=np.float64)
    points = np.asarray(scenario.feedback_points, dtype=np.float64)
    tolerance = scenario.tolerance * scenario.total_length
    initial = np.asarray(scenario.initial_deg, dtype=np.int64)
    spacing = math.gcd(scenario.step_deg, 360)
    fixed = np.asarray(lattice_sizes(scenario)) == 1
    if scenario.feedback_target_deg is not None:
        pose = np.asarray(scenario.feedback_target_deg, dtype=np.int64)
        off = (fixed & (pose != initial)) | ((pose - initial) % spacing != 0)
        if off.any():
            return (
                f"the target pose {pose.tolist()} is not on the arm's lattice (from "
                f"{initial.tolist()} in {scenario.step_deg}-degree steps, joints "
                f"{np.flatnonzero(fixed).tolist()} never turning)"
            )
    else:
        links = np.diff(np.vstack([[0.0, 0.0], points]), axis=0)
        gaps = np.abs(np.hypot(links[:, 0], links[:, 1]) - lengths)
        if (gaps > 2 * tolerance).any():
            k = int(np.argmax(gaps))
            return (
                f"feedback point {k} is {gaps[k]:.3g} from every place link {k}'s tip can be "
                f"(tolerance {tolerance:.3g})"
            )
        absolute = np.degrees(np.arctan2(links[:, 1], links[:, 0]))
        relative = np.diff(np.concatenate([[0.0], absolute]))
        steps = np.where(fixed, 0, np.round((relative - initial) / spacing))
        pose = (initial + steps.astype(np.int64) * spacing) % 360
        tips = geometry.joint_positions(pose, lengths)[1:]
        miss = float(np.hypot(*(tips - points).T).max())
        if miss > tolerance:
            return (
                f"no pose on the arm's {scenario.step_deg}-degree lattice puts the tips on the "
                f"feedback points (the nearest, {pose.tolist()}, misses by {miss:.3g}; "
                f"tolerance {tolerance:.3g})"
            )
    code = int(geometry.pose_blockers(ArmGeometry.from_scenario(scenario), [pose])[0])
    blocker = ArmGeometry.from_scenario(scenario).decode(code)
    if blocker is not None:
        return f"the pose at the feedback point, {pose.tolist()}, is blocked: {blocker.describe()}"
    return None


def check_start(scenario: Scenario) -> ArmGeometry:
    """The scenario's geometry, once it has checked the start pose: raise
    :class:`~rsstp_sim.errors.ScenarioError` when the arm cannot stand there (a link meets an
    obstacle or another link, a joint folds back)."""
    geo = ArmGeometry.from_scenario(scenario)
    initial = list(scenario.initial_deg)
    blocker = geo.decode(int(geometry.pose_blockers(geo, [initial])[0]))
    if blocker is not None:
        raise ScenarioError(
            f"{scenario.origin}: arm.initial_deg: the start pose {initial} is invalid "
            f"({blocker.describe()})"
        )
    return geo


def pose_space_size(scenario: Scenario) -> int:
    """An upper bound on the reachable poses, known before any geometry is computed."""
    return math.prod(lattice_sizes(scenario))


def tabulation_checks(scenario: Scenario) -> int:
    """What the whole world table would cost, known before any geometry: every move of every
    lattice pose (an upper bound of the reachable ones), each moving link against each
    obstacle."""
    n_checks = pose_space_size(scenario) * len(scenario.actions) * scenario.n_joints
    return n_checks * max(1, len(scenario.obstacles))


class WorldTable:
    """The reachable poses of ``scenario`` found so far, and the moves computed so far.
    Raises :class:`~rsstp_sim.errors.ScenarioError` when the start pose is invalid
    (:func:`check_start`)."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.pose_space = pose_space_size(scenario)
        """:func:`pose_space_size`: the lattice poses, a bound on the reachable ones."""
        self.checks = tabulation_checks(scenario)
        """:func:`tabulation_checks`: what the whole table costs."""
        sizes = np.asarray(lattice_sizes(scenario), dtype=np.int64)
        self.geometry = check_start(scenario)
        n = scenario.n_joints
        self.actions: tuple[int, ...] = tuple(scenario.actions)
        self.radix = np.array([360**k for k in range(n)], dtype=np.int64)
        actions = np.asarray(self.actions, dtype=np.int64)
        self._joint = actions // 2
        self._delta = np.where(actions % 2 == 0, scenario.step_deg, -scenario.step_deg)
        # The index of each action's reverse (the same joint turned back), -1 when the
        # scenario lacks it: a move and its reverse sweep the same poses.
        self._reverse = np.array(
            [self.actions.index(a ^ 1) if a ^ 1 in self.actions else -1 for a in self.actions],
            dtype=np.int64,
        )
        self._points = np.asarray(scenario.feedback_points, dtype=np.float64)
        self._tolerance_abs = scenario.tolerance * scenario.total_length
        # The same in plain Python numbers, for the move-by-move path.
        self._reach = geometry.feedback_reach(self._points, self.geometry.lengths).tolist()
        self._flat_points = self._points.ravel()
        self._joint_list: list[int] = self._joint.tolist()
        self._delta_list: list[int] = self._delta.tolist()
        self._reverse_list: list[int] = self._reverse.tolist()
        self._radix_list: list[int] = self.radix.tolist()
        self.width = 2 * (n + 1)
        """Floats a row takes in :attr:`positions`."""

        self.codes = array.array("q")
        self.next_row = array.array("i")
        self.blocker = array.array("i")
        self.sensation = array.array("b")
        self.feedback = array.array("d")
        self.positions = array.array("d")
        """Every row's :func:`~rsstp_sim.arm.geometry.pose_points`, :attr:`width` floats a row."""
        self.keeps_distances = n * self.geometry.m <= KEPT_DISTANCES
        """Whether rows keep their distances (else :meth:`distances_of` computes them)."""
        self.distances = array.array("d")
        """When :attr:`keeps_distances`, every row's
        :func:`~rsstp_sim.arm.geometry.obstacle_distances` (``n * m`` floats a row) when its pose
        came in a block; NaN for a pose added alone (see :meth:`step`), whose distances its
        reader computes (:meth:`distances_of`). Empty otherwise."""
        self._unknown_distances = array.array(
            "d", [math.nan] * (n * self.geometry.m if self.keeps_distances else 0)
        )
        self.dense = self.pose_space <= DENSE_LIMIT
        self.heavy = self.checks > MAX_TABULATION_CHECKS
        """The whole table would cost more than :data:`MAX_TABULATION_CHECKS`: grow it move by
        move (see :class:`~rsstp_sim.arm.world.World`)."""
        # Rows by pose code: a dense array over a small lattice, else a dict of the poses
        # reached.
        self._spacing = math.gcd(scenario.step_deg, 360)
        self._lattice_radix = np.concatenate([[1], np.cumprod(sizes)[:-1]]).astype(np.int64)
        self._initial = np.asarray(scenario.initial_deg, dtype=np.int64)
        self._dense = np.full(int(sizes.prod()), -1, dtype=np.int32) if self.dense else None
        self._row_of: dict[int, int] = {}
        self._initial_list: list[int] = self._initial.tolist()
        self._lattice_list: list[int] = self._lattice_radix.tolist()
        self._blank_moves = array.array("i", [-1] * len(self.actions))
        self._no_blockers = array.array("i", [0] * len(self.actions))
        self._last: tuple[int, Sequence[int], Sequence[float]] = (-1, (), ())
        """The row :meth:`_add_pose` added last, its angles and its points, as plain lists."""
        start = int(self._initial @ self.radix)
        self._add_poses(np.array([start], dtype=np.int64))

    # -- size ----------------------------------------------------------------

    def __len__(self) -> int:
        return len(self.codes)

    @property
    def n_actions(self) -> int:
        return len(self.actions)

    def moves_computed(self) -> int:
        """How many rows have at least one move computed."""
        return int(np.count_nonzero((self.next_array() >= 0).any(axis=1)))

    # -- growing ---------------------------------------------------------------

    def machine(self) -> PoseMachine:
        """Every reachable pose: the table completed (:meth:`complete`), its rows put in code
        order."""
        self.complete()
        codes = np.frombuffer(self.codes, dtype=np.int64)
        order = np.argsort(codes, kind="stable")
        rank = np.empty(len(order), dtype=np.int64)
        rank[order] = np.arange(len(order))
        n = len(self.radix)
        return PoseMachine(
            codes=codes[order].copy(),
            values=self.angles()[order],
            next_pose=rank[self.next_array()[order]],
            sensation=self.sensations()[order],
            start_index=int(rank[0]),
            value_names=tuple(f"angle_deg_{j}" for j in range(n)),
            radices=(360,) * n,
            units=(1,) * n,
            wrap=True,
        )

    def complete(self) -> None:
        """Compute every reachable pose and all its moves (breadth first from the start)."""
        frontier = np.flatnonzero((self.next_array() < 0).any(axis=1))
        while frontier.size:
            first_new = len(self.codes)
            self._compute_moves(frontier)
            frontier = np.arange(first_new, len(self.codes), dtype=np.int64)

    def expand(self, row: int, budget: int) -> None:
        """Compute the moves of ``row`` and, breadth first through the poses it reaches, of
        up to ``budget`` poses in all (at least ``row``'s)."""
        frontier = np.array([row], dtype=np.int64)
        done = 0
        n_actions = len(self.actions)
        while frontier.size and done < budget:
            frontier = frontier[: budget - done]
            self._compute_moves(frontier)
            done += len(frontier)
            nxt = self.next_array()
            reached = distinct(nxt[frontier])
            frontier = reached[(nxt[reached] < 0).any(axis=1)].astype(np.int64)
            del nxt
        assert self.next_row[row * n_actions] >= 0

    def step(self, row: int, k: int) -> int:
        """Compute the scenario's ``k``-th action from ``row`` alone; the row it reaches.

        The move's reverse, when already computed from the pose the move reaches, gives its
        blocker (they sweep the same poses); else one check of the joint that turns
        (:func:`~rsstp_sim.arm.geometry.move_blocker`). A free move to a pose not in the table
        adds that one pose.
        """
        n_actions = len(self.actions)
        code = self.codes[row]
        joint, delta = self._joint_list[k], self._delta_list[k]
        radix = self._radix_list[joint]
        angle = code // radix % 360
        turned = (angle + delta) % 360
        moved = code + (turned - angle) * radix
        there = self._find(moved)
        back = self._reverse_list[k]
        if there >= 0 and back >= 0 and self.next_row[there * n_actions + back] >= 0:
            blocker = self.blocker[there * n_actions + back]
        else:
            last_row, last_angles, last_points = self._last
            if row == last_row:  # a walk mostly moves on from the pose it just added
                angles, points = list(last_angles), last_points
            else:
                width = self.width
                angles = self.angles_of(code)
                points = self.positions[row * width : (row + 1) * width]
            blocker = geometry.move_blocker(self.geometry, angles, points, joint, delta)
            if not blocker and there < 0:
                angles[joint] = turned
                there = self._add_pose(moved, angles, known=points, first=joint)
        if blocker:
            there = row
        self.next_row[row * n_actions + k] = there
        self.blocker[row * n_actions + k] = blocker
        return there

    def angles_of(self, code: int) -> list[int]:
        """The joint angles (integer degrees) of a pose code."""
        return [code // r % 360 for r in self._radix_list]

    def _find(self, code: int) -> int:
        """:meth:`row_of` without numpy, for the move-by-move path."""
        if self._dense is None:
            return self._row_of.get(code, -1)
        return int(self._dense[self._cell(self.angles_of(code))])

    def _cell(self, angles: list[int]) -> int:
        """A pose's index in the dense array (see :meth:`rows_of`)."""
        cell = 0
        for angle, start, stride in zip(
            angles, self._initial_list, self._lattice_list, strict=True
        ):
            cell += (angle - start) % 360 // self._spacing * stride
        return cell

    def _add_pose(self, code: int, angles: list[int], *, known: Sequence[float], first: int) -> int:
        """Append one pose (a new code, its ``angles``) as a row, computed in plain floats
        (its points from ``known``, those of a pose one move of joint ``first`` away); its
        row."""
        row = len(self.codes)
        points = geometry.pose_points(angles, self.geometry.link_lengths, known=known, first=first)
        sensation, closeness = geometry.pose_feedback(
            points, self._flat_points, self._reach, self._tolerance_abs
        )
        if self._dense is None:
            self._row_of[code] = row
        else:
            self._dense[self._cell(angles)] = row
        self._last = (row, angles, points)
        self.codes.append(code)
        self.positions.fromlist(points)
        self.distances.extend(self._unknown_distances)
        self.sensation.append(sensation)
        self.feedback.append(closeness)
        self.next_row.extend(self._blank_moves)
        self.blocker.extend(self._no_blockers)
        return row

    def _compute_moves(self, rows: IntArray) -> None:
        """Blockers and targets of every action from ``rows`` (poses without moves yet).

        A move and its reverse sweep the same poses, so they meet the same obstacles and
        links and have the same blocker (in endpoint mode both ends are valid poses, so both
        are free): a move whose reverse is already computed, from the pose it leads to, is
        copied from it; only the others are computed, in vectorised chunks.
        """
        n_actions = len(self.actions)
        per_chunk = max(1, _CHUNK_MOVES // n_actions)
        all_codes = np.frombuffer(self.codes, dtype=np.int64)
        codes_of = all_codes[rows]
        del all_codes  # the table grows below: no view of it may stay
        for lo in range(0, len(rows), per_chunk):
            chunk, codes = rows[lo : lo + per_chunk], codes_of[lo : lo + per_chunk]
            angles = (codes[:, None] // self.radix) % 360
            starts = np.repeat(angles, n_actions, axis=0)
            joints = np.tile(self._joint, len(chunk))
            deltas = np.tile(self._delta, len(chunk))
            index = np.arange(len(starts))
            turned = (starts[index, joints] + deltas) % 360
            here = np.repeat(codes, n_actions)
            moved = here + (turned - starts[index, joints]) * self.radix[joints]
            reverse = np.tile(self._reverse, len(chunk))
            there = self.rows_of(moved)
            known = (there >= 0) & (reverse >= 0)
            blockers = np.zeros(len(starts), dtype=np.int64)
            if known.any():
                at, back = there[known], reverse[known]
                copied = self.next_array()[at, back] >= 0
                known[np.flatnonzero(known)[~copied]] = False
                blockers[known] = self.blocker_array()[there[known], reverse[known]]
            todo = ~known
            if todo.any():
                blockers[todo] = geometry.move_blockers(
                    self.geometry, starts[todo], joints[todo], deltas[todo]
                )
            free = blockers == 0
            target_rows = np.where(free, there, np.repeat(chunk, n_actions)).astype(np.int32)
            new = target_rows < 0  # free moves to poses not in the table yet
            if new.any():
                self._add_poses(distinct(moved[new]))
                target_rows[new] = self.rows_of(moved[new])
            self.next_array()[chunk] = target_rows.reshape(-1, n_actions)
            self.blocker_array()[chunk] = blockers.reshape(-1, n_actions)

    def rows_of(self, codes: IntArray) -> Int32Array:
        """The row of every pose code, -1 for a pose not in the table."""
        if self._dense is not None:
            return self.rows_at((codes[:, None] // self.radix) % 360)
        get = self._row_of.get
        return np.fromiter((get(c, -1) for c in codes.tolist()), np.int32, len(codes))

    def rows_at(self, angles: IntArray) -> Int32Array:
        """The row of every pose given by its joint angles ``(poses, n)`` (integer degrees in
        ``0 .. 359``), -1 for a pose not in the table; a pose off the scenario's lattice of
        angles is never in it, but a dense table maps it to a lattice pose's row, so a caller
        that may hold one compares the row's code."""
        if self._dense is not None:
            cells = (((angles - self._initial) % 360) // self._spacing) @ self._lattice_radix
            return np.asarray(self._dense[cells], dtype=np.int32)
        return self.rows_of(np.asarray(angles, np.int64) @ self.radix)

    def row_of(self, code: int) -> int:
        """The row of one pose code, -1 when the pose is not in the table."""
        return int(self.rows_of(np.array([code], dtype=np.int64))[0])

    def _add_poses(self, codes: IntArray) -> None:
        """Append poses (new codes) as rows, with their geometry computed in one batch."""
        first = len(self.codes)
        rows = np.arange(first, first + len(codes), dtype=np.int32)
        angles = (codes[:, None] // self.radix) % 360
        positions = geometry.joint_positions(angles, self.geometry.lengths)
        tips = positions[:, 1:]
        sensation, closeness = geometry.feedback(
            tips, self._points, self.geometry.lengths, self._tolerance_abs
        )
        if self._dense is not None:
            cells = (((angles - self._initial) % 360) // self._spacing) @ self._lattice_radix
            self._dense[cells] = rows
        else:
            self._row_of.update(zip(codes.tolist(), rows.tolist(), strict=True))
        self.codes.frombytes(codes.astype(np.int64).tobytes())
        self.positions.frombytes(positions.tobytes())
        if self.keeps_distances:
            distances = geometry.obstacle_distances(
                tips, self.geometry.centers, self.geometry.radii
            )
            self.distances.frombytes(distances.tobytes())
        self.sensation.frombytes(sensation.astype(np.int8).tobytes())
        self.feedback.frombytes(closeness.astype(np.float64).tobytes())
        blank = len(codes) * len(self.actions)
        self.next_row.frombytes(np.full(blank, -1, dtype=np.int32).tobytes())
        self.blocker.frombytes(np.zeros(blank, dtype=np.int32).tobytes())

    # -- reading ---------------------------------------------------------------

    def next_array(self) -> Int32Array:
        """``next_row`` as a ``(rows, actions)`` numpy view (valid until the table grows)."""
        return np.frombuffer(self.next_row, dtype=np.int32).reshape(-1, len(self.actions))

    def blocker_array(self) -> Int32Array:
        """``blocker`` as a ``(rows, actions)`` numpy view (valid until the table grows)."""
        return np.frombuffer(self.blocker, dtype=np.int32).reshape(-1, len(self.actions))

    def positions_of(self, row: int) -> FloatArray:
        """``(n + 1, 2)`` the base and every link tip of a row (a read-only copy)."""
        width = self.width
        positions = np.frombuffer(self.positions[row * width : (row + 1) * width])
        positions.flags.writeable = False
        return positions.reshape(-1, 2)

    def distances_of(self, row: int) -> FloatArray:
        """``(n, m)`` from every tip of a row to every obstacle's surface (a read-only copy),
        computed now when the row's pose was added alone or the rows keep no distances."""
        n, m = self.geometry.n, self.geometry.m
        if not self.keeps_distances:
            distances = self._compute_distances(row)
        else:
            distances = np.frombuffer(self.distances[row * n * m : (row + 1) * n * m])
            if m and math.isnan(distances[0]):
                distances = self._compute_distances(row)
                self.distances[row * n * m : (row + 1) * n * m] = array.array(
                    "d", distances.tobytes()
                )
        distances.flags.writeable = False
        return distances.reshape(n, m)

    def _compute_distances(self, row: int) -> FloatArray:
        tips = self.positions_of(row)[1:]
        return geometry.obstacle_distances(tips, self.geometry.centers, self.geometry.radii)

    def truth_values(self, row: int) -> tuple[list[int], list[float], list[float]]:
        """A row's joint angles, its points (``x0, y0, x1, y1, ...``: :meth:`positions_of`
        flat) and its obstacle distances (tip by tip: :meth:`distances_of` flat), as plain
        Python numbers (what a recorder encodes once per pose, without numpy's per-call work)."""
        n_m = self.geometry.n * self.geometry.m
        kept = self.distances[row * n_m : (row + 1) * n_m] if self.keeps_distances else None
        if n_m and (kept is None or math.isnan(kept[0])):
            distances: list[float] = self.distances_of(row).ravel().tolist()
        else:
            distances = kept.tolist() if kept is not None else []
        positions = self.positions[row * self.width : (row + 1) * self.width].tolist()
        return self.angles_of(self.codes[row]), positions, distances

    def angles(self) -> IntArray:
        """``(rows, n)`` joint angles of every row."""
        codes = np.frombuffer(self.codes, dtype=np.int64)
        return np.asarray((codes[:, None] // self.radix) % 360, dtype=np.int64)

    def sensations(self) -> BoolArray:
        """The boolean sensation of every row."""
        return np.frombuffer(self.sensation, dtype=np.int8).astype(bool)
