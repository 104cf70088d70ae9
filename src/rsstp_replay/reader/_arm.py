"""The arm's steps into columns: its angles, and the joint positions and obstacle distances
the file holds for each pose.

The joint positions and obstacle distances of an arm's step depend on its pose alone, and
parsing their floats is most of the cost of a step, so a batch is decoded without them, and
only the first message of each pose met is decoded whole: the table's numbers of a pose are
that message's, what the file holds. Whether they are what the scenario's geometry gives, and
the same at every visit, is the physics check's business (``rsstp-replay check --physics``),
so a recording written before a geometry fix still opens, and that check names the first
step that differs.
"""

from __future__ import annotations

from itertools import chain
from typing import Any

import msgspec
import numpy as np
import numpy.typing as npt
import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_format.records import json_array
from rsstp_format.vocabulary import BlockerKind
from rsstp_replay.errors import BadStep, ReplayError
from rsstp_replay.reader._decode import (
    Agent,
    Angle,
    BlockedBy,
    Count,
    Point,
    check_lengths,
    describe,
)

__all__ = ["ARM"]


class _Distances(msgspec.Struct, gc=False):
    obstacles: list[float]


class _Truth(msgspec.Struct, gc=False, kw_only=True):
    angles_deg: list[Angle]
    joint_positions: list[Point]
    blocked: bool
    blocked_by: BlockedBy | None = None  # absent when the arm moved
    distances: list[_Distances]


class _Step(msgspec.Struct, gc=False):
    step: Count
    agent: Agent
    truth: _Truth


class _PoseTruth(msgspec.Struct, gc=False):
    """The ground truth of a step without the numbers that follow from its angles (skipped by
    the parser, not built)."""

    angles_deg: list[Angle]
    blocked: bool
    blocked_by: BlockedBy | None = None


class _PoseStep(msgspec.Struct, gc=False):
    step: Count
    agent: Agent
    truth: _PoseTruth


_BATCH = msgspec.json.Decoder(list[_PoseStep])
_ONE = msgspec.json.Decoder(_Step)
_WHOLE_STEPS = msgspec.json.Decoder(list[_Step])
"""Whole step messages, many in one call (the first message of each pose met)."""


class _ArmColumns:
    """An arm's angles, and the numbers of each pose met (see the module docstring)."""

    batch = _BATCH
    one = _ONE

    def __init__(self, n_rows: int, n_joints: int, n_obstacles: int, *, numbers: bool) -> None:
        self.n_joints = n_joints
        self.n_obstacles = n_obstacles
        self.numbers = numbers
        # One row per column, so each DataFrame column is a contiguous array; an angle
        # (0 .. 359) takes two bytes.
        self.angles_deg = np.empty((n_joints, n_rows), np.int16)
        # A pose's code -> x0, y0, x1, y1, ... then the distances tip by tip, as the first
        # message at that pose holds them.
        self.pose_numbers: dict[int, list[float]] = {}
        self._met = np.zeros(0, np.int64)
        self._places = 360 ** np.arange(n_joints, dtype=np.int64)

    def add(self, truths: list[Any], rows: slice, parts: list[memoryview]) -> None:
        k, n = len(truths), self.n_joints
        angles = [t.angles_deg for t in truths]
        check_lengths(angles, n, "truth.angles_deg", "angles")
        flat = np.fromiter(chain.from_iterable(angles), np.int64, k * n)
        self.angles_deg[:, rows] = flat.reshape(k, n).T
        if self.numbers:
            self._read_numbers(parts, flat.reshape(k, n))

    def _read_numbers(self, parts: list[memoryview], angles: npt.NDArray[np.int64]) -> None:
        """The positions and distances of every pose of this batch not met before, from its
        first message here: those messages decoded whole, in one call."""
        codes = angles @ self._places
        met = self._met  # the codes of the poses read so far, sorted
        if len(met):
            at = np.minimum(np.searchsorted(met, codes), len(met) - 1)
            unmet = np.flatnonzero(met[at] != codes)
            if not len(unmet):
                return
        else:
            unmet = np.arange(len(codes))
        fresh, first = np.unique(codes[unmet], return_index=True)
        self._met = np.insert(met, np.searchsorted(met, fresh), fresh)
        indices = unmet[first].tolist()
        new = fresh.tolist()
        try:
            truths = [
                step.truth for step in _WHOLE_STEPS.decode(json_array([parts[i] for i in indices]))
            ]
        except msgspec.DecodeError:
            truths = []
            for index in indices:  # which one, and why
                try:
                    truths.append(_ONE.decode(parts[index]).truth)
                except msgspec.DecodeError as exc:
                    raise BadStep(describe(exc), index=index) from None
        n, m = self.n_joints, self.n_obstacles
        known = self.pose_numbers
        for code, index, truth in zip(new, indices, truths, strict=True):
            if len(truth.joint_positions) != n + 1:
                found = len(truth.joint_positions)
                raise BadStep(
                    f"truth.joint_positions: expected {n + 1} points, found {found}", index=index
                )
            rows = [tip.obstacles for tip in truth.distances]
            if len(rows) != n:
                raise BadStep(
                    f"truth.distances: expected {n} entries (one per tip), found {len(rows)}",
                    index=index,
                )
            if any(len(row) != m for row in rows):
                raise BadStep(f"truth.distances: expected {m} obstacles per tip", index=index)
            numbers = [v for p in truth.joint_positions for v in (p.x, p.y)]
            for row in rows:
                numbers += row
            known[code] = numbers

    def columns(self, part: slice, *, geometry: bool, narrow: bool = False) -> dict[str, Any]:
        columns: dict[str, Any] = {
            f"angle_deg_{j}": self.angles_deg[j, part]
            if narrow
            else self.angles_deg[j, part].astype(np.int64)
            for j in range(self.n_joints)
        }
        if geometry:
            if not self.numbers:
                raise ReplayError("the joint positions were not read (numbers=False)")
            columns |= self._geometry_columns(part)
        return columns

    def _geometry_columns(self, part: slice) -> dict[str, npt.NDArray[np.float64]]:
        """``joint{k}_x``, ``joint{k}_y`` and ``dist_{k}_{j}`` of the rows ``part``: each
        distinct pose's numbers as the file holds them (found by its code,
        ``sum_j angle_j * 360**j``), each column taken whole from those."""
        index, codes = pd.factorize(self._places @ self.angles_deg[:, part].astype(np.int64))
        n, m = self.n_joints, self.n_obstacles
        known = self.pose_numbers
        numbers = np.array([known[code] for code in np.asarray(codes).tolist()], np.float64)
        numbers = numbers.reshape(len(codes), 2 * (n + 1) + n * m)
        positions = numbers[:, : 2 * (n + 1)].reshape(len(codes), n + 1, 2)
        distances = numbers[:, 2 * (n + 1) :].reshape(len(codes), n, m)
        columns = {}
        for k in range(n + 1):
            columns[f"joint{k}_x"] = positions[:, k, 0].take(index)
            columns[f"joint{k}_y"] = positions[:, k, 1].take(index)
        for k in range(n):
            for j in range(m):
                columns[f"dist_{k}_{j}"] = distances[:, k, j].take(index)
        return columns


class _ArmReader:
    """The arm's :class:`~rsstp_replay.reader._decode.BodyReader`."""

    kinds: tuple[BlockerKind, ...] = ("fold", "obstacle", "links")

    def truth_columns(self, n_rows: int, scenario: Any, *, numbers: bool) -> _ArmColumns:
        return _ArmColumns(n_rows, scenario.n_joints, len(scenario.obstacles), numbers=numbers)

    def pose_columns(self, scenario: Any) -> tuple[str, ...]:
        return tuple(f"angle_deg_{j}" for j in range(scenario.n_joints))

    def place_columns(self, scenario: Any) -> tuple[str, str]:
        n = scenario.n_joints
        return (f"joint{n}_x", f"joint{n}_y")

    def shape_difference(self, record: Any, scenario: Any) -> str | None:
        if scenario.n_joints == record.n_joints and len(scenario.obstacles) == len(
            record.obstacles
        ):
            return None
        return (
            f"the /rsstp/scenario message has {record.n_joints} joints and "
            f"{len(record.obstacles)} obstacles, its scenario file {scenario.n_joints} and "
            f"{len(scenario.obstacles)}"
        )


ARM = _ArmReader()
