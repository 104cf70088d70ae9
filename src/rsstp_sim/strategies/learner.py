"""The ``learner`` strategy: the minimal model of the world, learned from one long trajectory."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from rsstp_sim.errors import StrategyError
from rsstp_sim.strategies._base import AgentView, StrategyBase
from rsstp_sim.strategies._learner_plan import Learning
from rsstp_sim.strategies._learner_walk import Plan
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["LearnerStrategy"]


class LearnerStrategy(StrategyBase):
    """Learns the minimal Moore model of the world, without resets, from actions and sensations.

    It uses nothing but the :class:`~rsstp_sim.strategies.AgentView`: its memory (actions
    and sensations), its model, the actions and the run's generator. The internal states are
    labelled with the sensation they predict (:meth:`labels`); the model keeps one transition
    per (state, action), always. The sensation is true in one world state (the feedback pose):
    seeing it, the agent knows where it is, as a reset would tell it. That state is the
    *landmark*; until it is seen the agent searches with random runs of one action.

    Each transition is *confirmed* (taken and identified) or a *conjecture* (copied by the
    split that created its state). Located at an internal state, the agent walks confirmed
    transitions to the nearest unconfirmed pair, takes it, and identifies the world state it
    reached by ruling candidates out along paths to the landmark: first the paths of the
    candidates the confirmed transitions predict, then *the way back* (the action that undoes
    the one taken, then the known path to the landmark: it reaches the landmark if the state
    is new), then the paths of the candidates left. None left: a new state (``split``); one
    left: that state. Which action undoes which, and which actions commute, are learned from
    the confirmed transitions and only order the tests. A wrong prediction on a confirmed path
    is a counterexample: the landmark serves as the reset of Rivest and Schapire's analysis,
    which finds the wrong transition.
    With boolean feedback, taking moves to be one-to-one (a move that changes the state comes
    from one state only, as the arm's and the rover's do), two states leading by one action to
    a third shown apart from both are merged as one, with their successors (``twins``); a
    candidate that a third state already moves to by the same action is ruled out
    (``implausible``); squares of actions shown not to commute cast no votes; and, lost among at
    most 64 candidates, the agent first takes the move that brings them together.
    When every transition is confirmed the hypothesis is minimised (``merge``), the tests kept
    for each transition are replayed against it and the doubtful ones taken again; then
    :attr:`done` is set and the learner ends the run (``agent.stop``): the recording ends
    there, with an event saying so.

    With float feedback (``mode = "float"``, :attr:`AgentView.float_feedback
    <rsstp_sim.strategies.AgentView.float_feedback>`) the learner climbs the closeness where it
    would search blind, and takes what it feels as part of what it observes: two world states
    felt differently are different poses, so a candidate felt otherwise is ruled out at once
    (in identification, homing, counterexamples and verification), and a test ends where one
    candidate is left that agreed for two steps (the agent is located there, no walk back to the
    landmark). Its states are then poses; the minimisation at the end merges those the
    sensation cannot tell apart, so the model is over the sensation and its truth unchanged.

    With ``stop=False`` it goes on instead, walking its model
    at random, every prediction checked (a refutation resumes learning). ``model.current`` is
    where the agent believes it is.

    Parameters:

    - ``doubts`` (>= 0, default 1): after the way back showed a state is new as far as the
      confirmed transitions tell, how many remaining candidates are still tested one by one;
      more than that and the state is taken as new (merged later if it was not). With float
      feedback felt alike by many states (on average two or more a value felt, as a rover's
      closeness to a region is), 64 at least.
    - ``stop`` (default true): end the run when done; false: walk the model and check it
      until the budget of steps is spent.

    Assumptions: the world is deterministic and strongly connected (every state reaches every
    other, as the arm's reachable poses do, a blocked move being a self-loop), and at most one
    class of states is sensed. The state the run started in is known only if the steps before
    the landmark was first seen single it out (:attr:`start_state`).
    """

    name: ClassVar[str] = "learner"

    def __init__(self, *, doubts: int = 1, stop: bool = True) -> None:
        if isinstance(doubts, bool) or not isinstance(doubts, int) or doubts < 0:
            raise StrategyError(
                f"learner: parameter doubts: expected an integer >= 0 (doubts=2), got {doubts!r}"
            )
        if not isinstance(stop, bool):
            raise StrategyError(
                f"learner: parameter stop: expected true or false (stop=true), got {stop!r}"
            )
        self._doubts = doubts
        self._stop = stop
        self._learning: Learning | None = None
        self._plan: Plan | None = None
        self._next = 0

    def params(self) -> Mapping[str, Any]:
        return {"doubts": self._doubts, "stop": self._stop}

    def initial_model(self, actions: tuple[int, ...]) -> TransitionSystem:
        """One state with a self-loop per action: the conjecture that nothing ever changes."""
        return TransitionSystem.universal(actions)

    def reset(self, agent: AgentView) -> None:
        self._learning = Learning(agent, doubts=self._doubts, stop=self._stop)
        self._plan = self._learning.plan()
        self._next = next(self._plan)

    def choose_action(self, agent: AgentView) -> int:
        return self._next

    def refine(self, agent: AgentView) -> None:
        learning, plan = self._run()
        self._next = plan.send(agent.memory.last_sensation)
        if learning.belief is not None and agent.model.current != learning.belief:
            agent.model.current = learning.belief

    def _run(self) -> tuple[Learning, Plan]:
        if self._learning is None or self._plan is None:
            raise StrategyError("learner: reset(agent) must come first")
        return self._learning, self._plan

    # ------------------------------------------------------------------ results

    @property
    def done(self) -> bool:
        """Every transition confirmed and tested, the model minimal, no refutation since."""
        return self._learning is not None and self._learning.done

    def labels(self) -> dict[int, bool]:
        """The sensation each internal state predicts."""
        learning, _ = self._run()
        if not learning.found:
            return {s: learning.start_sensation for s in learning.agent.model.states}
        return dict(learning.h.labels)

    @property
    def start_state(self) -> int | None:
        """The internal state the run started in, or None if the trajectory leaves it open.

        Judge the model from there: ``check_equivalence(model, labels(), truth,
        start_state=start_state)``; ``model.current`` is where the agent is now.
        """
        return self._run()[0].start_state()

    def stats(self) -> dict[str, int]:
        """Counters: steps per phase, sessions, new states, merges, counterexamples..."""
        return dict(self._run()[0].stats)
