"""Test doubles for the replay side: a recording-like object built from a live run, a
strategy that refines its model at random (and counts what it did), and a counter of the
chunks a reader reads.

:class:`FakeRecording` has what the audits read of a
:class:`rsstp_replay.reader.recording.Recording` (``memory()``, ``model_versions()``, ``steps()``,
``events()``, ``model_at(step)``, ``n_steps``), observed through the runner's callbacks the way
the recorder observes a run, so the audits can be tested without an MCAP file.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt
import pandas as pd
import pytest

from rsstp_format import records
from rsstp_format.schemas import STEP_NS
from rsstp_sim import Runner, Scenario, Strategy
from rsstp_sim.memory import Memory
from rsstp_sim.recording import builders
from rsstp_sim.runner import Event
from rsstp_sim.strategies import AgentView, StrategyBase
from rsstp_sim.transition_system import Operation, TransitionSystem


def _angles(angles_deg: Sequence[int]) -> dict[str, int]:
    """A step row's ground-truth joint angles, named as the steps table names them."""
    return {f"angle_deg_{j}": int(a) for j, a in enumerate(angles_deg)}


class FakeRecording:
    """A run of ``strategy`` in ``scenario`` for ``steps`` steps, kept as a recording keeps it.

    ``runner`` is the live runner (its memory and model are the live ones); ``memory()`` is
    rebuilt from the steps table, as a recording rebuilds it from the step messages.
    """

    path = None
    finished = True

    def __init__(self, scenario: Scenario, strategy: Strategy, *, seed: int, steps: int) -> None:
        self._models: list[records.ModelRecord] = []
        self._events: list[records.EventRecord] = []
        self._early: list[tuple[int, Sequence[Operation]]] = []
        self._runner: Runner | None = None
        runner = Runner(
            scenario,
            strategy,
            seed=seed,
            on_event=self._on_event,
            on_model_change=self._on_model_change,
        )
        self._runner = runner
        # Changes at reset are reported before the runner exists; the model is unchanged since.
        for step, operations in self._early:
            self._add_model(step, operations)
        if not self._models:
            self._add_model(0, ())
        memory = runner.memory
        rows: list[dict[str, Any]] = [
            {
                "step": 0,
                "action": None,
                "state_before": None,
                "internal_state": int(memory.internal_states[0]),
                "sensation": bool(memory.sensations[0]),
                "feedback": float(memory.feedback[0]),
                "model_version": runner.model.version,
                "no_transition": False,
                "blocked": False,
                **_angles(runner.world.current.angles_deg),
            }
        ]
        for _ in range(steps):
            if runner.stopped is not None:  # the strategy ended the run
                break
            outcome = runner.step()
            pose = runner.world.current
            if outcome.blocker is not None:
                self._events.append(
                    builders.blocked_event(
                        outcome.step, action=outcome.action, blocker=outcome.blocker
                    )
                )
            rows.append(
                {
                    "step": outcome.step,
                    "action": outcome.action,
                    "state_before": outcome.state_before,
                    "internal_state": outcome.state_after,
                    "sensation": bool(pose.sensation),
                    "feedback": float(pose.feedback),
                    "model_version": runner.model.version,
                    "no_transition": outcome.no_transition,
                    "blocked": outcome.blocker is not None,
                    **_angles(pose.angles_deg),
                }
            )
        self._steps = (
            pd.DataFrame(rows)
            .astype({"step": "int64"})
            .set_index("step")
            .astype(
                {
                    "action": "Int64",
                    "state_before": "Int64",
                    "internal_state": "int64",
                    "sensation": bool,
                    "feedback": "float64",
                    "model_version": "int64",
                    "no_transition": bool,
                    "blocked": bool,
                }
            )
        )

    @property
    def runner(self) -> Runner:
        assert self._runner is not None
        return self._runner

    # -- the runner's callbacks -----------------------------------------------------------

    def _on_model_change(self, step: int, operations: Sequence[Operation]) -> None:
        if self._runner is None:
            self._early.append((step, list(operations)))
        else:
            self._add_model(step, operations)

    def _add_model(self, step: int, operations: Sequence[Operation]) -> None:
        self._models.append(
            builders.model_record(self.runner.model, step=step, operations=operations)
        )
        self._events.extend(builders.operation_events(step, operations))

    def _on_event(self, event: Event) -> None:
        if event.kind == "note":
            self._events.append(builders.note_event(event.step, event.text))

    # -- what a Recording offers ------------------------------------------------------------

    @property
    def n_steps(self) -> int:
        return len(self._steps) - 1

    def steps(self, *, geometry: bool = True) -> pd.DataFrame:
        return self._steps.copy()

    def memory(self) -> Memory:
        steps = self._steps
        return Memory.from_arrays(
            steps["action"].fillna(-1).to_numpy(dtype=np.int64),
            steps["internal_state"].to_numpy(dtype=np.int64),
            steps["sensation"].to_numpy(dtype=bool),
            steps["feedback"].to_numpy(dtype=np.float64),
        )

    def model_versions(self) -> list[records.ModelRecord]:
        return list(self._models)

    def step_log_times(self) -> npt.NDArray[np.int64]:
        return self._steps.index.to_numpy(np.int64) * STEP_NS

    def model_at(self, step: int) -> TransitionSystem:
        record = [model for model in self._models if model.step <= step][-1]
        return TransitionSystem.from_snapshot(record.snapshot(), version=record.version)

    def events(self) -> pd.DataFrame:
        return pd.DataFrame(
            {
                "step": [event.step for event in self._events],
                "kind": [event.kind for event in self._events],
                "text": [event.text for event in self._events],
                "data": [event.data for event in self._events],
            }
        )


class RandomRefiner(StrategyBase):
    """Random actions, and random model operations after each step; ``counts`` holds how many
    operations of each kind actually changed the model (what a summary must report).

    Splits the current state with probability ``split`` (at most ``max_states`` states), adds
    a random transition, deletes a random one, or merges two random states.
    """

    name: ClassVar[str] = "random-refiner"

    def __init__(self, *, split: float = 0.04, max_states: int = 6) -> None:
        self._split = split
        self._max_states = max_states
        self.counts: Counter[str] = Counter()

    def params(self) -> Mapping[str, Any]:
        return {"split": self._split, "max_states": self._max_states}

    def reset(self, agent: AgentView) -> None:
        self.counts = Counter()
        agent.model.split(agent.model.current)  # a change at reset, recorded at step 0
        self.counts["split"] += 1

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]

    def refine(self, agent: AgentView) -> None:
        model, rng = agent.model, agent.rng
        states = model.states
        draw = float(rng.random())
        if draw < self._split and len(states) < self._max_states:
            model.split(model.current)
            self.counts["split"] += 1
        elif draw < 0.15:
            s, t = (states[int(i)] for i in rng.integers(len(states), size=2))
            action = agent.actions[int(rng.integers(len(agent.actions)))]
            if model.add(s, t, action):
                self.counts["add"] += 1
        elif draw < 0.30:
            transitions = model.transitions()
            if transitions:
                s, action, t = transitions[int(rng.integers(len(transitions)))]
                if model.delete(s, t, action):
                    self.counts["delete"] += 1
        elif draw < 0.33 and len(states) > 1:
            first, second = rng.choice(len(states), size=2, replace=False)
            model.merge(states[int(first)], states[int(second)])
            self.counts["merge"] += 1


class StaticRecording:
    """A recording-like object from given model messages and a memory (no run behind it);
    the steps table has no blocked move and no step without a transition."""

    path = None
    finished = True

    def __init__(self, models: Sequence[records.ModelRecord], memory: Memory) -> None:
        self._models = list(models)
        self._memory = memory
        frame = memory.to_dataframe()
        frame["state_before"] = frame["internal_state"].shift(1).astype("Int64")
        frame["model_version"] = np.int64(self._models[-1].version)
        frame["no_transition"] = False
        frame["blocked"] = False
        self._steps = frame

    @property
    def n_steps(self) -> int:
        return self._memory.steps

    def memory(self) -> Memory:
        return self._memory

    def model_versions(self) -> list[records.ModelRecord]:
        return list(self._models)

    def steps(self, *, geometry: bool = True) -> pd.DataFrame:
        return self._steps.copy()

    def step_log_times(self) -> npt.NDArray[np.int64]:
        return np.arange(self._memory.steps + 1, dtype=np.int64) * STEP_NS

    def events(self) -> pd.DataFrame:
        return pd.DataFrame({"step": np.array([], np.int64), "kind": [], "text": [], "data": []})


def count_chunk_reads(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """The file offset of every chunk the reader reads from now on, in order (repeats kept):
    :meth:`Container.chunk_data <rsstp_replay.reader._container.Container.chunk_data>`
    counted, for the rest of the test."""
    from rsstp_replay.reader._container import Container

    reads: list[int] = []
    chunk_data = Container.chunk_data

    def counted(self: Container, stream: Any, ref: Any) -> bytes:
        reads.append(ref.offset)
        return chunk_data(self, stream, ref)

    monkeypatch.setattr(Container, "chunk_data", counted)
    return reads
