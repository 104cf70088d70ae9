"""The rover's world: one pose at a time, every answer read from its :class:`RoverTable`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rsstp_sim.errors import ActionError
from rsstp_sim.rover.scenario import ACTION_NAMES, RoverScenario
from rsstp_sim.rover.table import ROVER_BLOCKER_KINDS, RoverTable

__all__ = ["RoverBlocker", "RoverPose", "RoverWorld"]


@dataclass(frozen=True, slots=True)
class RoverBlocker:
    """Why a rover's move was blocked: ``kind`` one of ``room``, ``obstacle``, ``wall``,
    ``door``; ``indices`` the obstacle's, wall's or door's number in the scenario (empty for
    the room's edge)."""

    kind: str
    indices: tuple[int, ...]

    def describe(self) -> str:
        if self.kind == "room":
            return "the robot would leave the room"
        if self.kind == "door":
            return f"door {self.indices[0]} is one-way, the other way"
        return f"the robot meets {self.kind} {self.indices[0]}"


@dataclass(frozen=True, slots=True)
class RoverPose:
    """One pose: the cell, the heading (degrees), the centre's position, what is sensed."""

    code: int
    sensation: bool
    feedback: float
    cell: tuple[int, int]
    heading_deg: int

    @property
    def position(self) -> tuple[float, float]:
        return (self.cell[0] + 0.5, self.cell[1] + 0.5)


class RoverWorld:
    """A robot on a grid of cells, turned and driven by actions ``0`` forward, ``1`` back,
    ``2`` turn left, ``3`` turn right (restricted to ``scenario.actions``). A blocked move
    leaves the robot where it is and :meth:`move` returns its :class:`RoverBlocker`."""

    def __init__(self, scenario: RoverScenario) -> None:
        self.scenario = scenario
        self.table = RoverTable.of(scenario)
        self._index = {action: k for k, action in enumerate(scenario.actions)}
        self._next = self.table.next_code.ravel().tolist()
        self._blocker_codes = self.table.blocker.ravel().tolist()
        self._n_actions = len(scenario.actions)
        self._poses: dict[int, RoverPose] = {}
        self._code = self.table.start_code
        self._pose = self.pose(self._code)
        self.last_blocker: RoverBlocker | None = None

    def pose(self, code: int) -> RoverPose:
        """The pose of a pose code."""
        pose = self._poses.get(code)
        if pose is None:
            x, y, heading = self.table.values_of(np.array([code]))[0].tolist()
            pose = self._poses[code] = RoverPose(
                code,
                bool(self.table.sensation[code]),
                float(self.table.feedback[code]),
                (x, y),
                heading * self.scenario.turn_deg,
            )
        return pose

    def reset(self) -> RoverPose:
        """Put the robot back at its start cell and heading."""
        self._code = self.table.start_code
        self._pose = self.pose(self._code)
        self.last_blocker = None
        return self._pose

    def move(self, action: int) -> RoverBlocker | None:
        """Execute an action; None when the robot moved (or turned), else why it was blocked."""
        k = self._index.get(action) if action.__class__ is not bool else None
        if k is None:
            names = ", ".join(f"{a} ({ACTION_NAMES[a]})" for a in self._index)
            raise ActionError(f"action {action!r} is not one of the scenario's actions: {names}")
        at = self._code * self._n_actions + k
        code = self._next[at]
        if code != self._code:
            self._code = code
            self._pose = self.pose(code)
        blocker_code = self._blocker_codes[at]
        self.last_blocker = self.blocker_of(blocker_code) if blocker_code else None
        return self.last_blocker

    def blocker_of(self, blocker_code: int) -> RoverBlocker | None:
        """The :class:`RoverBlocker` of a blocker code (None for 0: it moved)."""
        if not blocker_code:
            return None
        if blocker_code == 1:
            return RoverBlocker("room", ())
        s = self.scenario
        index = blocker_code - 2
        kinds = zip(ROVER_BLOCKER_KINDS[1:], (s.obstacles, s.walls, s.doors), strict=True)
        for kind, items in kinds:
            if index < len(items) or kind == "door":
                assert index < len(items), f"no blocker has code {blocker_code}"  # (the table's)
                return RoverBlocker(kind, (index,))
            index -= len(items)
        return None  # pragma: no cover - the loop ends at the doors

    @property
    def current(self) -> RoverPose:
        return self._pose

    @property
    def pose_code(self) -> int:
        return self._code

    @property
    def sensation(self) -> bool:
        return self._pose.sensation

    @property
    def feedback(self) -> float:
        return self._pose.feedback
