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

STATE: Colour = (60, 60, 60)
"""A state of the model drawn on the world, when the truth audit says nothing of it."""
STATE_EXACT: Colour = (30, 150, 60)
"""A state that stood for one true class no other state of its version stood for."""
STATE_REDUNDANT: Colour = (140, 80, 200)
"""A state that stood for one true class that other states of its version stood for too."""
STATE_ALIASED: Colour = (215, 30, 120)
"""A state that stood for several true classes."""
STATE_UNVISITED: Colour = (175, 175, 175)
"""A state its version was never in."""
