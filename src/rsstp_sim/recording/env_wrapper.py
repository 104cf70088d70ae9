"""Recording a Gymnasium-driven run: :class:`RecordMcap` wraps an ``rsstp/Arm-v0``
environment and writes every episode to its own recording, in the same format as
``rsstp-sim record`` (agent view and ground truth, events; schemas/README.md).

The agent is whatever calls ``step``: an RL library, a script. It keeps no model unless it
asks for one, and then the recording has no ``/rsstp/model`` channel: its steps are in the
internal state 0, model version 0, the one state of an agent that models nothing (the
replay side reads such a file as having that one-state model). An agent that does keep a
model passes ``model=`` a factory; :attr:`RecordMcap.model` is then the episode's
:class:`~rsstp_sim.transition_system.TransitionSystem`, to refine between steps, and the
recording has the model channel as a strategy's run does: the internal state follows the
model's transitions at each step, and an operation made between two steps is recorded at
the later one.

The recording is written by :class:`~rsstp_sim.recording.Recorder` as a sink: it reads the
environment's own world, and the wrapper hands it each step the environment took
(:meth:`Recorder.taken <rsstp_sim.recording.Recorder.taken>`), so the writer, the crash
safety and the bytes are those of ``rsstp-sim record``, with no second world beside the
environment's.

>>> import gymnasium, tempfile
>>> folder = tempfile.mkdtemp()
>>> env = RecordMcap(gymnasium.make("rsstp_sim:rsstp/Arm-v0", scenario="thesis-roulette"), folder)
>>> _ = env.reset(seed=0)
>>> for _ in range(4):
...     _ = env.step(0)
>>> env.close()
>>> [p.name for p in env.recordings]
['episode-0000.mcap']
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar, SupportsFloat

import gymnasium

from rsstp_sim.env import ArmEnv
from rsstp_sim.errors import EnvError
from rsstp_sim.recording.recorder import DEFAULT_CHUNK_SIZE, Recorder
from rsstp_sim.strategies import AgentView, StrategyBase
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["GymnasiumAgent", "RecordMcap"]

ModelFactory = Callable[[tuple[int, ...]], TransitionSystem]


class GymnasiumAgent(StrategyBase):
    """The strategy of a recorded Gymnasium run: its actions are the environment's, handed to
    the recorder as steps already taken (:meth:`Recorder.taken
    <rsstp_sim.recording.Recorder.taken>`), never chosen here."""

    name: ClassVar[str] = "gymnasium"

    def __init__(self, model: ModelFactory | None = None) -> None:
        self._model = model

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        if self._model is None:
            return super().initial_model(actions)
        return self._model(actions)

    def choose_action(self, agent: AgentView) -> int:
        raise EnvError(
            "a Gymnasium run's actions are the environment's: step the environment, which "
            "hands each step to the recorder"
        )


class RecordMcap(gymnasium.Wrapper[Any, Any, Any, Any]):
    """Write each episode of ``env`` (an ``ArmEnv``, possibly wrapped) to
    ``folder/{name_prefix}-{episode:04d}.mcap``, starting at every ``reset`` and finished at
    the next ``reset`` or at ``close``.

    ``model``: a factory ``actions -> TransitionSystem`` when the agent keeps a model (then
    :attr:`model` is it, and the recording has a model channel), else None. ``force``
    replaces existing recordings; ``chunk_size`` as for ``rsstp-sim record``. The recording's
    seed is the ``reset`` seed (the episode's index when there is none); its strategy is
    :class:`GymnasiumAgent`, named ``gymnasium``. An episode that a strategy ended
    (``terminated`` with ``info["stopped"]``, as a wrapped
    :class:`~rsstp_sim.env_strategy.StrategyPolicy` returns it) ends its recording with the
    stop event of a run the strategy stopped.
    """

    def __init__(
        self,
        env: gymnasium.Env[Any, Any],
        folder: str | Path,
        *,
        name_prefix: str = "episode",
        model: ModelFactory | None = None,
        force: bool = False,
        chunk_size: int = DEFAULT_CHUNK_SIZE,
    ) -> None:
        super().__init__(env)
        if not isinstance(env.unwrapped, ArmEnv):
            raise EnvError(
                f"RecordMcap records rsstp/Arm-v0 environments, not {type(env.unwrapped).__name__}"
            )
        self.folder = Path(folder)
        if not self.folder.is_dir():
            raise EnvError(f"{self.folder}: no such directory for the recordings")
        self.name_prefix = name_prefix
        self._model_factory = model
        self._force = force
        self._chunk_size = chunk_size
        self._recorder: Recorder | None = None
        self.recordings: list[Path] = []
        """The recordings written so far, the current one last."""

    @property
    def model(self) -> TransitionSystem | None:
        """The agent's model in the current episode (None without ``model=``)."""
        if self._model_factory is None or self._recorder is None:
            return None
        return self._recorder.runner.model

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        self._finish()
        observation, info = self.env.reset(seed=seed, options=options)
        episode = len(self.recordings)
        path = self.folder / f"{self.name_prefix}-{episode:04d}.mcap"
        body = self._arm()
        self._recorder = Recorder(
            path,
            body.scenario,
            GymnasiumAgent(self._model_factory),
            seed=episode if seed is None else seed,
            chunk_size=self._chunk_size,
            force=self._force,
            model=self._model_factory is not None,
            world=body.world,
        )
        self.recordings.append(path)
        return observation, info

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        recorder = self._recorder
        if recorder is None:
            raise EnvError("RecordMcap: call reset() before step()")
        observation, reward, terminated, truncated, info = self.env.step(action)
        recorder.taken(int(info["action"]), self._arm().world.last_blocker)
        stopped = info.get("stopped")
        if terminated and isinstance(stopped, str):  # a strategy ended the episode
            recorder.runner.agent.stop(stopped)
        return observation, reward, terminated, truncated, info

    def close(self) -> None:
        self._finish()
        super().close()

    def _finish(self) -> None:
        recorder, self._recorder = self._recorder, None
        if recorder is not None:
            recorder.close()

    def _arm(self) -> ArmEnv:
        arm = self.env.unwrapped
        assert isinstance(arm, ArmEnv)  # checked in __init__
        return arm
