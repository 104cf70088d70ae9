"""The rover as a Gymnasium environment (registered as ``rsstp/Rover-v0`` by
:func:`rsstp_sim.env.register_envs`)."""

from __future__ import annotations

from pathlib import Path

from rsstp_sim.env import ROVER_ENV_ID, ArmEnv
from rsstp_sim.rover.scenario import RoverScenario

__all__ = ["RoverEnv"]


class RoverEnv(ArmEnv):
    """The rover (the second body, ``docs/scenarios.md``) as a Gymnasium environment: the same
    spaces, rewards and episodes as :class:`ArmEnv`, its actions 0 forward, 1 back, 2 turn
    left, 3 turn right, and its ``info`` the rover's ground truth: ``cell`` ``(x, y)``,
    ``heading_deg``, ``position`` (the cell's centre, length units), with ``pose_code``,
    ``blocked``, ``blocked_by``, ``sensation``, ``feedback`` and ``action`` as every body's.
    ``gymnasium.make("rsstp/Rover-v0")`` builds it (default scenario ``rover-room``)."""

    env_id = ROVER_ENV_ID

    def __init__(
        self,
        scenario: RoverScenario | str | Path = "rover-room",
        *,
        render_mode: str | None = None,
        reward: str = "none",
        step_cost: float = 0.0,
    ) -> None:
        super().__init__(scenario, render_mode=render_mode, reward=reward, step_cost=step_cost)
