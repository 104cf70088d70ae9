"""The model as a map of an arm's joint space: a cell per pose, coloured by what the model
stood for there.

For an arm of two joints, the map is a grid: joint 0's angle index across (left to right),
joint 1's up (bottom to top), one cell per pose of the arm's lattice
(``360 / gcd(step, 360)`` angles a joint that an action turns, one for another, counted
from its initial angle). For three joints, the same grid for each angle of joint 2 (a
*tile*), the tiles in rows of :func:`tile_columns`, joint 2's angle growing left to right,
then down. A pose the arm cannot be in from its start (a collision, a fold, behind an
obstacle) has no cell: the tile's background shows through (:data:`NO_POSE_COLOR`).

A cell's colour is the role (:mod:`rsstp_replay.audits.state_roles`) of the model states that
stood for its pose's *true class* in the model version at the time cursor, over the steps that
version was in force: **exact** (one state stood for the class, and for it alone), **redundant**
(several states stood for it, none for another class too), **aliased** (a state that stood for
it stood for another class too); the worst of these when several states stood for it
(:func:`~rsstp_replay.audits.class_roles.class_roles`). As on the model drawn on the world,
a class keeps the colour of the last version that visited it (a version of a few hundred
steps visits few classes), and is **unvisited** (grey) until one did. So a model that learned,
on a run that went on visiting, is a green map, and the places where it is still wrong show
where they are in joint space.

Logging: the cells are cut into *blocks* (a row of a tile, or several rows when there would be
more than :data:`MAX_BLOCKS` blocks), one entity each, ``map/cells/{b}``: the cells' places
once (static ``Boxes2D``, drawn filled), their colours (``Boxes2D:colors``) at the first step
shown and then only at the steps where a cell of the block changed colour, with ``send_columns``
and numpy throughout. So the data grows with the changes (times a block's width), not with
versions times cells. The current pose is a ring, ``map/pose``, with a row where it changed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import rerun as rr

from rsstp_replay.audits.class_roles import (
    RoleChanges,
    class_role_changes,
    class_roles,
    model_class_roles,
)
from rsstp_replay.audits.state_roles import (
    ALIASED,
    EXACT,
    REDUNDANT,
    ROLE_NAMES,
    UNVISITED,
)
from rsstp_replay.viewer._chunks import latest_rows, send_rows
from rsstp_sim import palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.truth import GroundTruth

__all__ = [
    "CELLS",
    "MAP",
    "MAP_LEGEND",
    "MAX_BLOCKS",
    "NO_POSE",
    "NO_POSE_COLOR",
    "POSE",
    "RoleChanges",
    "JointGrid",
    "block_path",
    "class_role_changes",
    "model_class_roles",
    "class_roles",
    "joint_grid",
    "log_map",
    "log_map_pose",
    "map_bounds",
]

MAP = "map"
CELLS = "map/cells"
NO_POSE = "map/no_pose"
POSE = "map/pose"
MAP_LEGEND = "map/legend"
MAX_BLOCKS = 128
"""At most this many cell entities: the web viewer's work grows with the entity paths."""
TILE_GAP = 2
"""Empty cells between two tiles of a three-joint map."""
CELL_HALF = 0.45
"""Half a cell's side (the cells are one apart: a thin gap between them)."""
NO_POSE_COLOR = (238, 222, 222)
"""A tile's background: where the arm cannot be (no reachable pose)."""

_ROLE_ORDER = (UNVISITED, EXACT, REDUNDANT, ALIASED)
_Ints = npt.NDArray[np.int64]
_Floats = npt.NDArray[np.float64]


def block_path(block: int) -> str:
    return f"{CELLS}/{block}"


def _packed(color: tuple[int, int, int]) -> int:
    r, g, b = color
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


_ROLE_PACKED = np.zeros(max(_ROLE_ORDER) + 1, np.uint32)
for _role, _color in zip(
    _ROLE_ORDER,
    (palette.STATE_UNVISITED, palette.STATE_EXACT, palette.STATE_REDUNDANT, palette.STATE_ALIASED),
    strict=True,
):
    _ROLE_PACKED[_role] = _packed(_color)
"""A role code's colour (``0xRRGGBBAA``), indexed by the code (``UNVISITED`` is 0)."""


@dataclass(frozen=True, slots=True)
class JointGrid:
    """Where every pose of a two- or three-joint arm's lattice is drawn on the map.

    ``sizes[k]`` angles of joint ``k``, ``spacing_deg`` apart from ``initial_deg[k]``; the
    tiles (one per angle of joint 2; one tile for two joints) in rows of ``columns``."""

    sizes: tuple[int, ...]
    spacing_deg: int
    initial_deg: tuple[int, ...]
    columns: int

    @property
    def n_tiles(self) -> int:
        return self.sizes[2] if len(self.sizes) > 2 else 1

    @property
    def tile_rows(self) -> int:
        return -(-self.n_tiles // self.columns)

    def indexes(self, angles_deg: npt.ArrayLike) -> _Ints:
        """Each pose's angle index per joint: shape ``(P, n_joints)``."""
        angles = np.asarray(angles_deg, np.int64).reshape(-1, len(self.sizes))
        steps = (angles - np.asarray(self.initial_deg, np.int64)) % 360 // self.spacing_deg
        return np.asarray(steps % np.asarray(self.sizes, np.int64), np.int64)

    def tile_origin(self, tile: npt.ArrayLike) -> _Floats:
        """The place of cell ``(0, 0)`` of each tile (map coordinates, y up)."""
        t = np.asarray(tile, np.int64)
        n0, n1 = self.sizes[:2]
        return np.stack(
            [(t % self.columns) * (n0 + TILE_GAP), -(t // self.columns) * (n1 + TILE_GAP)],
            axis=-1,
        ).astype(np.float64)

    def places(self, angles_deg: npt.ArrayLike) -> _Floats:
        """Each pose's cell centre, shape ``(P, 2)`` (map coordinates, y up)."""
        index = self.indexes(angles_deg)
        tile = index[:, 2] if index.shape[1] > 2 else np.zeros(len(index), np.int64)
        return self.tile_origin(tile) + index[:, :2].astype(np.float64)

    def blocks(self, angles_deg: npt.ArrayLike) -> _Ints:
        """Each pose's block (its entity): a tile's rows, ``rows_per_block`` at a time."""
        index = self.indexes(angles_deg)
        tile = index[:, 2] if index.shape[1] > 2 else np.zeros(len(index), np.int64)
        per_tile = -(-self.sizes[1] // self.rows_per_block)
        return np.asarray(tile * per_tile + index[:, 1] // self.rows_per_block, np.int64)

    @property
    def rows_per_block(self) -> int:
        """The fewest rows of a tile per block that keep at most :data:`MAX_BLOCKS` blocks."""
        n1 = self.sizes[1]
        for rows in range(1, n1 + 1):
            if self.n_tiles * -(-n1 // rows) <= MAX_BLOCKS:
                return rows
        return n1


def map_bounds(grid: JointGrid) -> tuple[float, float, float, float]:
    """``x_min, x_max, y_min, y_max`` (map coordinates, y up) of the tiles, their axes' names
    and the legend."""
    n0, n1 = grid.sizes[:2]
    width = grid.columns * (n0 + TILE_GAP)
    bottom = -(grid.tile_rows - 1) * (n1 + TILE_GAP)
    return -0.1 * width - 2.0, 1.45 * width + 2.0, bottom - 4.0, n1 + 3.0


def tile_columns(n_tiles: int) -> int:
    """Tiles per row: a square-ish arrangement."""
    return max(1, math.ceil(math.sqrt(n_tiles)))


def joint_grid(scenario: object) -> JointGrid | None:
    """The map of ``scenario``'s joint space, or None when it has none (not an arm, or an arm
    of other than two or three joints)."""
    if not isinstance(scenario, Scenario) or scenario.n_joints not in (2, 3):
        return None
    spacing = math.gcd(scenario.step_deg, 360)
    turned = {action // 2 for action in scenario.actions}
    sizes = tuple(360 // spacing if k in turned else 1 for k in range(scenario.n_joints))
    n_tiles = sizes[2] if len(sizes) > 2 else 1
    return JointGrid(
        sizes=sizes,
        spacing_deg=spacing,
        initial_deg=tuple(scenario.initial_deg),
        columns=tile_columns(n_tiles),
    )


# ------------------------------------------------------------------------------ logging


def log_map(
    stream: rr.RecordingStream,
    grid: JointGrid,
    truth: GroundTruth,
    changes: RoleChanges,
    *,
    version_steps: dict[int, int],
    first: int,
) -> dict[str, int]:
    """The map (see the module docstring) from step ``first`` on: every cell's colour at
    ``first`` (the changes of the versions at or before it), then at each later version's
    step (``version_steps``: version number to the step it came in at; versions not in it are
    not shown) the blocks where a cell changed colour. Returns rows per entity path (the
    blocks summed under :data:`CELLS`)."""
    _log_static(stream, grid)
    angles = truth.pose_values
    block = grid.blocks(angles)
    order = np.lexsort((np.arange(len(block)), block))  # cells by block
    block, pose_of_cell = block[order], order
    places = grid.places(angles)[pose_of_cell]
    cell_class = np.asarray(truth.true_class, np.int64)[pose_of_cell]
    blocks, starts, widths = np.unique(block, return_index=True, return_counts=True)
    # The class's cells: a class's changes go to every cell of the class.
    by_class = np.argsort(cell_class, kind="stable")
    class_start = np.searchsorted(cell_class[by_class], np.arange(truth.n_classes))
    class_count = np.bincount(cell_class, minlength=truth.n_classes)
    # Each change's step (versions outside ``version_steps`` are dropped), clamped to first.
    known = np.array([v in version_steps for v in changes.versions.tolist()], np.bool_)
    steps = np.array(
        [max(version_steps[v], first) for v in changes.versions[known].tolist()], np.int64
    )
    classes, roles = changes.classes[known], changes.roles[known]
    # Expand to cells: (step, cell, role), in change order.
    counts = class_count[classes]
    within = np.arange(int(counts.sum())) - np.repeat(np.cumsum(counts) - counts, counts)
    cells = by_class[np.repeat(class_start[classes], counts) + within]
    cell_steps, cell_roles = np.repeat(steps, counts), np.repeat(roles, counts)
    cell_block = np.searchsorted(starts, cells, side="right") - 1
    order = np.lexsort((np.arange(len(cells)), cell_block))  # by block, stably
    rows = 0
    bounds = np.searchsorted(cell_block[order], np.arange(len(blocks) + 1))
    for k, b in enumerate(blocks.tolist()):
        mine = order[bounds[k] : bounds[k + 1]]
        colors, times = latest_rows(
            cells[mine] - starts[k],
            cell_steps[mine],
            cell_roles[mine].astype(np.int64),
            width=int(widths[k]),
            first=first,
            initial=UNVISITED,
        )
        path = block_path(b)
        lo, hi = int(starts[k]), int(starts[k] + widths[k])
        stream.log(
            path,
            rr.Boxes2D(
                centers=places[lo:hi],
                half_sizes=np.full((hi - lo, 2), CELL_HALF / 2),
                radii=np.full(hi - lo, CELL_HALF / 2, np.float32),  # a filled square
                draw_order=10.0,
            ),
            static=True,
        )
        rows += send_rows(stream, path, times, _color_columns(_ROLE_PACKED[colors]))
    return {CELLS: rows}


def _color_columns(
    packed: npt.NDArray[np.uint32],
) -> Callable[[slice], rr.ComponentColumnList]:
    """The ``Boxes2D:colors`` column of rows ``rows`` of a block's colour table."""

    def columns(rows: slice) -> rr.ComponentColumnList:
        chosen = packed[rows]
        return rr.Boxes2D.columns(colors=chosen.ravel()).partition(
            np.full(len(chosen), chosen.shape[1])
        )

    return columns


def _log_static(stream: rr.RecordingStream, grid: JointGrid) -> None:
    """The y-up transform, each tile's background (labelled with joint 2's angle for three
    joints), the axes named (under and over the first tile) and the legend (right of the
    tiles)."""
    stream.log(MAP, rr.Transform3D(scale=[1.0, -1.0, 1.0]), static=True)
    n0, n1 = grid.sizes[:2]
    tiles = np.arange(grid.n_tiles)
    origin = grid.tile_origin(tiles)
    half = np.array([n0, n1], np.float64) / 2
    labels = None
    if len(grid.sizes) > 2:
        angles = (grid.initial_deg[2] + tiles * grid.spacing_deg) % 360
        labels = [f"joint 2: {a}°" for a in angles.tolist()]
    stream.log(
        NO_POSE,
        rr.Boxes2D(
            centers=origin + half - 0.5,
            half_sizes=np.tile(half / 2, (len(tiles), 1)),
            radii=np.full(len(tiles), float(min(half)) / 2, np.float32),
            colors=np.tile(NO_POSE_COLOR, (len(tiles), 1)).astype(np.uint8),
            labels=labels,
            draw_order=5.0,
        ),
        static=True,
    )
    # The axes named under and left of the first tile, the legend right of the tiles.
    width = grid.columns * (n0 + TILE_GAP)
    texts = [
        f"joint 0: {grid.initial_deg[0]}° + {grid.spacing_deg}° a cell →",
        f"↑ joint 1: {grid.initial_deg[1]}° + {grid.spacing_deg}° a cell",
    ]
    spots = [(n0 / 2, -2.0), (n0 / 2, n1 + 1.0)]  # under and over the first tile
    colors = [(90, 90, 90), (90, 90, 90)]
    for k, role in enumerate((EXACT, REDUNDANT, ALIASED, UNVISITED)):
        spots.append((width + 0.1 * width, n1 - 1.0 - 2.0 * k))
        colors.append(_unpacked(int(_ROLE_PACKED[role])))
        texts.append(f"{ROLE_NAMES[role]} class")
    spots.append((width + 0.1 * width, n1 - 9.0))
    colors.append(NO_POSE_COLOR)
    texts.append("no pose")
    stream.log(
        MAP_LEGEND,
        rr.Points2D(
            spots,
            colors=colors,
            labels=texts,
            radii=np.full(len(spots), CELL_HALF, np.float32),
            draw_order=30.0,
        ),
        static=True,
    )


def _unpacked(packed: int) -> tuple[int, int, int]:
    return (packed >> 24) & 0xFF, (packed >> 16) & 0xFF, (packed >> 8) & 0xFF


_POSE_COLOR = (235, 100, 0)


def log_map_pose(
    stream: rr.RecordingStream, grid: JointGrid, times: _Ints, angles_deg: _Ints
) -> int:
    """The current pose as a ring on its cell, a row at the first step and where it changed;
    returns the rows logged."""
    if not len(times):
        return 0
    index = grid.indexes(angles_deg)
    change = np.flatnonzero(np.r_[True, (index[1:] != index[:-1]).any(axis=1)])
    places = grid.places(angles_deg[change])
    stream.log(  # the ring's look, once; its place in every row
        POSE,
        rr.Boxes2D.from_fields(
            half_sizes=[(0.6, 0.6)], colors=[_POSE_COLOR], radii=[0.12], draw_order=20.0
        ),
        static=True,
    )
    return send_rows(
        stream, POSE, times[change], lambda rows: rr.Boxes2D.columns(centers=places[rows])
    )
