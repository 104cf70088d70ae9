"""A step's scene messages from a pose's encoding and the step's stamp are foxglove-sdk's
encoding of the whole messages, byte for byte (steps where the seconds or the nanoseconds
are zero and where their varints grow; arms of one and seven links)."""

from __future__ import annotations

import pytest
from foxglove.messages import Timestamp

from rsstp_replay.export._foxglove_arm import ArmDrawing as _Drawing
from rsstp_replay.export._foxglove_stamps import PoseMessages
from rsstp_sim import World, load_scenario
from rsstp_sim.scenario import parse_scenario
from scenarios import arm_toml

STEPS = [0, 1, 7, 127, 128, 999, 1000, 1001, 16_384, 123_456, 10_000_000, 2**31 + 5, 10**12]


def seven_links() -> str:
    return arm_toml([1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4], [0, 20, 20, 20, 20, 20, 20], 5)


@pytest.mark.parametrize("name", ["three-joint", "thesis-algo", "seven"])
def test_the_messages_are_the_sdks(name: str) -> None:
    scenario = (
        parse_scenario(seven_links(), origin="seven.toml")
        if name == "seven"
        else load_scenario(name)
    )
    draw = _Drawing(scenario)
    world = World(scenario)
    poses = []
    for move in range(2 * len(STEPS)):
        world.move(scenario.actions[move % len(scenario.actions)])
        poses.append(world.current)
    messages = PoseMessages(
        lambda row: draw.arm(None, poses[row].joint_positions.ravel().tolist()),
        lambda row: draw.links(None, list(poses[row].angles_deg)),
        cached=4,  # the cache is emptied too
    )
    for row, (pose, step) in enumerate(zip(poses, STEPS * 2, strict=True)):
        points = pose.joint_positions.ravel().tolist()
        angles = list(pose.angles_deg)
        sec, nsec = divmod(step * 1_000_000, 1_000_000_000)
        stamp = Timestamp(sec, nsec)
        head, tail, links = messages.at(step, pose.code, row)
        assert head + tail == draw.arm(stamp, points).encode(), step
        assert links == draw.links(stamp, angles).encode(), step
