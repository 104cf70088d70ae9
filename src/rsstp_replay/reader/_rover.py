"""The rover's steps into columns: its cell and heading, and its position (the cell's centre,
which every message must hold)."""

from __future__ import annotations

from itertools import chain
from typing import Annotated, Any

import msgspec
import numpy as np

from rsstp_format.vocabulary import BlockerKind
from rsstp_replay.errors import BadStep
from rsstp_replay.reader._decode import Agent, Angle, BlockedBy, Count, Point

__all__ = ["ROVER"]

POSE_COLUMNS = ("cell_x", "cell_y", "heading_deg")
"""A rover's pose in the steps table: its cell and heading (degrees), the ground truth's
``value_names``."""


class _RoverTruth(msgspec.Struct, gc=False):
    """A rover's ground truth after a step (``rsstp.RoverStep``)."""

    cell: Annotated[list[Count], msgspec.Meta(min_length=2, max_length=2)]
    heading_deg: Angle
    position: Point
    blocked: bool
    blocked_by: BlockedBy | None = None


class _RoverStep(msgspec.Struct, gc=False):
    step: Count
    agent: Agent
    truth: _RoverTruth


class _RoverColumns:
    batch = msgspec.json.Decoder(list[_RoverStep])
    one = msgspec.json.Decoder(_RoverStep)

    def __init__(self, n_rows: int) -> None:
        self.values = np.empty((len(POSE_COLUMNS), n_rows), np.int64)

    def add(self, truths: list[Any], rows: slice, parts: list[memoryview]) -> None:
        """A rover's cell and heading; its position must be its cell's centre."""
        k = len(truths)
        cells = np.fromiter(chain.from_iterable(t.cell for t in truths), np.int64, 2 * k)
        self.values[:2, rows] = cells.reshape(k, 2).T
        self.values[2, rows] = [t.heading_deg for t in truths]
        found = np.array([(t.position.x, t.position.y) for t in truths], np.float64)
        wrong = np.flatnonzero((found != cells.reshape(k, 2) + 0.5).any(axis=1))
        if wrong.size:
            index = int(wrong[0])
            raise BadStep(
                f"truth.position {found[index].tolist()} is not the centre of its cell "
                f"{cells.reshape(k, 2)[index].tolist()}",
                index=index,
            )

    def columns(self, part: slice, *, geometry: bool, narrow: bool = False) -> dict[str, Any]:
        columns: dict[str, Any] = {
            name: values[part] for name, values in zip(POSE_COLUMNS, self.values, strict=True)
        }
        if geometry:
            columns["x"] = self.values[0, part] + 0.5
            columns["y"] = self.values[1, part] + 0.5
        return columns


class _RoverReader:
    """The rover's :class:`~rsstp_replay.reader._decode.BodyReader`."""

    kinds: tuple[BlockerKind, ...] = ("room", "obstacle", "wall", "door")

    def truth_columns(self, n_rows: int, scenario: Any, *, numbers: bool) -> _RoverColumns:
        return _RoverColumns(n_rows)

    def pose_columns(self, scenario: Any) -> tuple[str, ...]:
        return POSE_COLUMNS

    def place_columns(self, scenario: Any) -> tuple[str, str]:
        return ("x", "y")

    def shape_difference(self, record: Any, scenario: Any) -> str | None:
        told = (len(record.obstacles), len(record.rover.walls), len(record.rover.doors))
        given = (len(scenario.obstacles), len(scenario.walls), len(scenario.doors))
        if list(record.rover.room) == list(scenario.room) and told == given:
            return None
        return (
            f"the /rsstp/scenario message has a {record.rover.room[0]} x "
            f"{record.rover.room[1]} room with {told[0]} obstacles, {told[1]} walls and "
            f"{told[2]} doors, its scenario file a {scenario.room[0]} x {scenario.room[1]} "
            f"one with {given[0]}, {given[1]} and {given[2]}"
        )


ROVER = _RoverReader()
