"""The colours the world is drawn in: by the Gymnasium environment's frames
(:mod:`rsstp_sim.env`) and by the Rerun viewer (:mod:`rsstp_replay.viewer`), so that a
frame and the viewer read alike. RGB, 0 to 255."""

from __future__ import annotations

Colour = tuple[int, int, int]

BACKGROUND: Colour = (255, 255, 255)
ARM: Colour = (31, 119, 180)
ARM_BLOCKED: Colour = (230, 40, 40)
"""The arm (and, in the viewer, a marker) after a blocked move."""
JOINT: Colour = (40, 40, 40)
OBSTACLE: Colour = (225, 140, 140)
OBSTACLE_EDGE: Colour = (190, 60, 60)
FEEDBACK: Colour = (44, 160, 44)
SENSORS: tuple[Colour, ...] = ((230, 150, 30), (150, 90, 200), (30, 160, 160), (200, 90, 130))
"""One colour per obstacle-distance sensor, in turn."""
