"""An arm's frames for the Gymnasium environment's ``rgb_array`` mode (numpy only)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from rsstp_sim import palette
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.arm.world import World
from rsstp_sim.canvas import Canvas

__all__ = ["ArmPicture"]


class ArmPicture:
    """Frames of an arm's scenario: obstacles and feedback points once, the arm per frame."""

    def __init__(self, scenario: Scenario) -> None:
        self.canvas = canvas = Canvas((0.0, 0.0), 1.1 * scenario.total_length)  # it always fits
        for obstacle in scenario.obstacles:
            canvas.disk(
                canvas.background,
                obstacle.center,
                obstacle.radius * canvas.px_per_unit,
                palette.OBSTACLE,
            )
        for point in scenario.feedback_points:
            canvas.disk(canvas.background, point, 6.0, palette.FEEDBACK)
            canvas.disk(canvas.background, point, 3.5, palette.BACKGROUND)

    def draw(self, world: World, *, blocked: bool) -> NDArray[np.uint8]:
        canvas, joint_positions = self.canvas, world.joint_positions
        image = canvas.frame()
        color = palette.ARM_BLOCKED if blocked else palette.ARM
        for k in range(len(joint_positions) - 1):
            canvas.segment(image, joint_positions[k], joint_positions[k + 1], 3.0, color)
        for point in joint_positions:
            canvas.disk(image, point, 4.5, palette.JOINT)
        return image
