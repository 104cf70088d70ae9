"""A rover's frames for the Gymnasium environment's ``rgb_array`` mode (numpy only): the room,
its walls (dark), one-way doors (light, with a dot on the side they open to), obstacles and the
feedback region once; the robot and its heading per frame."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from rsstp_sim import palette
from rsstp_sim.canvas import Canvas
from rsstp_sim.rover.scenario import RoverScenario
from rsstp_sim.rover.world import RoverWorld

__all__ = ["RoverPicture"]

_WALL = (60, 60, 60)
_DOOR = (170, 170, 170)


class RoverPicture:
    """Frames of one rover scenario."""

    def __init__(self, scenario: RoverScenario) -> None:
        width, height = scenario.room
        self.canvas = canvas = Canvas((width / 2, height / 2), 0.55 * max(width, height))
        self.scenario = scenario
        image = canvas.background
        corners = [(0.0, 0.0), (width, 0.0), (width, height), (0.0, height), (0.0, 0.0)]
        for a, b in zip(corners, corners[1:], strict=False):
            canvas.segment(image, a, b, 1.5, _WALL)
        region = scenario.feedback_radius * canvas.px_per_unit
        canvas.disk(image, scenario.feedback_center, max(region, 3.0), palette.FEEDBACK)
        for obstacle in scenario.obstacles:
            radius = obstacle.radius * canvas.px_per_unit
            canvas.disk(image, obstacle.center, radius, palette.OBSTACLE)
        for wall in scenario.walls:
            canvas.segment(image, wall.start, wall.end, 2.0, _WALL)
        for door in scenario.doors:
            canvas.segment(image, door.start, door.end, 2.0, _DOOR)
            middle = np.add(door.start, door.end) / 2
            norm = math.hypot(*door.toward) or 1.0
            ahead = middle + 0.3 * np.asarray(door.toward) / norm
            canvas.disk(image, ahead, 2.5, _DOOR)

    def draw(self, world: RoverWorld, *, blocked: bool) -> NDArray[np.uint8]:
        canvas, pose = self.canvas, world.current
        image = canvas.frame()
        color = palette.ARM_BLOCKED if blocked else palette.ARM
        radius = max(self.scenario.robot_radius * canvas.px_per_unit, 5.0)
        canvas.disk(image, pose.position, radius, color)
        angle = math.radians(pose.heading_deg)
        x, y = pose.position
        nose = (x + 0.45 * math.cos(angle), y + 0.45 * math.sin(angle))
        canvas.segment(image, pose.position, nose, 1.5, palette.JOINT)
        return image
