"""A recording read once for several audits.

Decoding a recording's steps is the cost of an audit (a million steps take seconds), and a
command that runs several audits (``rsstp-replay audit --truth``) would otherwise decode them
once per audit, and hold each copy. :func:`load` reads the steps table (without the joint
positions and distances, and without what blocked a move beyond the ``blocked`` flag: no
audit reads them, and they were half the table) and, from a recording, the events and the
model messages in the same read of its chunks (most chunks hold some of each), and builds
the memory;
the memory is built from the table's columns, so nothing is decoded twice, and the table
then reads those columns from the memory. Ten million steps are audited in about 200 bytes
a step. The result has the
methods the audits read, so it is passed to each audit in place of the recording.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
import pandas as pd

from rsstp_format.records import ModelRecord
from rsstp_replay.reader import BLOCKED_COLUMNS
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.memory import Memory

__all__ = ["LoadedRecording", "load"]


class _Source(Protocol):
    def steps(self, *, geometry: bool = True) -> pd.DataFrame: ...
    def step_log_times(self) -> npt.NDArray[np.int64]: ...
    def model_versions(self) -> Sequence[ModelRecord]: ...
    def events(self) -> pd.DataFrame: ...


class LoadedRecording:
    """The steps table, the model messages and the memory of a recording, read once."""

    def __init__(self, source: _Source) -> None:
        self.source = source
        detail = [column for names in BLOCKED_COLUMNS.values() for column in names]
        # A recording reads its steps, events and model messages in one pass over its chunks.
        both = getattr(source, "steps_and_events", None)
        self._events: pd.DataFrame | None = None
        if both is not None:
            table, self._events = both(geometry=False, blockers=False, narrow=True, models=True)
        else:
            table = source.steps(geometry=False)
        table = table.drop(columns=["blocked_kind", *detail], errors="ignore")
        self._models = source.model_versions()
        self._memory = memory = Memory.from_arrays(
            table["action"].to_numpy(table["action"].dtype.numpy_dtype, na_value=-1),
            table["internal_state"].to_numpy(),
            table["sensation"].to_numpy(np.bool_),
            table["feedback"].to_numpy(np.float64),
        )
        # The memory's columns are the table's, value for value: the table reads them from
        # the memory instead of keeping a copy; the joint angles (0 .. 359) take two bytes,
        # the other integer columns (from a recording) the narrowest dtype of their values.
        shared = {
            "internal_state": memory.internal_states,
            "sensation": memory.sensations,
            "feedback": memory.feedback,
        }
        columns: dict[str, Any] = {}
        for name in table.columns:
            if name in shared:
                columns[name] = shared[name]
            elif name.startswith("angle_deg_"):
                columns[name] = table[name].to_numpy(np.int16)
            else:
                columns[name] = table[name].array
        self._steps = pd.DataFrame(columns, index=table.index, copy=False)

    @property
    def scenario(self) -> Scenario:
        scenario: Scenario = getattr(self.source, "scenario")  # noqa: B009 - not every source
        return scenario

    @property
    def n_steps(self) -> int:
        return len(self._steps) - 1

    def steps(self, *, geometry: bool = True) -> pd.DataFrame:
        """The steps table without the joint positions and distances (``geometry`` is
        ignored: the audits do not read them), ``blocked_kind`` and the blocker's indices;
        the ``angle_deg_{j}`` columns in int16, from a recording the agent's integer columns
        (but ``internal_state``, the memory's) in the narrowest dtype of their values."""
        return self._steps

    def memory(self) -> Memory:
        return self._memory

    def model_versions(self) -> Sequence[ModelRecord]:
        return self._models

    def step_log_times(self) -> npt.NDArray[np.int64]:
        return self.source.step_log_times()

    def events(self) -> pd.DataFrame:
        if self._events is None:
            self._events = self.source.events()
        return self._events


def load(source: _Source) -> LoadedRecording:
    """``source`` read once (itself when it already is)."""
    return source if isinstance(source, LoadedRecording) else LoadedRecording(source)
