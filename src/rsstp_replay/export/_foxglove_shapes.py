"""What every body's Foxglove scene builds its messages from: a step's timestamp, a colour, a
turn about z, the steps a body's pose changed at, and those rows as Python numbers."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pandas as pd
from foxglove.messages import Color, Quaternion, Timestamp

from rsstp_format.schemas import STEP_NS
from rsstp_replay.errors import ReplayError
from rsstp_sim import palette

__all__ = ["BLOCK", "WORLD_FRAME", "color", "pose_rows", "step_numbers", "timestamp", "turn"]

WORLD_FRAME = "world"
"""The frame every body's world is drawn in (the plane z = 0)."""

BLOCK = 65_536
"""Poses turned into Python numbers at a time."""


def timestamp(step: int) -> Timestamp:
    """The timestamp of ``step`` (``step * STEP_NS`` ns)."""
    sec, nsec = divmod(step * STEP_NS, 1_000_000_000)
    return Timestamp(sec, nsec)


def color(rgb: palette.Colour, alpha: float = 1.0) -> Color:
    r, g, b = rgb
    return Color(r=r / 255, g=g / 255, b=b / 255, a=alpha)


def turn(angle_deg: float) -> Quaternion:
    """The rotation by ``angle_deg`` about z (counter-clockwise seen from +z), ``w >= 0``."""
    half = math.radians((angle_deg + 180) % 360 - 180) / 2
    return Quaternion(x=0.0, y=0.0, z=math.sin(half), w=math.cos(half))


def step_numbers(steps: pd.DataFrame, *, source: Path) -> npt.NDArray[np.int64]:
    """The step of every row: the steps table's index, named ``step``."""
    if steps.index.name != "step":
        raise ReplayError(f"{source}: the steps table is not indexed by step")
    return steps.index.to_numpy(np.int64)


def pose_rows(
    steps: npt.NDArray[np.int64], codes: npt.NDArray[np.int64]
) -> Iterator[tuple[int, int]]:
    """``(step, pose code)`` of every row as Python numbers, a block at a time."""
    for start in range(0, len(steps), BLOCK):
        block = slice(start, start + BLOCK)
        yield from zip(steps[block].tolist(), codes[block].tolist(), strict=True)
