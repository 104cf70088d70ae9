"""The agent's memory (thesis 4.1) and the thesis's ``compare`` of two sub-memories (4.2).

Entry 0 is written at reset: ``(action=None, internal_state, sensation, feedback)``. Entry ``t``
follows step ``t``: the action ``a_t`` the agent took, the internal state ``s_t`` it moved to, the
boolean sensation ``o_t`` and the float feedback (closeness in ``[0, 1]``) it then received.

The original platform kept the memory in one class-level list shared by every arm and every test
(defect 6); here each :class:`Memory` owns its own numpy buffers.
"""

from __future__ import annotations

import enum
import operator
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, SupportsIndex

import numpy as np
import numpy.typing as npt

from rsstp_sim.errors import MemoryRangeError

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["CompareKind", "CompareResult", "Memory", "MemoryEntry", "NO_ACTION"]

NO_ACTION = -1
"""The value of :attr:`Memory.actions` at entry 0 (the reset has no action)."""

_INT32_MAX = int(np.iinfo(np.int32).max)


class CompareKind(enum.Enum):
    """How two sub-memories relate, decided at their first difference (thesis 4.2)."""

    UNKNOWN = "unknown"
    """The actions differ: the sub-memories say nothing about each other."""
    DIFFERENT_STATE = "different_state"
    """Same actions so far, the internal states differ."""
    DIFFERENT_SENSATION = "different_sensation"
    """Same actions and internal states so far, the sensations differ."""
    IDENTICAL = "identical"
    """The thesis's "unknown (identical)": no difference over the whole length."""


@dataclass(frozen=True, slots=True)
class CompareResult:
    """The outcome of :meth:`Memory.compare`.

    ``offset`` is the 0-based offset from ``n`` and ``m`` of the entries where the kind was
    decided; for :attr:`CompareKind.IDENTICAL` it equals ``length``. ``length`` is the length of
    both sub-memories, ``T + 1 - max(n, m)``.
    """

    kind: CompareKind
    offset: int
    length: int
    n: int
    m: int


@dataclass(frozen=True, slots=True)
class MemoryEntry:
    """One memory entry; ``action`` is ``None`` for entry 0 (the reset)."""

    action: int | None
    internal_state: int
    sensation: bool
    feedback: float


class Memory:
    """Per-instance, numpy-backed, append-only memory of one agent.

    The original platform shared one class-level list between every arm (defect 6); every
    instance of this class owns its buffers. They are preallocated and double when full, so
    :meth:`append` (called once per simulated step) is a handful of index writes.

    Columns, each a read-only numpy view of the filled part (``len(memory)`` entries):

    - :attr:`actions` (int32): the action that led to the entry, ``0 .. 2n-1`` for an arm of
      ``n`` links; :data:`NO_ACTION` (-1) at entry 0.
    - :attr:`internal_states` (int64): the internal state id at the end of the step (after the
      strategy's refinement, see :mod:`rsstp_sim.runner`).
    - :attr:`sensations` (bool): the boolean sensation after the step.
    - :attr:`feedback` (float64): the float feedback (closeness in ``[0, 1]``) after the step.

    A view taken earlier keeps showing the entries it covered; later appends are not in it.
    """

    __slots__ = ("_actions", "_states", "_sensations", "_feedback", "_length", "_limit")

    _actions: npt.NDArray[np.int32]
    _states: npt.NDArray[np.int64]
    _sensations: npt.NDArray[np.bool_]
    _feedback: npt.NDArray[np.float64]
    _length: int
    _limit: int

    def __init__(self, *, capacity: int = 1024) -> None:
        capacity = operator.index(capacity)
        if capacity < 1:
            raise MemoryRangeError(f"memory capacity must be at least 1, got {capacity}")
        self._actions = np.empty(capacity, dtype=np.int32)
        self._states = np.empty(capacity, dtype=np.int64)
        self._sensations = np.empty(capacity, dtype=np.bool_)
        self._feedback = np.empty(capacity, dtype=np.float64)
        self._length = 0
        # `append` writes without checks while `_length < _limit`. The limit is 0 until the reset,
        # so an append before `reset` takes the slow path, which refuses it: the check is free.
        self._limit = 0

    # -- writing -------------------------------------------------------------------------------

    def reset(self, internal_state: int, sensation: bool, feedback: float) -> None:
        """Write entry 0 (no action); :class:`MemoryRangeError` if the memory is not empty."""
        if self._length != 0:
            raise MemoryRangeError(
                f"reset writes entry 0 of an empty memory; this one already has "
                f"{self._length} entries"
            )
        self._actions[0] = NO_ACTION
        self._states[0] = internal_state
        self._sensations[0] = sensation
        self._feedback[0] = feedback
        self._length = 1
        self._limit = len(self._actions)

    def append(self, action: int, internal_state: int, sensation: bool, feedback: float) -> None:
        """Write the entry of the next step (hot path: no validation beyond what is free).

        Raises :class:`MemoryRangeError` before :meth:`reset`; an action that does not fit in
        int32 raises numpy's ``OverflowError``.
        """
        t = self._length
        if t >= self._limit:
            self._make_room()
        self._actions[t] = action
        self._states[t] = internal_state
        self._sensations[t] = sensation
        self._feedback[t] = feedback
        self._length = t + 1

    def relocate_last(self, internal_state: int) -> None:
        """Set the internal state of the last entry: the agent re-localised in the step's
        refinement, so the step ended in ``internal_state`` (see :mod:`rsstp_sim.runner`)."""
        if self._length == 0:
            raise MemoryRangeError("relocate_last on an empty memory: there is no entry yet")
        self._states[self._length - 1] = internal_state

    @property
    def last_state(self) -> int:
        """The internal state of the last entry."""
        if self._length == 0:
            raise MemoryRangeError("last_state of an empty memory: there is no entry yet")
        return int(self._states[self._length - 1])

    @property
    def last_sensation(self) -> bool:
        """The sensation of the last entry (a strategy reads it after every step: no view)."""
        if self._length == 0:
            raise MemoryRangeError("last_sensation of an empty memory: there is no entry yet")
        return bool(self._sensations[self._length - 1])

    @property
    def last_feedback(self) -> float:
        """The float feedback of the last entry (a strategy reads it after every step: no
        view)."""
        if self._length == 0:
            raise MemoryRangeError("last_feedback of an empty memory: there is no entry yet")
        return float(self._feedback[self._length - 1])

    def _make_room(self) -> None:
        if self._length == 0:
            raise MemoryRangeError("append before reset: entry 0 must be written by reset()")
        capacity = 2 * len(self._actions)
        for name in ("_actions", "_states", "_sensations", "_feedback"):
            old: npt.NDArray[Any] = getattr(self, name)
            new = np.empty(capacity, dtype=old.dtype)
            new[: self._length] = old[: self._length]
            setattr(self, name, new)
        self._limit = capacity

    # -- reading -------------------------------------------------------------------------------

    def __len__(self) -> int:
        """The number of entries, ``T + 1`` (0 before the reset)."""
        return self._length

    @property
    def steps(self) -> int:
        """``T``, the number of steps after the reset: ``len(self) - 1``, so -1 before the reset."""
        return self._length - 1

    @property
    def actions(self) -> npt.NDArray[np.int32]:
        """Actions (int32, read-only view); -1 (:data:`NO_ACTION`) at entry 0."""
        return _read_only(self._actions[: self._length])

    @property
    def internal_states(self) -> npt.NDArray[np.int64]:
        """Internal state ids (int64, read-only view)."""
        return _read_only(self._states[: self._length])

    @property
    def sensations(self) -> npt.NDArray[np.bool_]:
        """Boolean sensations (read-only view)."""
        return _read_only(self._sensations[: self._length])

    @property
    def feedback(self) -> npt.NDArray[np.float64]:
        """Float feedback, closeness in ``[0, 1]`` (float64, read-only view)."""
        return _read_only(self._feedback[: self._length])

    def __getitem__(self, t: SupportsIndex) -> MemoryEntry:
        """Entry ``t``; negative indices count from the end like a list."""
        index = operator.index(t)
        if index < 0:
            index += self._length
        if not 0 <= index < self._length:
            negative = f" or -{self._length} .. -1" if self._length else ""
            raise MemoryRangeError(
                f"memory index {operator.index(t)} out of range: valid indices are "
                f"{_range_text(self._length)}{negative}"
            )
        action = int(self._actions[index])
        return MemoryEntry(
            action=None if index == 0 else action,
            internal_state=int(self._states[index]),
            sensation=bool(self._sensations[index]),
            feedback=float(self._feedback[index]),
        )

    def __iter__(self) -> Iterator[MemoryEntry]:
        for t in range(self._length):
            yield self[t]

    def __eq__(self, other: object) -> bool:
        """Entry by entry equality (feedback compared exactly)."""
        if not isinstance(other, Memory):
            return NotImplemented
        return (
            self._length == other._length
            and np.array_equal(self.actions, other.actions)
            and np.array_equal(self.internal_states, other.internal_states)
            and np.array_equal(self.sensations, other.sensations)
            and np.array_equal(self.feedback, other.feedback)
        )

    __hash__ = None  # type: ignore[assignment]  # mutable

    def __repr__(self) -> str:
        return f"Memory(steps={self.steps}, capacity={len(self._actions)})"

    # -- compare (thesis 4.2) --------------------------------------------------------------------

    def compare(self, n: int, m: int) -> CompareResult:
        """Compare the sub-memories starting at entries ``n`` and ``m`` (thesis 4.2).

        Both run to the end of the shorter one: ``L = T + 1 - max(n, m)`` entries. For offset
        ``i = 0 .. L-1`` entries ``n+i`` and ``m+i`` are compared; at the first offset where they
        differ: actions differ -> :attr:`~CompareKind.UNKNOWN`; else internal states differ ->
        :attr:`~CompareKind.DIFFERENT_STATE`; else sensations differ ->
        :attr:`~CompareKind.DIFFERENT_SENSATION`. No difference ->
        :attr:`~CompareKind.IDENTICAL` with ``offset == L``. Feedback is not compared.

        At offset 0 the actions are **not** compared: the action of entry ``n`` (or ``m``) is the
        one that led to the starting point, outside the sub-memory. The thesis's Figure 11
        walk-through first compares the starting points' sensations, and only then "they both use
        the same action".

        Raises :class:`MemoryRangeError` when ``n == m`` or either is outside ``0 .. T``.

        >>> memory = Memory()
        >>> memory.reset(0, False, 0.1)
        >>> for action, sensation in [(1, True), (0, False), (1, True), (0, True), (1, True)]:
        ...     memory.append(action, 0, sensation, 0.5)
        >>> result = memory.compare(2, 0)  # the thesis's Figure 11
        >>> result.kind, result.offset, result.length
        (<CompareKind.DIFFERENT_SENSATION: 'different_sensation'>, 2, 4)
        """
        n = operator.index(n)
        m = operator.index(m)
        size = self._length
        if not (0 <= n < size and 0 <= m < size):
            raise MemoryRangeError(
                f"compare({n}, {m}): both starts must be in {_range_text(size)}"
                f" (the memory has {size} entries)"
            )
        if n == m:
            raise MemoryRangeError(
                f"compare({n}, {m}): the starts must differ (a sub-memory equals itself)"
            )
        length = size - max(n, m)
        states_differ = self._states[n : n + length] != self._states[m : m + length]
        sensations_differ = self._sensations[n : n + length] != self._sensations[m : m + length]
        actions_differ = np.zeros(length, dtype=np.bool_)
        np.not_equal(
            self._actions[n + 1 : n + length],
            self._actions[m + 1 : m + length],
            out=actions_differ[1:],
        )
        any_differ = actions_differ | states_differ | sensations_differ
        offset = int(np.argmax(any_differ))
        if not any_differ[offset]:
            return CompareResult(CompareKind.IDENTICAL, length, length, n, m)
        if actions_differ[offset]:
            kind = CompareKind.UNKNOWN
        elif states_differ[offset]:
            kind = CompareKind.DIFFERENT_STATE
        else:
            kind = CompareKind.DIFFERENT_SENSATION
        return CompareResult(kind, offset, length, n, m)

    # -- conversion ----------------------------------------------------------------------------

    def to_dataframe(self) -> pd.DataFrame:
        """One row per entry, indexed by ``step`` (as :meth:`rsstp_replay.Recording.steps`):
        ``action`` (nullable Int64, ``<NA>`` at step 0), ``internal_state`` (int64),
        ``sensation`` (bool), ``feedback`` (float64)."""
        import pandas as pd  # a simulation never needs it: imported on first use (~0.2 s)

        size = self._length
        mask = np.zeros(size, dtype=np.bool_)
        mask[:1] = True
        action = pd.arrays.IntegerArray(self._actions[:size].astype(np.int64), mask)
        return pd.DataFrame(
            {
                "action": action,
                "internal_state": self._states[:size].copy(),
                "sensation": self._sensations[:size].copy(),
                "feedback": self._feedback[:size].copy(),
            },
            index=pd.RangeIndex(size, name="step"),
        )

    def until(self, step: int) -> Memory:
        """The memory as it was at the end of step ``step`` (entries ``0 .. step``), a copy."""
        end = operator.index(step) + 1
        if not 0 < end <= self._length:
            raise MemoryRangeError(f"until: step {step} is not in 0..{self._length - 1}")
        return Memory.from_arrays(
            self.actions[:end],
            self.internal_states[:end],
            self.sensations[:end],
            self.feedback[:end],
        )

    @classmethod
    def from_arrays(
        cls,
        actions: npt.ArrayLike,
        internal_states: npt.ArrayLike,
        sensations: npt.ArrayLike,
        feedback: npt.ArrayLike,
    ) -> Memory:
        """Rebuild a memory from its columns (as in :attr:`actions` etc.), validated.

        ``actions`` and ``internal_states`` must be integer arrays, ``sensations`` a bool array,
        ``feedback`` a real array in ``[0, 1]``; all one-dimensional and of the same length.
        ``actions[0]`` must be -1 and every later action a non-negative int32. An empty set of
        columns gives an empty memory. Raises :class:`MemoryRangeError` naming the column and
        the first offending entry.
        """
        columns = {
            "actions": np.asarray(actions),
            "internal_states": np.asarray(internal_states),
            "sensations": np.asarray(sensations),
            "feedback": np.asarray(feedback),
        }
        for name, column in columns.items():
            if column.ndim != 1:
                raise MemoryRangeError(
                    f"{name}: expected a one-dimensional array, got shape {column.shape}"
                )
        lengths = {name: len(column) for name, column in columns.items()}
        if len(set(lengths.values())) != 1:
            raise MemoryRangeError(f"the columns must have the same length, got {lengths}")
        size = lengths["actions"]
        expected_kinds = {
            "actions": ("iu", "an integer"),
            "internal_states": ("iu", "an integer"),
            "sensations": ("b", "a bool"),
            "feedback": ("iuf", "a real"),
        }
        for name, (kinds, text) in expected_kinds.items():
            column = columns[name]
            if size and column.dtype.kind not in kinds:
                raise MemoryRangeError(f"{name}: expected {text} dtype, got {column.dtype}")
        action_column = columns["actions"]
        if size:
            if action_column[0] != NO_ACTION:
                raise MemoryRangeError(
                    f"actions[0] must be {NO_ACTION} (the reset has no action), "
                    f"got {action_column[0]}"
                )
            bad = np.flatnonzero((action_column[1:] < 0) | (action_column[1:] > _INT32_MAX))
            if bad.size:
                t = int(bad[0]) + 1
                raise MemoryRangeError(
                    f"actions[{t}] = {action_column[t]}: expected 0 .. {_INT32_MAX}"
                )
            states_column = columns["internal_states"]
            if states_column.dtype.kind == "u" and states_column.max() > np.iinfo(np.int64).max:
                t = int(np.argmax(states_column > np.iinfo(np.int64).max))
                raise MemoryRangeError(
                    f"internal_states[{t}] = {states_column[t]} does not fit in int64"
                )
            feedback_column = columns["feedback"].astype(np.float64)
            bad = np.flatnonzero(~((feedback_column >= 0.0) & (feedback_column <= 1.0)))
            if bad.size:
                t = int(bad[0])
                raise MemoryRangeError(f"feedback[{t}] = {feedback_column[t]} is outside [0, 1]")
        memory = cls(capacity=max(size, 1))
        if size:
            memory._actions[:size] = action_column
            memory._states[:size] = columns["internal_states"]
            memory._sensations[:size] = columns["sensations"]
            memory._feedback[:size] = columns["feedback"]
            memory._length = size
            memory._limit = len(memory._actions)
        return memory


def _read_only(view: npt.NDArray[Any]) -> npt.NDArray[Any]:
    view.flags.writeable = False
    return view


def _range_text(size: int) -> str:
    return "none (the memory is empty)" if size == 0 else f"0 .. {size - 1}"
