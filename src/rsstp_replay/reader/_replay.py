"""A model version's transitions as one sorted array of integer keys, and the operations of
the versions after it applied to that array with numpy, as
:meth:`~rsstp_sim.transition_system.TransitionSystem.apply` applies them to a model.

What :meth:`~rsstp_replay.reader._models.ModelHistory.model` rebuilds a version with: the
operations since the nearest whole model kept are applied to arrays (no dict, tuple or set
per transition, and no index of predecessors to build), and only the version asked for
becomes a :class:`~rsstp_sim.transition_system.TransitionSystem`. The operations were
checked when the versions were read (:class:`~rsstp_replay.reader._models.ChainCheck`), so
none is checked again here.

A transition ``source -action-> target`` is the key ``(source << high) | (action << low) |
target`` (:class:`KeyLayout`): sorting the keys sorts the transitions by source, action and
target, a state's transitions out are one slice, and the transitions into it are where the
low bits equal it.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rsstp_format.records import OperationRecord
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["KeyLayout", "KeyedVersion"]

_Keys = npt.NDArray[np.int64]


@dataclass(frozen=True)
class KeyLayout:
    """Where a key holds a transition's ids: the target in its ``low`` bits, the action in
    the next ``high - low``, the source above."""

    low: int
    high: int

    @classmethod
    def fitting(cls, *, id_bound: int, action_bound: int) -> KeyLayout | None:
        """The layout for state ids below ``id_bound`` and actions below ``action_bound``;
        None when such keys would not fit in 63 bits."""
        low = max(id_bound - 1, 1).bit_length()
        high = low + max(action_bound - 1, 1).bit_length()
        return cls(low, high) if high + low <= 63 else None

    def keys(self, source: Sequence[int], action: Sequence[int], target: Sequence[int]) -> _Keys:
        """The keys of transitions given as three columns (sorted by source, action and
        target, the keys are sorted)."""
        s, a, t = (np.asarray(column, dtype=np.int64) for column in (source, action, target))
        return (s << self.high) | (a << self.low) | t

    def key(self, source: int, action: int, target: int) -> int:
        return (source << self.high) | (action << self.low) | target

    def columns(self, keys: _Keys) -> tuple[list[int], list[int], list[int]]:
        """The transitions of ``keys`` as sources, actions and targets."""
        action_mask = (1 << (self.high - self.low)) - 1
        return (
            (keys >> self.high).tolist(),
            ((keys >> self.low) & action_mask).tolist(),
            (keys & ((1 << self.low) - 1)).tolist(),
        )


class KeyedVersion:
    """A version's states and transitions in sorted arrays, advanced by the operations of
    the versions after it (:meth:`apply`): an ``add`` or ``delete`` is noted in a set, and
    those noted are applied together before the next ``split`` or ``merge`` (each a few
    numpy passes over the keys) and before the arrays are read."""

    def __init__(self, layout: KeyLayout, states: _Keys, keys: _Keys, next_id: int) -> None:
        self.layout = layout
        self._states = states
        self._keys = keys
        self.next_id = next_id
        self._added: set[int] = set()
        self._deleted: set[int] = set()

    def apply(self, operations: Iterable[OperationRecord]) -> None:
        """Apply operations of the versions that follow, in order (each one a changing
        operation of the chain, or a no-op, ``changed`` false, which changes nothing)."""
        key = self.layout.key
        added, deleted = self._added, self._deleted
        for operation in operations:
            kind, args = operation.kind, operation.args
            if kind in ("add", "delete"):
                if operation.changed:  # (an add undoes a delete still pending, and back)
                    k = key(args[0], args[2], args[1])
                    undone, done = (deleted, added) if kind == "add" else (added, deleted)
                    if k in undone:
                        undone.discard(k)
                    else:
                        done.add(k)
            elif kind == "split":
                self._flush()
                self._split(args[0])
            else:
                self._flush()
                self._merge(args[0], args[1])

    def model(
        self, *, actions: Iterable[int], next_id: int, current: int, version: int
    ) -> TransitionSystem:
        """The version reached, as a model of its own."""
        self._flush()
        return TransitionSystem.from_columns(
            self._states.tolist(),
            actions,
            self.layout.columns(self._keys),
            next_id=next_id,
            current=current,
            version=version,
        )

    def arrays(self) -> tuple[_Keys, _Keys]:
        """The version reached: its state ids, sorted, and its transitions as rows
        ``(source, action, target)``, sorted (copies, the caller's)."""
        self._flush()
        keys, layout = self._keys, self.layout
        rows = np.empty((len(keys), 3), np.int64)
        rows[:, 0] = keys >> layout.high
        rows[:, 1] = (keys >> layout.low) & ((1 << (layout.high - layout.low)) - 1)
        rows[:, 2] = keys & ((1 << layout.low) - 1)
        return self._states.copy(), rows

    def _flush(self) -> None:
        """Apply the adds and deletes noted since the last flush."""
        keys = self._keys
        if self._deleted:
            gone = np.sort(np.fromiter(self._deleted, np.int64, len(self._deleted)))
            keys = np.delete(keys, np.searchsorted(keys, gone))
            self._deleted.clear()  # (in place: :meth:`apply` holds the sets)
        if self._added:
            new = np.sort(np.fromiter(self._added, np.int64, len(self._added)))
            keys = np.insert(keys, np.searchsorted(keys, new), new)
            self._added.clear()
        self._keys = keys

    def _out(self, s: int) -> slice:
        """Where the transitions out of ``s`` lie among the keys."""
        high = self.layout.high
        lo, hi = np.searchsorted(self._keys, (s << high, (s + 1) << high)).tolist()
        return slice(lo, hi)

    def _into(self, t: int) -> npt.NDArray[np.bool_]:
        """Which keys are transitions into ``t``."""
        into: npt.NDArray[np.bool_] = (self._keys & ((1 << self.layout.low) - 1)) == t
        return into

    def _split(self, s: int) -> None:
        """As :meth:`TransitionSystem.split`: the new state ``s'`` (the next id, above every
        other) gets ``s'`` -a-> t for every ``s`` -a-> t, ``s'`` -a-> ``s'`` for a self-loop of
        ``s``, and u -a-> ``s'`` for every u -a-> ``s``."""
        layout, keys, new = self.layout, self._keys, self.next_id
        low_mask = (1 << layout.low) - 1
        lower = keys[self._out(s)] & ((1 << layout.high) - 1)  # (action, target) of s's
        loops = lower[(lower & low_mask) == s]
        into = keys[self._into(s)]
        into_new = (into & ~low_mask) | new  # u -a-> s' (sorted as u -a-> s were)
        keys = np.insert(keys, np.searchsorted(keys, into_new), into_new)
        # s''s own (action, target) pairs, sorted; s' is the largest id: its keys come last
        own = np.sort(np.concatenate((lower, (loops & ~low_mask) | new)))
        self._keys = np.concatenate((keys, own | (new << layout.high)))
        self._states = np.append(self._states, new)
        self.next_id = new + 1

    def _merge(self, s: int, t: int) -> None:
        """As :meth:`TransitionSystem.merge`: every transition out of or into ``t`` moves onto
        ``s`` (``t`` read as ``s`` at either end; a union with ``s``'s own), and ``t`` goes."""
        layout, keys = self.layout, self._keys
        low_mask = (1 << layout.low) - 1
        lower_mask = (1 << layout.high) - 1
        gone = self._into(t)
        out = self._out(t)
        gone[out] = True
        moved = keys[gone]
        source, target = moved >> layout.high, moved & low_mask
        source[source == t] = s
        target[target == t] = s
        moved = (source << layout.high) | (moved & lower_mask & ~low_mask) | target
        self._keys = np.union1d(keys[~gone], moved)
        self._states = self._states[self._states != t]
