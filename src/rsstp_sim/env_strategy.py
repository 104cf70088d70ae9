"""A strategy as the policy of a Gymnasium episode, which ends when the strategy stops the run.

:class:`StrategyPolicy` wraps an ``rsstp/Arm-v0`` environment and couples a
:class:`~rsstp_sim.strategies.Strategy` to it: the strategy keeps its memory and model from
the steps the environment takes, exactly as in ``rsstp-sim run`` with the same seed, and
:attr:`StrategyPolicy.action` is the action it chooses for the next step (the index to pass
to ``step``; also ``info["strategy_action"]``). When the strategy ends the run
(:meth:`AgentView.stop <rsstp_sim.strategies.AgentView.stop>`: the learner does when it is
done), ``step`` returns ``terminated=True`` and ``info["stopped"]`` is its reason.

>>> import gymnasium
>>> from rsstp_sim.strategies import LearnerStrategy
>>> env = StrategyPolicy(gymnasium.make("rsstp_sim:rsstp/Arm-v0", scenario="thesis-roulette"),
...                      LearnerStrategy())
>>> _ = env.reset(seed=0)
>>> terminated = truncated = False
>>> while not (terminated or truncated):
...     _, _, terminated, truncated, info = env.step(env.action)
>>> terminated, info["stop"]
(True, 'stopped by the strategy at step 24 of a budget of 1,000')
>>> info["stopped"]
'done: 4 states, every transition confirmed and tested'
"""

from __future__ import annotations

from typing import Any, SupportsFloat

import gymnasium

from rsstp_sim.env import ArmEnv
from rsstp_sim.errors import EnvError, StrategyError
from rsstp_sim.runner import Runner, stop_text
from rsstp_sim.strategies import AgentView, Strategy

__all__ = ["StrategyPolicy"]


class StrategyPolicy(gymnasium.Wrapper[Any, Any, Any, Any]):
    """Couple ``strategy`` to ``env`` (an ``ArmEnv``, possibly wrapped) for every episode.

    - ``reset(seed=s)`` starts the strategy afresh with the run's generator seeded by ``s``
      (the episode's index when there is none): the episode is the run ``rsstp-sim run
      --strategy NAME --seed s`` makes, step for step.
    - :attr:`action`: the index of the action the strategy chooses for the next step (None
      once it ended the run). ``step`` takes that index and no other: the strategy's plan
      rests on its own choices (:class:`~rsstp_sim.errors.EnvError` otherwise).
    - ``step`` returns ``terminated=True`` at the step where the strategy ended the run, with
      ``info["stopped"]`` (its reason) and ``info["stop"]`` ("stopped by the strategy at step
      s", "of a budget of b" when the episode has a time limit of ``b`` steps); a further
      ``step`` before ``reset`` is refused. ``info["strategy_action"]`` is :attr:`action`.
    - :attr:`agent`: the strategy's :class:`~rsstp_sim.strategies.AgentView` (its memory
      and model) in the current episode.

    The strategy sees only actions and sensations (and the float feedback in ``mode =
    "float"``), as in any run; the wrapper follows the environment in a world of its own (the
    world is deterministic; the pose is checked at every step).
    """

    def __init__(self, env: gymnasium.Env[Any, Any], strategy: Strategy) -> None:
        super().__init__(env)
        if not isinstance(env.unwrapped, ArmEnv):
            raise EnvError(
                f"StrategyPolicy couples a strategy to rsstp/Arm-v0 environments, not "
                f"{type(env.unwrapped).__name__}"
            )
        if not isinstance(strategy, Strategy):
            raise EnvError(f"StrategyPolicy needs a strategy, got {type(strategy).__name__}")
        self.strategy = strategy
        self._episodes = 0
        self._runner: Runner | None = None
        self._actions = env.unwrapped.scenario.actions
        self.action: int | None = None

    @property
    def agent(self) -> AgentView:
        """The strategy's view in the current episode."""
        return self._running().agent

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        observation, info = self.env.reset(seed=seed, options=options)
        arm = self.env.unwrapped
        assert isinstance(arm, ArmEnv)  # checked in __init__
        self._runner = Runner(
            arm.scenario,
            self.strategy,
            seed=self._episodes if seed is None else seed,
            world=arm.world,
        )
        self._episodes += 1
        return observation, self._told(info)

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        runner = self._running()
        if runner.stopped is not None:
            raise EnvError(
                f"the strategy ended the episode at step {runner.step_index:,} "
                f"({runner.stopped}): call reset()"
            )
        proposed = self.action
        if proposed is None or action != proposed:
            raise EnvError(
                f"step {runner.step_index + 1:,}: the strategy chose action index "
                f"{proposed}, step() was given {action!r} (pass StrategyPolicy.action)"
            )
        observation, reward, terminated, truncated, info = self.env.step(action)
        runner.taken(int(info["action"]), runner.world.last_blocker)
        info = self._told(info)
        return observation, reward, terminated or runner.stopped is not None, truncated, info

    def _told(self, info: dict[str, Any]) -> dict[str, Any]:
        """``info`` with the strategy's next action, and its reason if it ended the run."""
        runner = self._running()
        info = dict(info)
        if runner.stopped is None:
            chosen = self.strategy.choose_action(runner.agent)
            if chosen not in self._actions:
                raise StrategyError(
                    f"strategy {self.strategy.name!r} at step {runner.step_index + 1:,}: "
                    f"action {chosen!r} is not one of the scenario's {list(self._actions)}"
                )
            self.action = self._actions.index(chosen)
        else:
            self.action = None
            spec = self.env.spec
            budget = None if spec is None else spec.max_episode_steps
            info["stopped"] = runner.stopped
            info["stop"] = stop_text(runner.step_index, budget)
        info["strategy_action"] = self.action
        return info

    def _running(self) -> Runner:
        if self._runner is None:
            raise EnvError("StrategyPolicy: call reset() before step()")
        return self._runner
