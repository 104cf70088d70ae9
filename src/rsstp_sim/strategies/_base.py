"""The strategy protocol: what a learning strategy sees and may do."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar, Protocol, runtime_checkable

import numpy as np

from rsstp_sim.errors import StrategyError
from rsstp_sim.memory import Memory
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["AgentView", "Strategy", "StrategyBase"]


class AgentView:
    """The agent as a strategy sees it: its own memory and model, nothing of the world.

    - ``memory``: the :class:`~rsstp_sim.memory.Memory` so far (read it, do not write it).
    - ``model``: the internal :class:`~rsstp_sim.transition_system.TransitionSystem`;
      refine it with ``split``, ``merge``, ``add`` and ``delete``; ``model.current``
      is the internal state, which a strategy may also set (re-localisation).
    - ``actions``: the actions the agent may take.
    - ``rng``: the run's seeded generator; the only source of randomness allowed.
    - ``float_feedback``: whether the scenario gives the agent its float feedback
      (``mode = "float"``): then ``memory.feedback`` (closeness to the feedback pose, in
      ``[0, 1]``, 1 there) is the agent's to use; else only the boolean sensations are, the
      float being recorded for the analysis only.
    - ``note(text)``: a strategy note, recorded as an event at the current step.
    - ``enter(phase)``: the strategy's phase from the current step on (``"explore"``,
      ``"home"``...), recorded as a note event whose data says the phase; the audit summary
      gives the share of steps spent in each phase. Entering the phase it is in does nothing.
    - ``stop(reason)``: the strategy ends the run after the current step (its work is done,
      or it cannot go on); the run's ``--steps`` is then a budget it did not use up. The
      runner takes no further step; a recording ends with an event saying why. ``stopped``
      is the reason given, or None.

    Ground truth (angles, positions, blocked moves, obstacle distances) is
    deliberately absent: a strategy learns from actions and sensations only.
    """

    __slots__ = (
        "memory",
        "model",
        "actions",
        "rng",
        "float_feedback",
        "stopped",
        "phase",
        "_notes",
        "_phases",
    )

    def __init__(
        self,
        memory: Memory,
        model: TransitionSystem,
        actions: tuple[int, ...],
        rng: np.random.Generator,
        notes: Callable[[str], None],
        phases: Callable[[str], None] | None = None,
        *,
        float_feedback: bool = False,
    ) -> None:
        self.memory = memory
        self.model = model
        self.actions = actions
        self.rng = rng
        self.float_feedback = float_feedback
        self.stopped: str | None = None
        self.phase: str | None = None
        self._notes = notes
        self._phases = phases

    @property
    def state(self) -> int:
        """The current internal state."""
        return self.model.current

    @property
    def step(self) -> int:
        """The number of steps taken so far (the memory's last entry index)."""
        return len(self.memory) - 1

    def note(self, text: str) -> None:
        self._notes(text)

    def enter(self, phase: str) -> None:
        """From the current step on, the strategy is in ``phase`` (one word, not empty)."""
        if phase == self.phase:
            return
        if not phase or not phase.isidentifier():
            raise StrategyError(f"a phase is one word, got {phase!r}")
        self.phase = phase
        if self._phases is not None:
            self._phases(phase)

    def stop(self, reason: str) -> None:
        """End the run after the current step, for ``reason`` (one line)."""
        if self.stopped is None:
            self.stopped = " ".join(reason.split()) or "no reason given"


@runtime_checkable
class Strategy(Protocol):
    """Decides actions and refines the internal model.

    The runner calls ``initial_model`` and ``reset`` once, then each step
    ``choose_action`` before the move and ``refine`` after the memory entry of
    that step has been written. A strategy ends the run by calling
    :meth:`AgentView.stop` (in ``reset`` or ``refine``): the runner then takes no further
    step. A strategy that never calls it runs the whole budget of steps, as before.
    """

    name: ClassVar[str]

    def params(self) -> Mapping[str, Any]: ...
    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem: ...
    def reset(self, agent: AgentView) -> None: ...
    def choose_action(self, agent: AgentView) -> int: ...
    def refine(self, agent: AgentView) -> None: ...


class StrategyBase:
    """Convenient defaults: the one-state model with a self-loop per action, no refinement.

    A new strategy needs only a ``name`` and ``choose_action``::

        class Clockwise(StrategyBase):
            name = "clockwise"

            def choose_action(self, agent: AgentView) -> int:
                return agent.actions[-1]
    """

    name: ClassVar[str] = "base"

    def params(self) -> Mapping[str, Any]:
        return {}

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        return TransitionSystem.universal(actions)

    def reset(self, agent: AgentView) -> None:
        return None

    def choose_action(self, agent: AgentView) -> int:
        raise NotImplementedError(f"strategy {self.name!r} must implement choose_action")

    def refine(self, agent: AgentView) -> None:
        return None
