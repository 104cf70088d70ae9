"""A rover scenario: the room, its walls, doors and obstacles, and the feedback region.

A scenario file picks its body by its table: ``[rover]`` here, ``[arm]`` for the arm
(:mod:`rsstp_sim.scenario`). Every key is checked; a bad file raises
:class:`~rsstp_sim.errors.ScenarioError` naming the file, the key path and what was
expected::

    [rover]
    room = [20, 12]          # width and height in cells, each 1 length unit (1..1000)
    start = [1, 1]           # the start cell [x, y]
    heading_deg = 0          # the start heading: a multiple of turn_deg, 0 = +x
    turn_deg = 90            # 90 (four headings) or 45 (eight)
    radius = 0.25            # the robot's radius, in [0, 0.5)
    actions = [0, 1, 2, 3]   # optional subset: forward, back, turn left, turn right
    [[walls]]                # a wall segment (length units)
    from = [6, 0]
    to = [6, 8]
    [[doors]]                # a one-way door: crossed only moving along `toward`
    from = [12, 0]
    to = [12, 12]
    toward = [1, 0]
    [[obstacles]]
    center = [3.5, 8.5]
    radius = 0.8
    [feedback]
    center = [18.5, 10.5]    # the feedback region, a disk (default: the start cell's centre)
    radius = 0.5             # default 0.5
    heading_deg = 90         # optional: sensed only facing this way
    mode = "bool"            # or "float"
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar, Literal

from rsstp_sim._validation import MISSING, KeyedValidator

__all__ = ["ACTION_NAMES", "MAX_ROOM", "Door", "RoverScenario", "Wall", "parse_rover"]

ACTION_NAMES: tuple[str, ...] = ("forward", "back", "turn left", "turn right")
"""The rover's actions by number."""

MAX_ROOM = 1_000
"""The most cells a room has along each side."""
MAX_ITEMS = 1_000
"""The most walls, doors or obstacles a room has, of each."""
_MAX_MAGNITUDE = 1e6

_ROVER_KEYS = frozenset({"room", "start", "heading_deg", "turn_deg", "radius", "actions"})
_TOP_LEVEL = frozenset({"name", "description", "rover", "walls", "doors", "obstacles", "feedback"})
_FEEDBACK_KEYS = frozenset({"center", "radius", "heading_deg", "mode"})


@dataclass(frozen=True, slots=True)
class Wall:
    """A wall: the segment ``start``-``end`` (length units), closed at both ends."""

    start: tuple[float, float]
    end: tuple[float, float]


@dataclass(frozen=True, slots=True)
class Door:
    """A one-way door: the segment ``start``-``end``, crossed only by a move whose direction
    has a positive component along ``toward``; any other move that meets it is blocked."""

    start: tuple[float, float]
    end: tuple[float, float]
    toward: tuple[float, float]


@dataclass(frozen=True, slots=True)
class RoverObstacle:
    """A circular obstacle: a closed disk."""

    center: tuple[float, float]
    radius: float


@dataclass(frozen=True)
class RoverScenario:
    """A validated rover world. Cell ``(x, y)`` has its centre at ``(x + 0.5, y + 0.5)``;
    heading ``h`` (``0 .. headings - 1``) points ``h * turn_deg`` degrees counter-clockwise
    from +x."""

    name: str
    room: tuple[int, int]
    start: tuple[int, int]
    start_heading: int
    turn_deg: int
    robot_radius: float
    actions: tuple[int, ...]
    walls: tuple[Wall, ...]
    doors: tuple[Door, ...]
    obstacles: tuple[RoverObstacle, ...]
    feedback_center: tuple[float, float]
    feedback_radius: float
    feedback_heading: int | None
    feedback_mode: Literal["bool", "float"]
    description: str = ""
    source: str = ""
    origin: str = "<string>"

    body: ClassVar[str] = "rover"

    @property
    def headings(self) -> int:
        return 360 // self.turn_deg

    @property
    def sha256(self) -> str:
        """Hash of the scenario file's text (what a recording's metadata names)."""
        return hashlib.sha256(self.source.encode("utf-8")).hexdigest()


def parse_rover(data: Mapping[str, object], text: str, origin: str) -> RoverScenario:
    """Validate a parsed TOML document whose body is ``[rover]``."""
    return _Validator(origin).scenario(data, text)


class _Validator(KeyedValidator):
    def integer(self, value: object, key: str, low: int, high: int) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
            raise self.fail(key, f"an integer in {low}..{high}", value)
        return value

    def number(self, value: object, key: str, low: float, high: float) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(key, "a number", value)
        number = float(value)
        if not (math.isfinite(number) and low <= number <= high):
            raise self.fail(key, f"a number in [{low:g}, {high:g}]", value)
        return number

    def pair(self, value: object, key: str) -> Sequence[object]:
        if not isinstance(value, list) or len(value) != 2:
            raise self.fail(key, "a pair [x, y]", value)
        return value

    def point(self, value: object, key: str) -> tuple[float, float]:
        x, y = self.pair(value, key)
        big = _MAX_MAGNITUDE
        return (self.number(x, f"{key}[0]", -big, big), self.number(y, f"{key}[1]", -big, big))

    def items(
        self, data: Mapping[str, object], key: str, keys: frozenset[str]
    ) -> list[dict[str, object]]:
        raw = data.get(key, [])
        if not isinstance(raw, list) or not all(isinstance(item, dict) for item in raw):
            raise self.fail(key, f"an array of tables [[{key}]]", raw)
        if len(raw) > MAX_ITEMS:
            raise self.fail(key, f"at most {MAX_ITEMS:,} tables", f"{len(raw):,}")
        for i, item in enumerate(raw):
            self.unknown_keys(item, keys, f"{key}[{i}]")
        return raw

    def scenario(self, data: Mapping[str, object], text: str) -> RoverScenario:
        self.unknown_keys(data, _TOP_LEVEL, "")
        rover = data["rover"]
        if not isinstance(rover, dict):
            raise self.fail("[rover]", "a table", rover)
        self.unknown_keys(rover, _ROVER_KEYS, "rover")
        width_raw, height_raw = self.pair(rover.get("room", MISSING), "rover.room")
        room = (
            self.integer(width_raw, "rover.room[0]", 1, MAX_ROOM),
            self.integer(height_raw, "rover.room[1]", 1, MAX_ROOM),
        )
        x_raw, y_raw = self.pair(rover.get("start", MISSING), "rover.start")
        start = (
            self.integer(x_raw, "rover.start[0]", 0, room[0] - 1),
            self.integer(y_raw, "rover.start[1]", 0, room[1] - 1),
        )
        turn = rover.get("turn_deg", 90)
        if turn not in (45, 90) or isinstance(turn, bool):
            raise self.fail("rover.turn_deg", "45 or 90", turn)
        assert isinstance(turn, int)
        heading_deg = self.integer(rover.get("heading_deg", 0), "rover.heading_deg", 0, 359)
        if heading_deg % turn:
            raise self.fail("rover.heading_deg", f"a multiple of turn_deg ({turn})", heading_deg)
        radius = self.number(rover.get("radius", 0.25), "rover.radius", 0.0, 0.4999)
        actions_raw = rover.get("actions", [0, 1, 2, 3])
        if not isinstance(actions_raw, list) or not actions_raw:
            raise self.fail("rover.actions", "a non-empty array", actions_raw)
        actions = tuple(
            self.integer(a, f"rover.actions[{i}]", 0, 3) for i, a in enumerate(actions_raw)
        )
        if len(set(actions)) != len(actions):
            raise self.fail("rover.actions", "distinct actions", list(actions))

        walls = tuple(
            Wall(
                self.point(w.get("from", MISSING), f"walls[{i}].from"),
                self.point(w.get("to", MISSING), f"walls[{i}].to"),
            )
            for i, w in enumerate(self.items(data, "walls", frozenset({"from", "to"})))
        )
        doors = []
        for i, d in enumerate(self.items(data, "doors", frozenset({"from", "to", "toward"}))):
            toward = self.point(d.get("toward", MISSING), f"doors[{i}].toward")
            if toward == (0.0, 0.0):
                raise self.fail(f"doors[{i}].toward", "a direction other than [0, 0]", [0, 0])
            doors.append(
                Door(
                    self.point(d.get("from", MISSING), f"doors[{i}].from"),
                    self.point(d.get("to", MISSING), f"doors[{i}].to"),
                    toward,
                )
            )
        obstacles = tuple(
            RoverObstacle(
                self.point(o.get("center", MISSING), f"obstacles[{i}].center"),
                self.number(
                    o.get("radius", MISSING), f"obstacles[{i}].radius", 1e-9, _MAX_MAGNITUDE
                ),
            )
            for i, o in enumerate(self.items(data, "obstacles", frozenset({"center", "radius"})))
        )

        feedback = data.get("feedback", {})
        if not isinstance(feedback, dict):
            raise self.fail("[feedback]", "a table", feedback)
        self.unknown_keys(feedback, _FEEDBACK_KEYS, "feedback")
        center = (
            self.point(feedback["center"], "feedback.center")
            if "center" in feedback
            else (start[0] + 0.5, start[1] + 0.5)
        )
        region = self.number(feedback.get("radius", 0.5), "feedback.radius", 0.0, _MAX_MAGNITUDE)
        sensed_heading: int | None = None
        if "heading_deg" in feedback:
            degrees = self.integer(feedback["heading_deg"], "feedback.heading_deg", 0, 359)
            if degrees % turn:
                raise self.fail("feedback.heading_deg", f"a multiple of turn_deg ({turn})", degrees)
            sensed_heading = degrees // turn
        mode = feedback.get("mode", "bool")
        if mode not in ("bool", "float"):
            raise self.fail("feedback.mode", '"bool" or "float"', mode)

        name, description = self.name_and_description(data)
        return RoverScenario(
            name=name,
            room=room,
            start=start,
            start_heading=heading_deg // turn,
            turn_deg=turn,
            robot_radius=radius,
            actions=tuple(sorted(actions)),
            walls=walls,
            doors=tuple(doors),
            obstacles=obstacles,
            feedback_center=center,
            feedback_radius=region,
            feedback_heading=sensed_heading,
            feedback_mode=mode,  # type: ignore[arg-type]  # (checked above)
            description=description,
            source=text,
            origin=self.origin,
        )
