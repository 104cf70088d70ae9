"""A Gymnasium environment for the world alone: the arm among its obstacles.

:class:`ArmEnv` exposes the :class:`~rsstp_sim.world.World` through the
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

from rsstp_sim import palette
from rsstp_sim.errors import ActionError, EnvError
from rsstp_sim.geometry import Blocker
from rsstp_sim.scenario import Scenario, load_scenario
from rsstp_sim.world import Pose, World

__all__ = ["ENV_ID", "MAX_EPISODE_STEPS", "ArmEnv", "register_envs"]

ENV_ID = "rsstp/Arm-v0"
"""The id under which :func:`register_envs` registers :class:`ArmEnv`."""

_ENTRY_POINT = "rsstp_sim.env:ArmEnv"
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

    - ``scenario``: a :class:`~rsstp_sim.scenario.Scenario`, the name of a built-in
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

    def __init__(
        self,
        scenario: Scenario | str | Path = "three-joint",
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
        loaded = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        if not isinstance(loaded, Scenario):
            raise EnvError(
                f"{loaded.name}: a {loaded.body} has no Gymnasium env yet (its observation and "
                "drawing are the arm's); the Runner runs it"
            )
        self.scenario = loaded
        self.render_mode = render_mode
        self.world = World(self.scenario)
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
            id=ENV_ID,
            entry_point=_ENTRY_POINT,
            kwargs={
                "scenario": scenario,
                "render_mode": render_mode,
                "reward": reward,
                "step_cost": step_cost,
            },
        )
        self._last_blocker: Blocker | None = None
        self._canvas: _Canvas | None = None

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
        if self._canvas is None:
            self._canvas = _Canvas(self.scenario)
        return self._canvas.draw(self.world.joint_positions, blocked=self._last_blocker is not None)

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

    def _observe(self, pose: Pose) -> ArmObs:
        if self._float_mode:
            return np.array([min(max(pose.feedback, 0.0), 1.0)], dtype=np.float32)
        return int(pose.sensation)

    @staticmethod
    def _info(pose: Pose, action: int | None, blocker: Blocker | None) -> dict[str, Any]:
        return {
            "angles_deg": pose.angles_deg,
            "joint_positions": pose.joint_positions.copy(),
            "blocked": blocker is not None,
            "blocked_by": None if blocker is None else blocker.describe(),
            "distances": pose.distances.copy(),
            "sensation": pose.sensation,
            "feedback": pose.feedback,
            "action": action,
        }


def register_envs() -> None:
    """Register :class:`ArmEnv` as ``rsstp/Arm-v0`` with Gymnasium (idempotent), with a
    :data:`MAX_EPISODE_STEPS` time limit."""
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(id=ENV_ID, entry_point=_ENTRY_POINT, max_episode_steps=MAX_EPISODE_STEPS)


# -- rgb_array drawing, numpy only ---------------------------------------------------------

_SIZE_PX = 400


class _Canvas:
    """Pixels of one scenario: the static background once, the arm on a copy per frame."""

    def __init__(self, scenario: Scenario) -> None:
        self.half_width = 1.1 * scenario.total_length  # the arm always fits
        self.px_per_unit = _SIZE_PX / (2.0 * self.half_width)
        background = np.empty((_SIZE_PX, _SIZE_PX, 3), dtype=np.uint8)
        background[:] = palette.BACKGROUND
        for obstacle in scenario.obstacles:
            self._disk(
                background, obstacle.center, obstacle.radius * self.px_per_unit, palette.OBSTACLE
            )
        for point in scenario.feedback_points:
            self._disk(background, point, 6.0, palette.FEEDBACK)
            self._disk(background, point, 3.5, palette.BACKGROUND)
        self.background = background

    def to_px(self, xy: tuple[float, float] | NDArray[np.float64]) -> tuple[float, float]:
        """(column, row) of a world point; rows grow downwards, +y points up."""
        return (
            (float(xy[0]) + self.half_width) * self.px_per_unit,
            (self.half_width - float(xy[1])) * self.px_per_unit,
        )

    def _disk(
        self,
        image: NDArray[np.uint8],
        center: tuple[float, float] | NDArray[np.float64],
        radius_px: float,
        color: tuple[int, int, int],
    ) -> None:
        cx, cy = self.to_px(center)
        rows, cols = _window(image, cx, cy, cx, cy, radius_px)
        if rows is None or cols is None:
            return
        inside = (cols[None, :] + 0.5 - cx) ** 2 + (rows[:, None] + 0.5 - cy) ** 2 <= radius_px**2
        image[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1][inside] = color

    def _segment(
        self,
        image: NDArray[np.uint8],
        a: NDArray[np.float64],
        b: NDArray[np.float64],
        half_width_px: float,
        color: tuple[int, int, int],
    ) -> None:
        ax, ay = self.to_px(a)
        bx, by = self.to_px(b)
        rows, cols = _window(
            image, min(ax, bx), min(ay, by), max(ax, bx), max(ay, by), half_width_px
        )
        if rows is None or cols is None:
            return
        px = cols[None, :] + 0.5
        py = rows[:, None] + 0.5
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        t = ((px - ax) * dx + (py - ay) * dy) / length2 if length2 > 0 else np.zeros(1)
        t = np.clip(t, 0.0, 1.0)
        inside = (px - ax - t * dx) ** 2 + (py - ay - t * dy) ** 2 <= half_width_px**2
        image[rows[0] : rows[-1] + 1, cols[0] : cols[-1] + 1][inside] = color

    def draw(self, joint_positions: NDArray[np.float64], *, blocked: bool) -> NDArray[np.uint8]:
        image = self.background.copy()
        color = palette.ARM_BLOCKED if blocked else palette.ARM
        for k in range(len(joint_positions) - 1):
            self._segment(image, joint_positions[k], joint_positions[k + 1], 3.0, color)
        for point in joint_positions:
            self._disk(image, point, 4.5, palette.JOINT)
        return image


def _window(
    image: NDArray[np.uint8], x0: float, y0: float, x1: float, y1: float, margin: float
) -> tuple[NDArray[np.int64] | None, NDArray[np.int64] | None]:
    """Pixel rows and columns of the box ``[x0, x1] x [y0, y1]`` grown by ``margin``, clipped."""
    height, width = image.shape[:2]
    c0, c1 = max(int(np.floor(x0 - margin)), 0), min(int(np.ceil(x1 + margin)), width - 1)
    r0, r1 = max(int(np.floor(y0 - margin)), 0), min(int(np.ceil(y1 + margin)), height - 1)
    if c0 > c1 or r0 > r1:
        return None, None
    return np.arange(r0, r1 + 1, dtype=np.int64), np.arange(c0, c1 + 1, dtype=np.int64)
