"""The roaming robot: a round robot on a grid of cells among walls, one-way doors and
circular obstacles, turned and driven forward and back, sensing only a feedback region.

Its pose is a cell and a heading in fixed steps; :mod:`~rsstp_sim.rover.table` computes
every pose's moves at once, :mod:`~rsstp_sim.rover.world` answers one move at a time.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rsstp_format.records import (
    DoorRecord,
    PointRecord,
    RegionRecord,
    RoverRecord,
    RoverScenarioRecord,
    SegmentRecord,
)
from rsstp_sim.interface import PoseMachine
from rsstp_sim.rover.picture import RoverPicture
from rsstp_sim.rover.scenario import ACTION_NAMES, RoverScenario, parse_rover
from rsstp_sim.rover.table import RoverTable, check_start
from rsstp_sim.rover.world import RoverBlocker, RoverPose, RoverWorld, check_size

__all__ = ["ACTION_NAMES", "ROVER", "RoverBlocker", "RoverPose", "RoverScenario", "RoverWorld"]


class _Rover:
    """The rover as a body (:class:`~rsstp_sim.interface.Body`)."""

    name = "rover"

    def parse(self, data: Mapping[str, object], text: str, origin: str) -> RoverScenario:
        return parse_rover(data, text, origin)

    def check_start(self, scenario: RoverScenario) -> None:
        check_start(scenario)

    def scenario_record(
        self, scenario: RoverScenario, common: dict[str, Any]
    ) -> RoverScenarioRecord:
        heading, point = scenario.feedback_heading, PointRecord.of
        return RoverScenarioRecord(
            rover=RoverRecord(
                room=scenario.room,
                start=scenario.start,
                heading_deg=scenario.start_heading * scenario.turn_deg,
                turn_deg=scenario.turn_deg,
                radius=float(scenario.robot_radius),
                walls=tuple(
                    SegmentRecord(start=PointRecord.of(w.start), end=PointRecord.of(w.end))
                    for w in scenario.walls
                ),
                doors=tuple(
                    DoorRecord(
                        start=PointRecord.of(d.start),
                        end=PointRecord.of(d.end),
                        toward=PointRecord.of(d.toward),
                    )
                    for d in scenario.doors
                ),
            ),
            feedback=RegionRecord(
                mode=scenario.feedback_mode,
                center=point(scenario.feedback_center),
                radius=float(scenario.feedback_radius),
                heading_deg=None if heading is None else heading * scenario.turn_deg,
            ),
            **common,
        )

    def world(self, scenario: RoverScenario) -> RoverWorld:
        return RoverWorld(scenario)

    def describe(self, scenario: RoverScenario) -> list[str]:
        s = scenario
        names = ", ".join(f"{a} {ACTION_NAMES[a]}" for a in s.actions)
        obstacles = "; ".join(
            f"centre ({o.center[0]:g}, {o.center[1]:g}) radius {o.radius:g}" for o in s.obstacles
        )
        heading = (
            "" if s.feedback_heading is None else f", facing {s.feedback_heading * s.turn_deg} deg"
        )
        return [
            f"  rover: a {s.room[0]} x {s.room[1]} room, start cell {list(s.start)} facing "
            f"{s.start_heading * s.turn_deg} deg; turns of {s.turn_deg} deg; radius "
            f"{s.robot_radius:g}; actions {names}",
            f"  walls: {len(s.walls)}; one-way doors: {len(s.doors)}; obstacles: "
            f"{len(s.obstacles)}" + (f": {obstacles}" if obstacles else ""),
            f"  feedback: {s.feedback_mode} (region centre ({s.feedback_center[0]:g}, "
            f"{s.feedback_center[1]:g}) radius {s.feedback_radius:g}{heading})",
        ]

    def pose_info(self, pose: RoverPose) -> dict[str, Any]:
        """The cell ``(x, y)``, the heading (degrees) and the position (the cell's centre)."""
        return {"cell": pose.cell, "heading_deg": pose.heading_deg, "position": pose.position}

    def picture(self, scenario: RoverScenario) -> RoverPicture:
        return RoverPicture(scenario)

    def warnings(self, scenario: RoverScenario) -> list[str]:
        """A feedback region no reachable pose senses."""
        machine = self.machine(scenario)
        if machine.sensation.any():
            return []
        return [
            "no reachable pose senses the feedback region, every sensation will be false "
            f"(centre {list(scenario.feedback_center)}, radius {scenario.feedback_radius:g})"
        ]

    def check_size(
        self, scenario: RoverScenario, *, max_poses: int, max_checks: int | None
    ) -> None:
        width, height = scenario.room
        check_size(scenario.name, width * height * scenario.headings, max_poses)

    def machine(self, scenario: RoverScenario) -> PoseMachine:
        """Every pose's moves at once (:class:`RoverTable`), then the poses reached from the
        start, breadth first (:meth:`RoverTable.machine`)."""
        return RoverTable.of(scenario).machine()


ROVER = _Rover()
"""The rover, as the body registry (:mod:`rsstp_sim.bodies`) names it."""
