"""The contract between the step records and the model messages (docs/contract.md).

A recording holds the agent's internal state twice: in every step record and, implicitly, as
the current state of the model. The contract ties them together, step by step:

- ``model-version``: a step names the model version in force at its end (the last model
  message at or before it);
- ``state-in-model``: its internal state is a state of that version;
- ``state-chain``: a step starts where the step before it ended (``state_before`` of step
  ``t`` is the internal state of step ``t - 1``);
- ``versions-in-order``: model versions grow from one message to the next;
- ``model-current``: a model message's own current state is the internal state of the step it
  was written at (the last message of a step; an earlier one of the same step was replaced
  within it);
- ``log-time``: a step message is logged at step x 1,000,000 ns (what tools that plot by
  log time, Foxglove and Rerun's importer, rely on);
- ``event-in-range``: an event names a step of the recording.

(A model or event message whose log time disagrees with its step, and a channel whose message
count differs from the summary's, are refused by the reader itself.)

``Recording.model_at(t)`` takes its structure from the model message in force and its current
state from the step record (``model-version`` and ``state-in-model`` are what make that state
one the version has); ``model-current`` checks the one place where the file says the current
state twice. An audit can read a state id as what its version says. :func:`check_contract`
checks every step with numpy (no per-step Python), and reports each broken rule once, at its
first step.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
import pandas as pd

from rsstp_format.records import ModelRecord
from rsstp_format.schemas import STEP_NS
from rsstp_replay.reader import version_alive, version_heads
from rsstp_sim.words import counted

__all__ = ["ContractFindings", "ContractSource", "Violation", "check_contract", "version_index"]

_Ints = npt.NDArray[np.int64]


class ContractSource(Protocol):
    """What the contract check reads of a recording."""

    def steps(self, *, geometry: bool = True) -> pd.DataFrame: ...
    def step_log_times(self) -> _Ints: ...
    def model_versions(self) -> Sequence[ModelRecord]: ...
    def events(self) -> pd.DataFrame: ...


@dataclass(frozen=True, slots=True)
class Violation:
    """A broken rule: its name, the first step that breaks it, how many steps (or ``counted``
    things) do, and why."""

    rule: str
    step: int
    count: int
    text: str
    counted: str = "step"


@dataclass(frozen=True, slots=True)
class ContractFindings:
    """The contract check of a recording of ``steps`` steps."""

    steps: int
    violations: tuple[Violation, ...]

    @property
    def holds(self) -> bool:
        return not self.violations

    def to_text(self) -> str:
        if self.holds:
            return f"contract: holds at every one of the {counted(self.steps + 1, 'step')}"
        lines = [f"contract: {len(self.violations)} rule(s) broken"]
        lines += [
            f"  {v.rule}: from step {v.step:,} ({v.count:,} {v.counted}(s)): {v.text}"
            for v in self.violations
        ]
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        return {
            "holds": self.holds,
            "violations": [
                {
                    "rule": v.rule,
                    "step": v.step,
                    "count": v.count,
                    "counted": v.counted,
                    "text": v.text,
                }
                for v in self.violations
            ],
        }


def version_index(versions: Sequence[ModelRecord], steps: _Ints) -> _Ints:
    """For each step, the index in ``versions`` of the model message in force at its end (the
    last at or before it; -1 before the first message)."""
    heads = version_heads(versions)
    message_steps = np.fromiter((record.step for record in heads), np.int64, len(heads))
    return np.searchsorted(message_steps, steps, side="right").astype(np.int64) - 1


_BLOCK = 1 << 20
"""Steps whose per-step rules :func:`check_contract` checks together: a long run's int64
temporaries stay a few megabytes, not eight bytes a step each."""


def check_contract(source: ContractSource) -> ContractFindings:
    """Check every step against the model messages (see the module docstring)."""
    table = source.steps(geometry=False)
    history = source.model_versions()
    versions = version_heads(history)
    n = len(table)
    steps = _Steps(table.index)
    state_column = table["internal_state"].to_numpy()
    named_column = table["model_version"].to_numpy()
    before_column = table["state_before"]
    found: list[Violation] = []

    def ints(column: npt.NDArray[Any], rows: slice) -> _Ints:
        return column[rows].astype(np.int64)

    def before_at(rows: slice) -> _Ints:
        return before_column.iloc[rows].to_numpy(np.int64, na_value=-1)

    numbers = np.fromiter((record.version for record in versions), np.int64, len(versions))
    backwards = np.flatnonzero(np.diff(numbers) <= 0)
    if len(backwards):
        at = int(backwards[0]) + 1
        found.append(
            Violation(
                "versions-in-order",
                versions[at].step,
                len(backwards),
                f"model version {numbers[at]} follows version {numbers[at - 1]}",
            )
        )

    # The per-step rules, a block of steps at a time: each rule's first bad step and count.
    log_times = source.step_log_times()
    bad: dict[str, list[_Ints]] = {rule: [] for rule in _STEP_RULES}
    for start in range(0, n, _BLOCK):
        stop = min(start + _BLOCK, n)
        step = steps.block(start, stop)
        state = ints(state_column, slice(start, stop))
        named = ints(named_column, slice(start, stop))
        index = version_index(versions, step)
        in_force = np.where(index >= 0, numbers[np.maximum(index, 0)], -1)
        bad["model-version"].append(np.flatnonzero(named != in_force) + start)
        member = version_alive(history, index, state)
        bad["state-in-model"].append(np.flatnonzero(~member) + start)
        first = max(start, 1)  # step 0 has no state before
        before = before_at(slice(first, stop))
        earlier = ints(state_column, slice(first - 1, stop - 1))
        bad["state-chain"].append(np.flatnonzero(before != earlier) + first)
        bad["log-time"].append(np.flatnonzero(log_times[start:stop] != step * STEP_NS) + start)
    rows = {rule: np.concatenate(parts) if parts else _NONE for rule, parts in bad.items()}

    def version_at(t: int) -> int:  # (a row)
        index = int(version_index(versions, steps.block(t, t + 1))[0])
        return int(numbers[index]) if index >= 0 else -1

    found += _first_of(
        "model-version",
        rows["model-version"],
        steps,
        lambda t: (
            f"step {steps[t]} names model version {named_column[t]}, but the version in "
            f"force is {version_at(t)}"
        ),
    )
    found += _first_of(
        "state-in-model",
        rows["state-in-model"],
        steps,
        lambda t: (
            f"step {steps[t]} is in internal state {state_column[t]}, which is not a state "
            f"of model version {version_at(t)}"
        ),
    )

    message_steps = np.fromiter((record.step for record in versions), np.int64, len(versions))
    currents = np.fromiter((record.current for record in versions), np.int64, len(versions))
    last_of_step = np.r_[message_steps[1:] != message_steps[:-1], True] if len(versions) else []
    row = steps.index.searchsorted(message_steps)
    known = (row < n) & (steps.index.take(np.minimum(row, max(n - 1, 0))) == message_steps)
    checked = np.flatnonzero(np.asarray(last_of_step, np.bool_) & known)
    ended = state_column[row[checked]].astype(np.int64)
    wrong = checked[currents[checked] != ended]
    if len(wrong):
        k = int(wrong[0])
        found.append(
            Violation(
                "model-current",
                int(message_steps[k]),
                len(wrong),
                f"model version {numbers[k]} (step {message_steps[k]:,}) says the current state "
                f"is {currents[k]}, but step {message_steps[k]:,} ends in state "
                f"{state_column[row[k]]}",
                counted="model message",
            )
        )

    found += _first_of(
        "state-chain",
        rows["state-chain"],
        steps,
        lambda t: (
            f"step {steps[t]} starts in state {before_at(slice(t, t + 1))[0]}, but step "
            f"{steps[t - 1]} ended in state {state_column[t - 1]}"
        ),
    )
    found += _first_of(
        "log-time",
        rows["log-time"],
        steps,
        lambda t: f"step {steps[t]} is logged at {log_times[t]:,} ns, not {steps[t] * STEP_NS:,}",
    )
    last = int(steps[-1]) if n else 0
    found += _event_steps(source.events(), last)
    found.sort(key=lambda v: v.step)
    return ContractFindings(last, tuple(found))


class _Steps:
    """A table's step numbers (its index) by row, a block at a time: a long run's
    ``RangeIndex`` is never made an array whole."""

    def __init__(self, index: pd.Index) -> None:
        self.index = index

    def block(self, start: int, stop: int) -> _Ints:
        return self.index[start:stop].to_numpy(np.int64)

    def __getitem__(self, row: int) -> int:
        return int(self.index[row])


_STEP_RULES = ("model-version", "state-in-model", "state-chain", "log-time")
_NONE = np.empty(0, np.int64)


def _first_of(
    rule: str, bad: _Ints, step: _Ints | _Steps, text: Callable[[int], str]
) -> list[Violation]:
    """One violation of ``rule`` for the steps at the rows ``bad``: the first, described by
    ``text(row)``, and how many there are."""
    if not len(bad):
        return []
    t = int(bad[0])
    return [Violation(rule, int(step[t]), len(bad), text(t))]


def _event_steps(events: pd.DataFrame, last_step: int) -> list[Violation]:
    steps = events["step"].to_numpy(np.int64)
    outside = np.flatnonzero((steps < 0) | (steps > last_step))
    if not len(outside):
        return []
    at = int(steps[outside[0]])
    kind = events["kind"].iloc[int(outside[0])]
    return [
        Violation(
            "event-in-range",
            at,
            len(outside),
            f"a {kind} event names step {at:,}, outside the recording's steps 0 to {last_step:,}",
            counted="event",
        )
    ]
