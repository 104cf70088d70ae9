"""A Gymnasium environment for the world alone: the arm among its obstacles.

:class:`ArmEnv` exposes the :class:`~rsstp_sim.arm.world.World` through the
standard ``reset``/``step`` interface, with no internal model, memory or
strategy: those are what a Gymnasium agent brings itself. :func:`register_envs`
makes it available as ``gymnasium.make("rsstp/Arm-v0")``.

>>> env = ArmEnv("thesis-algo")
>>> obs, info = env.reset(seed=0)
>>> obs, info["angles_deg"]
(0, (95,))
>>> for _ in range(5):
...     obs, reward, terminated, truncated, info = env.step(0)  # joint 0, +1 degree
>>> obs, info["angles_deg"], reward, terminated, truncated
(1, (100,), 0.0, False, False)
"""

from __future__ import annotations

import operator
from pathlib import Path
from typing import Any, SupportsFloat

import gymnasium
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import EnvSpec
from numpy.typing import NDArray

from rsstp_sim.bodies import body_of
from rsstp_sim.errors import ActionError, EnvError
from rsstp_sim.interface import Blocker
from rsstp_sim.scenario import AnyScenario, load_scenario

__all__ = ["ENV_ID", "MAX_EPISODE_STEPS", "ROVER_ENV_ID", "ArmEnv", "register_envs"]

ENV_ID = "rsstp/Arm-v0"
"""The id under which :func:`register_envs` registers :class:`ArmEnv`."""

_ENTRY_POINT = "rsstp_sim.env:ArmEnv"
ROVER_ENV_ID = "rsstp/Rover-v0"
"""The id under which :func:`register_envs` registers the rover's env
(:class:`rsstp_sim.rover.env.RoverEnv`)."""
_ENVS = {
    ENV_ID: _ENTRY_POINT,
    ROVER_ENV_ID: "rsstp_sim.rover.env:RoverEnv",
}
"""Env id -> its entry point: one line a body."""
MAX_EPISODE_STEPS = 1000
"""The time limit ``gymnasium.make(ENV_ID)`` puts on an episode (steps)."""
_REWARDS = ("none", "sensation")

ArmObs = int | NDArray[np.float32]
"""An observation: ``0``/``1`` in boolean feedback mode, a ``(1,)`` float32 array in float mode."""


class ArmEnv(gymnasium.Env[ArmObs, np.int64]):
    """A planar arm of ``n`` links moved one joint at a time among circular obstacles.

    ## Description

    The world of the RSSTP platform (thesis chapter 3, ``docs/world.md``)
    with nothing of the agent: the arm's base is at the origin, joint angles are
    integer degrees, and every action turns one joint by the scenario's step.
    A move that would make a link meet an obstacle, two non-adjacent links
    cross, or a link fold back onto its predecessor is *blocked*: the arm stays
    where it is. The agent senses only whether its link tips are at the
    scenario's feedback points (or, in float mode, how close they are).

    ## Action Space

    ``Discrete(len(scenario.actions))``. Index ``i`` means the action id
    ``scenario.actions[i]`` (the scenario's actions are sorted); when the
    scenario uses all ``2n`` actions the index *is* the action id. Action id
    ``a`` turns joint ``a // 2`` by ``+step_deg`` (counter-clockwise) when ``a``
    is even and by ``-step_deg`` (clockwise) when ``a`` is odd.

    | Index | Action id (all actions) | Meaning                              |
    |-------|-------------------------|--------------------------------------|
    | 0     | 0                       | joint 0 turns by +step_deg degrees   |
    | 1     | 1                       | joint 0 turns by -step_deg degrees   |
    | 2k    | 2k                      | joint k turns by +step_deg degrees   |
    | 2k+1  | 2k+1                    | joint k turns by -step_deg degrees   |

    ## Observation Space

    Boolean feedback mode (``[feedback] mode = "bool"``, the default):
    ``Discrete(2)``; ``1`` when every link tip is within the scenario's
    tolerance of its feedback point, else ``0``.

    Float feedback mode (``mode = "float"``): ``Box(0.0, 1.0, (1,), float32)``;
    the closeness ``mean_k (1 - |p_k - f_k| / (|f_k| + L_1 + ... + L_k))``,
    dimensionless, ``1.0`` exactly at the feedback points.

    ## Rewards

    ``reward="none"`` (the default): always ``0.0``; the platform studies what an
    agent can learn from sensations, not reward maximisation.
    ``reward="sensation"``: ``1.0`` at a step that ends with the sensation true (every
    tip at its feedback point), minus ``step_cost`` at every step (default ``0.0``; e.g.
    ``0.01`` rewards reaching the point soon).

    ## Starting State

    The scenario's start pose, always (``reset`` has no randomness; its seed
    only seeds :attr:`np_random`, which the environment does not use).

    ## Episode End

    The environment itself never ends an episode (``terminated`` is ``False``: the
    arm has no terminal pose). ``gymnasium.make("rsstp/Arm-v0")`` wraps it in a
    ``TimeLimit`` of :data:`MAX_EPISODE_STEPS` steps (``truncated`` then); pass
    ``max_episode_steps=N`` to change it, or build ``ArmEnv`` directly for no limit.

    ## Information (ground truth)

    ``info`` holds what the agent is not meant to see, for analysis:

    - ``angles_deg``: tuple of ``n`` relative joint angles, integer degrees in ``[0, 360)``.
    - ``joint_positions``: float64 array ``(n + 1, 2)``, the base then every link tip,
      in the scenario's length unit (a fresh array at every call).
    - ``blocked``: whether the last move was blocked (``False`` after ``reset``).
    - ``blocked_by``: ``None``, or why the move was blocked (``"link 0 meets obstacle 1"``).
    - ``distances``: float64 array ``(n, m)``, distance from tip ``k`` to obstacle
      ``j``'s surface (negative inside), for ``m`` obstacles (a fresh array).
    - ``sensation``: the boolean sensation (whatever the feedback mode).
    - ``feedback``: the float closeness in ``[0, 1]`` (whatever the feedback mode).
    - ``action``: the action id executed (``None`` after ``reset``).

    ## Arguments

    - ``scenario``: a :class:`~rsstp_sim.arm.scenario.Scenario`, the name of a built-in
      scenario, or the path of a scenario file (default ``"three-joint"``).
    - ``render_mode``: ``None`` or ``"rgb_array"`` (a ``(400, 400, 3)`` uint8 picture
      drawn with numpy: obstacles grey, feedback points green, the arm blue, or
      orange just after a blocked move).
    - ``reward``: ``"none"`` or ``"sensation"``, and ``step_cost`` (see Rewards).

    An ``ArmEnv`` built directly carries the same :class:`~gymnasium.envs.registration.EnvSpec`
    that ``gymnasium.make(ENV_ID, scenario=...)`` gives it, so ``env.spec.make()``
    rebuilds it.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 10}
    env_id: str = ENV_ID

    def __init__(
        self,
        scenario: AnyScenario | str | Path = "three-joint",
        *,
        render_mode: str | None = None,
        reward: str = "none",
        step_cost: float = 0.0,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise EnvError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        if reward not in _REWARDS:
            raise EnvError(f"reward must be one of {list(_REWARDS)}, got {reward!r}")
        if isinstance(step_cost, bool) or not isinstance(step_cost, int | float):
            raise EnvError(f"step_cost must be a number, got {step_cost!r}")
        self._reward = reward
        self._step_cost = float(step_cost)
        loaded = scenario if not isinstance(scenario, str | Path) else load_scenario(scenario)
        self.scenario = loaded
        self.render_mode = render_mode
        self._body = body_of(loaded)
        self.world = self._body.world(loaded)
        self._actions = self.scenario.actions
        self.action_space = spaces.Discrete(len(self._actions))
        self._float_mode = self.scenario.feedback_mode == "float"
        observation_space: spaces.Space[Any] = (
            spaces.Box(0.0, 1.0, shape=(1,), dtype=np.float32)
            if self._float_mode
            else spaces.Discrete(2)
        )
        self.observation_space = observation_space
        self.spec = EnvSpec(
            id=self.env_id,
            entry_point=_ENTRY_POINT,
            kwargs={
                "scenario": scenario,
                "render_mode": render_mode,
                "reward": reward,
                "step_cost": step_cost,
            },
        )
        self._last_blocker: Blocker | None = None
        self._picture: Any = None

    # -- the Gymnasium interface -------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[ArmObs, dict[str, Any]]:
        """Put the arm at the scenario's start pose; ``options`` is accepted and unused."""
        super().reset(seed=seed)
        pose = self.world.reset()
        self._last_blocker = None
        return self._observe(pose), self._info(pose, None, None)

    def step(
        self, action: int | np.integer[Any]
    ) -> tuple[ArmObs, SupportsFloat, bool, bool, dict[str, Any]]:
        """Execute the action at index ``action`` (see the class docstring)."""
        action_id = self._actions[self._index(action)]
        blocker = self.world.move(action_id)
        self._last_blocker = blocker
        pose = self.world.current
        reward = 0.0
        if self._reward == "sensation":
            reward = (1.0 if pose.sensation else 0.0) - self._step_cost
        return self._observe(pose), reward, False, False, self._info(pose, action_id, blocker)

    def render(self) -> NDArray[np.uint8] | None:  # type: ignore[override]
        """The current picture (``rgb_array`` mode), or ``None`` without a render mode."""
        if self.render_mode is None:
            return None
        if self._picture is None:
            self._picture = self._body.picture(self.scenario)
        frame: NDArray[np.uint8] = self._picture.draw(
            self.world, blocked=self._last_blocker is not None
        )
        return frame

    # -- helpers -------------------------------------------------------------------------

    def _index(self, action: object) -> int:
        size = len(self._actions)
        try:
            if isinstance(action, bool | np.bool_):
                raise TypeError
            index = operator.index(action)  # type: ignore[arg-type]
        except TypeError:
            raise ActionError(
                f"action must be an integer index in 0..{size - 1} (Discrete({size})), "
                f"got {action!r}"
            ) from None
        if not 0 <= index < size:
            raise ActionError(
                f"action index {index} is not in 0..{size - 1} (Discrete({size}): "
                f"indices of the scenario's actions {list(self._actions)})"
            )
        return index

    def _observe(self, pose: Any) -> ArmObs:
        if self._float_mode:
            return np.array([min(max(pose.feedback, 0.0), 1.0)], dtype=np.float32)
        return int(pose.sensation)

    def _info(self, pose: Any, action: int | None, blocker: Any) -> dict[str, Any]:
        return {
            **self._body.pose_info(pose),
            "pose_code": pose.code,
            "blocked": blocker is not None,
            "blocked_by": None if blocker is None else blocker.describe(),
            "sensation": pose.sensation,
            "feedback": pose.feedback,
            "action": action,
        }


def register_envs() -> None:
    """Register every body's env (:class:`ArmEnv` as ``rsstp/Arm-v0``, the rover's as
    ``rsstp/Rover-v0``) with Gymnasium (idempotent), with a :data:`MAX_EPISODE_STEPS` time
    limit."""
    for env_id, entry_point in _ENVS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id, entry_point=entry_point, max_episode_steps=MAX_EPISODE_STEPS
            )


# -- rgb_array drawing, numpy only ---------------------------------------------------------
