"""The arm's scenario: its links, its obstacles and its feedback point, from TOML.

A scenario file is part of the public contract. Every key is checked at the
boundary; a bad file raises :class:`~rsstp_sim.errors.ScenarioError` whose
message names the file, the key path and what was expected::

    [arm]
    lengths = [3.0, 2.0, 1.0]      # > 0, at most 7 links
    initial_deg = [330, 3, 357]     # integers, one per joint (taken modulo 360)
    step_deg = 5                    # integer in 1..359
    actions = [0, 1, 2, 3, 4, 5]    # optional subset of 0..2n-1 (default: all)
    [[obstacles]]
    center = [1.5, 1.0]
    radius = 0.5                    # > 0
    [feedback]                      # optional (default: the start pose)
    target_deg = [330, 3, 357]      # or: points = [[x, y], ...] one per joint
    mode = "bool"                   # or "float"
    tolerance = 1e-6                # relative to the total arm length
    [motion]
    collision = "swept"             # or "endpoint" (thesis behaviour)
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import ClassVar

from rsstp_format.vocabulary import CollisionMode, FeedbackMode
from rsstp_sim._validation import MISSING, KeyedValidator
from rsstp_sim.arm import geometry
from rsstp_sim.errors import ScenarioError
from rsstp_sim.scenario import MAX_MAGNITUDE, MAX_OBSTACLES, Obstacle

__all__ = ["MAX_JOINTS", "Scenario", "parse_arm"]

_SECTIONS: dict[str, frozenset[str]] = {
    "arm": frozenset({"lengths", "initial_deg", "step_deg", "actions"}),
    "feedback": frozenset({"target_deg", "points", "mode", "tolerance"}),
    "motion": frozenset({"collision"}),
}
_TOP_LEVEL = frozenset({"name", "description", "arm", "obstacles", "feedback", "motion"})
_OBSTACLE_KEYS = frozenset({"center", "radius"})
MAX_JOINTS = 7
"""Most links an arm may have: the world numbers poses as int64 ``sum(angle_i * 360**i)``."""


@dataclass(frozen=True)
class Scenario:
    """A validated world description.

    Angles are integer degrees in ``[0, 360)``; lengths, coordinates and radii
    are in the same (arbitrary) length unit. ``feedback_points[k]`` is where
    the tip of link ``k`` must be for the sensation to be true.
    """

    name: str
    lengths: tuple[float, ...]
    initial_deg: tuple[int, ...]
    step_deg: int
    actions: tuple[int, ...]
    obstacles: tuple[Obstacle, ...]
    feedback_points: tuple[tuple[float, float], ...]
    feedback_target_deg: tuple[int, ...] | None
    feedback_mode: FeedbackMode
    tolerance: float
    collision: CollisionMode
    description: str = ""
    source: str = ""
    origin: str = "<string>"

    body: ClassVar[str] = "arm"

    @property
    def n_joints(self) -> int:
        return len(self.lengths)

    @property
    def total_length(self) -> float:
        return math.fsum(self.lengths)

    @property
    def sha256(self) -> str:
        """Hash of the scenario file's text (what a recording's metadata names)."""
        return hashlib.sha256(self.source.encode("utf-8")).hexdigest()


def parse_arm(data: Mapping[str, object], text: str, origin: str) -> Scenario:
    """Validate a parsed TOML document whose body is ``[arm]``: every key, not the start
    pose's geometry (:func:`~rsstp_sim.arm.table.check_start`, where the world is built)."""
    return _Validator(origin).scenario(data, text)


class _Validator(KeyedValidator):
    def table(self, data: Mapping[str, object], key: str, *, required: bool) -> dict[str, object]:
        value = data.get(key, MISSING)
        if value is MISSING and not required:
            return {}
        if not isinstance(value, dict):
            raise self.fail(f"[{key}]", "a table", value)
        self.unknown_keys(value, _SECTIONS[key], key)
        return value

    def integer(
        self, value: object, key: str, *, low: int | None = None, high: int | None = None
    ) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, "an integer", value)
        if (low is not None and value < low) or (high is not None and value > high):
            bounds = f"an integer in {low}..{high}" if high is not None else f"an integer >= {low}"
            raise self.fail(key, bounds, value)
        return value

    def number(self, value: object, key: str, *, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(key, "a number", value)
        number = float(value)
        if not math.isfinite(number):
            raise self.fail(key, "a finite number", value)
        if abs(number) > MAX_MAGNITUDE:
            raise self.fail(key, f"a number of size at most {MAX_MAGNITUDE:g}", value)
        if positive and number <= 0:
            raise self.fail(key, "a number > 0", value)
        return number

    def array(self, value: object, key: str, *, length: int | None = None) -> Sequence[object]:
        if not isinstance(value, list):
            raise self.fail(key, "an array", value)
        if length is not None and len(value) != length:
            raise self.fail(key, f"an array of {length} (one per joint)", f"{len(value)} items")
        if not value:
            raise self.fail(key, "a non-empty array", value)
        return value

    def point(self, value: object, key: str) -> tuple[float, float]:
        items = self.array(value, key, length=None)
        if len(items) != 2:
            raise self.fail(key, "a point [x, y]", value)
        return (self.number(items[0], f"{key}[0]"), self.number(items[1], f"{key}[1]"))

    def scenario(self, data: Mapping[str, object], text: str) -> Scenario:
        self.unknown_keys(data, _TOP_LEVEL, "")
        arm = self.table(data, "arm", required=True)
        lengths_raw = self.array(arm.get("lengths", MISSING), "arm.lengths")
        lengths = tuple(
            self.number(v, f"arm.lengths[{i}]", positive=True) for i, v in enumerate(lengths_raw)
        )
        n = len(lengths)
        if n > MAX_JOINTS:
            raise self.fail("arm.lengths", f"at most {MAX_JOINTS} links", f"{n} items")
        initial_raw = self.array(arm.get("initial_deg", MISSING), "arm.initial_deg", length=n)
        initial = tuple(
            self.integer(v, f"arm.initial_deg[{i}]") % 360 for i, v in enumerate(initial_raw)
        )
        step = self.integer(arm.get("step_deg", MISSING), "arm.step_deg", low=1, high=359)
        if "actions" in arm:
            actions_raw = self.array(arm["actions"], "arm.actions")
            actions = tuple(
                self.integer(v, f"arm.actions[{i}]", low=0, high=2 * n - 1)
                for i, v in enumerate(actions_raw)
            )
            if len(set(actions)) != len(actions):
                raise self.fail("arm.actions", "distinct actions", list(actions))
            actions = tuple(sorted(actions))
        else:
            actions = tuple(range(2 * n))

        obstacles_raw = data.get("obstacles", [])
        if not isinstance(obstacles_raw, list):
            raise self.fail("obstacles", "an array of tables [[obstacles]]", obstacles_raw)
        if len(obstacles_raw) > MAX_OBSTACLES:
            raise ScenarioError(
                f"{self.origin}: obstacles: expected at most {MAX_OBSTACLES:,} (each step "
                f"measures every joint's distance to each), found {len(obstacles_raw):,}"
            )
        obstacles = []
        for j, entry in enumerate(obstacles_raw):
            where = f"obstacles[{j}]"
            if not isinstance(entry, dict):
                raise self.fail(where, "a table with center and radius", entry)
            self.unknown_keys(entry, _OBSTACLE_KEYS, where)
            center = self.point(entry.get("center", MISSING), f"{where}.center")
            radius = self.number(entry.get("radius", MISSING), f"{where}.radius", positive=True)
            obstacles.append(Obstacle(center, radius))

        feedback = self.table(data, "feedback", required=False)
        target: tuple[int, ...] | None
        if "target_deg" in feedback and "points" in feedback:
            raise ScenarioError(
                f"{self.origin}: feedback: give either target_deg or points, not both"
            )
        if "points" in feedback:
            points_raw = self.array(feedback["points"], "feedback.points", length=n)
            points = tuple(self.point(p, f"feedback.points[{i}]") for i, p in enumerate(points_raw))
            target = None
        else:
            target_raw = self.array(
                feedback.get("target_deg", list(initial)), "feedback.target_deg", length=n
            )
            target = tuple(
                self.integer(v, f"feedback.target_deg[{i}]") % 360 for i, v in enumerate(target_raw)
            )
            tips = geometry.joint_positions(target, lengths)[1:]
            points = tuple((float(x), float(y)) for x, y in tips)
        mode = feedback.get("mode", "bool")
        if mode not in ("bool", "float"):
            raise self.fail("feedback.mode", '"bool" or "float"', mode)
        tolerance = self.number(feedback.get("tolerance", 1e-6), "feedback.tolerance")
        if tolerance < 0:
            raise self.fail("feedback.tolerance", "a number >= 0", tolerance)

        motion = self.table(data, "motion", required=False)
        collision = motion.get("collision", "swept")
        if collision not in ("swept", "endpoint"):
            raise self.fail("motion.collision", '"swept" or "endpoint"', collision)

        name, description = self.name_and_description(data)

        scenario = Scenario(
            name=name,
            lengths=lengths,
            initial_deg=initial,
            step_deg=step,
            actions=actions,
            obstacles=tuple(obstacles),
            feedback_points=points,
            feedback_target_deg=target,
            feedback_mode=mode,
            tolerance=tolerance,
            collision=collision,
            description=description,
            source=text,
            origin=self.origin,
        )
        return scenario
