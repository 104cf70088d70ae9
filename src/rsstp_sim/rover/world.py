"""The rover's world: one pose at a time, every answer read from its :class:`RoverTable`."""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rsstp_format.records import BlockedByRecord, PointRecord, RoverTruthRecord
from rsstp_format.vocabulary import BlockerKind
from rsstp_sim.arrays import BoolArray, FloatArray, IntArray
from rsstp_sim.errors import ActionError, TruthError
from rsstp_sim.interface import PoseMachine
from rsstp_sim.rover.scenario import ACTION_NAMES, RoverScenario
from rsstp_sim.rover.table import ROOM_EDGES, RoverTable

__all__ = ["RoverBlocker", "RoverPose", "RoverWorld", "check_size"]


@dataclass(frozen=True, slots=True)
class RoverBlocker:
    """Why a rover's move was blocked (:data:`~rsstp_sim.interface.BlockerKind`): ``room``
    ``(edge,)`` (0 east, 1 north, 2 west, 3 south), ``obstacle`` ``(0, j)`` (the robot, part 0
    of its body, meets obstacle ``j``), ``wall`` ``(w,)``, ``door`` ``(d,)``."""

    kind: BlockerKind
    indices: tuple[int, ...]

    def describe(self) -> str:
        if self.kind == "room":
            edge = ("east", "north", "west", "south")[self.indices[0]]
            return f"the robot would leave the room by its {edge} edge"
        if self.kind == "door":
            return f"door {self.indices[0]} is one-way, the other way"
        if self.kind == "obstacle":
            return f"the robot meets obstacle {self.indices[1]}"
        return f"the robot meets wall {self.indices[0]}"


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

    def truth_json(self) -> tuple[bytes, bytes]:
        """The pose's members of its ``rsstp.RoverStep`` truth (JSON, keys in schema order),
        before its ``blocked`` field and after it (nothing): what a step's message repeats
        at every visit."""
        x, y = json.dumps(self.position)[1:-1].encode().split(b", ")  # (shortest reprs)
        before = b'"cell":[%d,%d],"heading_deg":%d,"position":{"x":%b,"y":%b},' % (
            self.cell[0], self.cell[1], self.heading_deg, x, y,
        )  # fmt: skip
        return before, b""

    def truth_record(self, blocker: RoverBlocker | None) -> RoverTruthRecord:
        """The truth record of a step ending here (``blocker``: None when it moved)."""
        return RoverTruthRecord(
            cell=self.cell,
            heading_deg=self.heading_deg,
            position=PointRecord.of(self.position),
            blocked=blocker is not None,
            blocked_by=BlockedByRecord.of(blocker),
        )


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

    def walk(self, actions: Sequence[int]) -> tuple[IntArray, IntArray]:
        """Take ``actions`` in order (as :meth:`move` does); the pose code after each move and
        each move's blocker code (0: it moved; :meth:`blocker_of` decodes one)."""
        index, nxt, blocker, width = self._index, self._next, self._blocker_codes, self._n_actions
        codes: list[int] = []
        blocked: list[int] = []
        code = self._code
        for action in actions:
            k = index.get(action) if action.__class__ is not bool else None
            if k is None:
                self.move(action)  # (raises the one-line ActionError)
            at = code * width + k  # type: ignore[operator]  # (k is not None here)
            code = nxt[at]
            codes.append(code)
            blocked.append(blocker[at])
        self._code = code
        self._pose = self.pose(code)
        self.last_blocker = self.blocker_of(blocked[-1]) if blocked else None
        return np.array(codes, np.int64), np.array(blocked, np.int64)

    def blocker_of(self, blocker_code: int) -> RoverBlocker | None:
        """The :class:`RoverBlocker` of a blocker code (None for 0: it moved)."""
        if not blocker_code:
            return None
        if blocker_code <= ROOM_EDGES:
            return RoverBlocker("room", (blocker_code - 1,))
        s = self.scenario
        index = blocker_code - 1 - ROOM_EDGES
        if index < len(s.obstacles):
            return RoverBlocker("obstacle", (0, index))
        index -= len(s.obstacles)
        if index < len(s.walls):
            return RoverBlocker("wall", (index,))
        index -= len(s.walls)
        assert index < len(s.doors), f"no blocker has code {blocker_code}"  # (the table's own)
        return RoverBlocker("door", (index,))

    def follow(self, actions: IntArray, recorded: Any = None) -> tuple[IntArray, IntArray]:
        """From the start pose, the pose code of every step (step 0's: the start) and each
        move's blocker code (0 at step 0) of ``actions[1:]``; ``recorded`` is not needed (a
        rover's walk is one array lookup a move)."""
        self.reset()
        codes, blocked = self.walk(actions[1:].tolist())
        start = np.array([self.table.start_code], np.int64)
        return np.concatenate([start, codes]), np.concatenate([[0], blocked])

    def senses(self) -> tuple[BoolArray, FloatArray]:
        """The sensation and the feedback of every pose code."""
        return self.table.sensation, self.table.feedback

    def truth_at(self, code: int, blocker_code: int) -> RoverTruthRecord:
        """The truth record of a step ending at pose ``code`` after a move blocked by
        ``blocker_code`` (0: it moved)."""
        return self.pose(code).truth_record(self.blocker_of(blocker_code))

    def check_size(self, *, max_poses: int, max_checks: int | None) -> None:
        width, height = self.scenario.room
        check_size(self.scenario.name, width * height * self.scenario.headings, max_poses)

    def machine(self) -> PoseMachine:
        """The world's table's (:meth:`~rsstp_sim.rover.table.RoverTable.machine`)."""
        return self.table.machine()

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


def check_size(name: str, poses: int, max_poses: int) -> None:
    """Refuse the ground truth of the room ``name`` of ``poses`` poses (cells x headings) past
    ``max_poses`` (:meth:`~rsstp_sim.interface.Body.check_size`)."""
    if poses > max_poses:
        raise TruthError(
            f"{name}: the pose space has {poses:,} poses, more than the "
            f"limit of {max_poses:,} (pass a larger max_poses)"
        )
