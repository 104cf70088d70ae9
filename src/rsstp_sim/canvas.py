"""Frames drawn with numpy alone: disks and thick segments on a white square, the world frame
mapped onto it (+y up). The Gymnasium environment draws each body with it."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rsstp_sim import palette

__all__ = ["SIZE_PX", "Canvas"]

SIZE_PX = 400
"""A frame's width and height (pixels)."""

Point = tuple[float, float] | NDArray[np.float64]


class Canvas:
    """A ``SIZE_PX`` square showing the world box centred on ``center`` with half-width
    ``half_width`` (length units); :attr:`background` is drawn once, a frame on a copy."""

    def __init__(self, center: tuple[float, float], half_width: float) -> None:
        self.center = center
        self.half_width = half_width
        self.px_per_unit = SIZE_PX / (2.0 * half_width)
        self.background = np.empty((SIZE_PX, SIZE_PX, 3), dtype=np.uint8)
        self.background[:] = palette.BACKGROUND

    def to_px(self, xy: Point) -> tuple[float, float]:
        """(column, row) of a world point; rows grow downwards, +y points up."""
        return (
            (float(xy[0]) - self.center[0] + self.half_width) * self.px_per_unit,
            (self.half_width - float(xy[1]) + self.center[1]) * self.px_per_unit,
        )

    def frame(self) -> NDArray[np.uint8]:
        return self.background.copy()

    def disk(
        self, image: NDArray[np.uint8], center: Point, radius_px: float, color: palette.Colour
    ) -> None:
        cx, cy = self.to_px(center)
        rows, cols = _window(image, cx, cy, cx, cy, radius_px)
        if rows is None or cols is None:
            return
        inside = (cols[None, :] + 0.5 - cx) ** 2 + (rows[:, None] + 0.5 - cy) ** 2 <= radius_px**2
        image[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1][inside] = color

    def segment(
        self,
        image: NDArray[np.uint8],
        a: Point,
        b: Point,
        half_width_px: float,
        color: palette.Colour,
    ) -> None:
        ax, ay = self.to_px(a)
        bx, by = self.to_px(b)
        rows, cols = _window(
            image, min(ax, bx), min(ay, by), max(ax, bx), max(ay, by), half_width_px
        )
        if rows is None or cols is None:
            return
        px = cols[None, :] + 0.5
        py = rows[:, None] + 0.5
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        t = ((px - ax) * dx + (py - ay) * dy) / length2 if length2 > 0 else np.zeros(1)
        t = np.clip(t, 0.0, 1.0)
        inside = (px - ax - t * dx) ** 2 + (py - ay - t * dy) ** 2 <= half_width_px**2
        image[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1][inside] = color


def _window(
    image: NDArray[np.uint8], x0: float, y0: float, x1: float, y1: float, margin: float
) -> tuple[NDArray[np.int64] | None, NDArray[np.int64] | None]:
    """Pixel rows and columns of the box ``[x0, x1] x [y0, y1]`` grown by ``margin``, clipped."""
    height, width = image.shape[:2]
    c0, c1 = max(int(np.floor(x0 - margin)), 0), min(int(np.ceil(x1 + margin)), width - 1)
    r0, r1 = max(int(np.floor(y0 - margin)), 0), min(int(np.ceil(y1 + margin)), height - 1)
    if c0 > c1 or r0 > r1:
        return None, None
    return np.arange(r0, r1 + 1, dtype=np.int64), np.arange(c0, c1 + 1, dtype=np.int64)
