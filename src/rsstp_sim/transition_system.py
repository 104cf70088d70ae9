"""The agent's internal model: a labelled transition system over internal states.

The thesis (section 3.1.1) keeps the model as a dense "transition matrix": row
``i``, column ``j`` holds the sorted list of actions leading from internal state
``i`` to internal state ``j``, and four operations reshape it: ``add`` and
``delete`` a transition, ``split`` a state (duplicate its row and column) and
``merge`` two states (union of their rows and columns).

Here states carry stable integer ids that are never reused, transitions are
stored sparsely (successors per state and action, plus an incoming index so
that ``split`` and ``merge`` cost time proportional to the degree of the states
involved), and the dense matrix is only a view (:meth:`TransitionSystem.to_matrix`).
Every operation that changes the model is logged as an :class:`Operation`, so a
recording can carry the operations and a replay can rebuild the model at any
step with :meth:`TransitionSystem.apply`.

Two defects of the original platform are fixed here (docs/world.md, defects 9 and 10):
``merge`` moves a current state that disappears onto the surviving state
(defect 9), and a duplicated action label inside one matrix cell is one
transition, not nondeterminism (defect 10).

>>> model = TransitionSystem.universal([0, 1])
>>> model.to_matrix()
[[[0, 1]]]
>>> model.split(0)
1
>>> model.to_matrix()
[[[0, 1], [0, 1]], [[0, 1], [0, 1]]]
>>> model.is_deterministic()
False
>>> model.merge(0, 1)
0
>>> model == TransitionSystem.universal([0, 1])
True
"""

from __future__ import annotations

import bisect
import operator
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from rsstp_format.vocabulary import Operation, snapshot_form
from rsstp_sim.errors import ModelError, RsstpError

__all__ = ["DeterminismReport", "Operation", "TransitionSystem", "snapshot_form"]

_ARITY: dict[str, int] = {"split": 1, "merge": 2, "add": 3, "delete": 3}


@dataclass(frozen=True, slots=True)
class DeterminismReport:
    """Which (state, action) pairs break determinism (thesis 4.3) or have no successor.

    ``nondeterministic`` lists ``(state, action, successors)`` for every pair
    with more than one successor; ``empty`` lists ``(state, action)`` for every
    action of the model's alphabet with no successor. Both are sorted.
    """

    nondeterministic: tuple[tuple[int, int, tuple[int, ...]], ...]
    empty: tuple[tuple[int, int], ...]

    @property
    def deterministic(self) -> bool:
        """Every (state, action) has at most one successor."""
        return not self.nondeterministic

    @property
    def complete(self) -> bool:
        """Every (state, action) has exactly one successor."""
        return not self.nondeterministic and not self.empty


def as_int(value: object, what: str, error: type[RsstpError] = ModelError) -> int:
    """``value`` as an int (numpy integers welcome; bools, numpy bools and floats refused
    with ``error``). The model's and the thesis facade's one check of an integer argument."""
    if isinstance(value, bool | np.bool_):
        raise error(f"{what} must be an integer, got {value!r}")
    try:
        return operator.index(value)  # type: ignore[arg-type]
    except TypeError:
        raise error(f"{what} must be an integer, got {value!r}") from None


def _as_action(value: object, what: str) -> int:
    action = as_int(value, what)
    if action < 0:
        raise ModelError(f"{what} must be an integer >= 0, got {action}")
    return action


class TransitionSystem:
    """A nondeterministic labelled transition system with a current state.

    States are integer ids (``0 .. n_states-1`` at construction; :meth:`split`
    hands out ``next_id`` and ids are never reused). Actions are integers
    ``>= 0``; the alphabet (:attr:`actions`) is given at construction and grows
    with every action used in :meth:`add`. ``version`` counts the operations
    that changed the model; :meth:`drain_operations` hands them out.
    """

    __slots__ = (
        "_out",
        "_in",
        "_actions",
        "_actions_sorted",
        "_current",
        "_version",
        "_next_id",
        "_n_nondeterministic",
        "_n_transitions",
        "_ops",
        "_states_sorted",
        "_index",
        "_rows",
    )
    __hash__ = None  # type: ignore[assignment]

    def __init__(self, n_states: int = 1, *, actions: Iterable[int] = ()) -> None:
        n = as_int(n_states, "n_states")
        if n < 1:
            raise ModelError(f"a transition system needs n_states >= 1, got {n}")
        # _out[s][a]: sorted tuple of successors (no empty entries);
        # _in[t][a]: set of predecessors (no empty entries); None until first needed after a
        # copy or a model from columns (:meth:`_incoming` builds it from _out).
        self._out: dict[int, dict[int, tuple[int, ...]]] = {s: {} for s in range(n)}
        self._in: dict[int, dict[int, set[int]]] | None = {s: {} for s in range(n)}
        self._actions: set[int] = {_as_action(a, "action") for a in actions}
        self._actions_sorted: tuple[int, ...] | None = None
        self._current = 0
        self._version = 0
        self._next_id = n
        self._n_nondeterministic = 0
        self._n_transitions = 0
        self._ops: list[Operation] = []
        self._states_sorted: tuple[int, ...] | None = None
        self._index: dict[int, int] | None = None
        # _rows[s]: s's transitions as (sources, actions, targets) columns, sorted; dropped
        # when they change (every change of a transition goes through _link and _unlink).
        self._rows: dict[int, tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]]] = {}

    @classmethod
    def universal(cls, actions: Iterable[int]) -> TransitionSystem:
        """One state with a self-loop for every action: the model that knows nothing."""
        model = cls(1, actions=actions)
        for a in model.actions:
            model._link(0, a, 0)
        return model

    # ----------------------------------------------------------------- views

    @property
    def actions(self) -> tuple[int, ...]:
        """The action alphabet, sorted."""
        if self._actions_sorted is None:
            self._actions_sorted = tuple(sorted(self._actions))
        return self._actions_sorted

    @property
    def states(self) -> tuple[int, ...]:
        """The state ids, sorted."""
        if self._states_sorted is None:
            self._states_sorted = tuple(sorted(self._out))
        return self._states_sorted

    @property
    def current(self) -> int:
        """The current internal state."""
        return self._current

    @current.setter
    def current(self, s: int) -> None:
        self._check(s, "set current")
        self._current = s

    @property
    def version(self) -> int:
        """0 at construction, +1 for every operation that changed the model."""
        return self._version

    @property
    def next_id(self) -> int:
        """The id the next :meth:`split` will create."""
        return self._next_id

    def __len__(self) -> int:
        return len(self._out)

    def __contains__(self, s: object) -> bool:
        return s in self._out

    def __repr__(self) -> str:
        n_transitions = sum(len(ts) for out in self._out.values() for ts in out.values())
        return (
            f"TransitionSystem(states={len(self)}, transitions={n_transitions}, "
            f"actions={self.actions}, current={self._current}, version={self._version})"
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, TransitionSystem):
            return NotImplemented
        return (
            self._current == other._current
            and self._actions == other._actions
            and self._out == other._out
        )

    def successors(self, s: int, a: int) -> tuple[int, ...]:
        """The sorted successors of ``s`` under action ``a``; ``()`` when there are none."""
        try:
            return self._out[s].get(a, ())
        except KeyError:
            raise ModelError(f"successors: unknown state {s!r}") from None

    def predecessors(self, s: int) -> set[int]:
        """The states with a transition into ``s`` (any action, ``s`` itself included)."""
        try:
            return {u for sources in self._incoming()[s].values() for u in sources}
        except KeyError:
            raise ModelError(f"predecessors: unknown state {s!r}") from None

    @property
    def n_transitions(self) -> int:
        """How many transitions there are (kept as they change: no count)."""
        return self._n_transitions

    def is_deterministic(self) -> bool:
        """Every (state, action) has at most one successor (O(1), kept incrementally)."""
        return self._n_nondeterministic == 0

    @property
    def nondeterministic_pairs(self) -> int:
        """How many (state, action) pairs have several successors (O(1), kept incrementally)."""
        return self._n_nondeterministic

    def determinism_report(self) -> DeterminismReport:
        """The pairs with several successors and the pairs with none (thesis 4.3)."""
        nondeterministic: list[tuple[int, int, tuple[int, ...]]] = []
        empty: list[tuple[int, int]] = []
        for s in self.states:
            several, none = self.determinism_of(s)
            nondeterministic += several
            empty += none
        return DeterminismReport(tuple(nondeterministic), tuple(empty))

    def determinism_of(
        self, s: int
    ) -> tuple[list[tuple[int, int, tuple[int, ...]]], list[tuple[int, int]]]:
        """State ``s``'s part of :meth:`determinism_report`: its (state, action, successors)
        with several successors and its (state, action) with none, by action."""
        out = self._out[s]
        several = [(s, a, out[a]) for a in sorted(out) if len(out[a]) > 1]
        return several, [(s, a) for a in self.actions if a not in out]

    def transitions(self) -> list[tuple[int, int, int]]:
        """Every transition as ``(source, action, target)``, sorted."""
        return list(zip(*self.transition_columns(), strict=True))

    def transition_columns(self) -> tuple[list[int], list[int], list[int]]:
        """Every transition as three columns, sources, actions and targets, in the order of
        :meth:`transitions`. Each state's part is kept until its transitions change: a model
        that changes a few states at a time gives its columns at the cost of joining them."""
        sources: list[int] = []
        actions: list[int] = []
        targets: list[int] = []
        rows = self._rows
        for s in self.states:
            row = rows.get(s)
            if row is None:
                pairs = self.transitions_from(s)
                row = rows[s] = (
                    (s,) * len(pairs),
                    tuple(a for a, _ in pairs),
                    tuple(t for _, t in pairs),
                )
            sources.extend(row[0])
            actions.extend(row[1])
            targets.extend(row[2])
        return sources, actions, targets

    def transitions_into(self, t: int) -> list[tuple[int, int]]:
        """Every transition into ``t`` as ``(source, action)``, sorted."""
        try:
            into = self._incoming()[t]
        except KeyError:
            raise ModelError(f"transitions_into: unknown state {t!r}") from None
        return sorted((u, a) for a, sources in into.items() for u in sources)

    def transitions_from(self, s: int) -> list[tuple[int, int]]:
        """Every transition out of ``s`` as ``(action, target)``, sorted."""
        try:
            out = self._out[s]
        except KeyError:
            raise ModelError(f"transitions_from: unknown state {s!r}") from None
        return [(a, t) for a, targets in sorted(out.items()) for t in targets]

    def index_of(self, s: int) -> int:
        """The row/column of state ``s`` in the dense matrix view."""
        if self._index is None:
            self._index = {state: i for i, state in enumerate(self.states)}
        try:
            return self._index[s]
        except KeyError:
            raise ModelError(f"index_of: unknown state {s!r}") from None

    def state_at(self, index: int) -> int:
        """The state at row/column ``index`` of the dense matrix view."""
        states = self.states
        if not isinstance(index, int) or not 0 <= index < len(states):
            raise ModelError(f"state_at: index {index!r} is not in range 0..{len(states) - 1}")
        return states[index]

    def to_matrix(self) -> list[list[list[int]]]:
        """The thesis's matrix: cell ``[i][j]`` lists the actions from state ``i`` to ``j``."""
        n = len(self)
        matrix: list[list[list[int]]] = [[[] for _ in range(n)] for _ in range(n)]
        for s, a, t in self.transitions():
            matrix[self.index_of(s)][self.index_of(t)].append(a)
        return matrix

    @classmethod
    def from_matrix(
        cls, matrix: Sequence[Sequence[Sequence[int]]], *, actions: Iterable[int] = ()
    ) -> TransitionSystem:
        """Build states ``0..n-1`` from the thesis's square matrix of action lists.

        A label repeated inside one cell is one transition (the original
        platform counted it as nondeterminism).
        """
        n = len(matrix)
        if n < 1:
            raise ModelError("from_matrix: the matrix is empty; it needs at least one row")
        model = cls(n, actions=actions)
        for i, row in enumerate(matrix):
            if isinstance(row, str | bytes) or len(row) != n:
                raise ModelError(
                    f"from_matrix: row {i} must have {n} cells (square matrix), got {row!r}"
                )
            for j, cell in enumerate(row):
                if isinstance(cell, str | bytes) or not isinstance(cell, Iterable):
                    raise ModelError(f"from_matrix: cell [{i}][{j}] must be a list, got {cell!r}")
                for a in cell:
                    action = _as_action(a, f"from_matrix: action in cell [{i}][{j}]")
                    model._actions_add(action)
                    model._link(i, action, j)
        return model

    # ------------------------------------------------------------ operations

    def add(self, s: int, t: int, a: int) -> bool:
        """Add the transition ``s -a-> t``; ``True`` when it is new."""
        self._check(s, "add")
        self._check(t, "add")
        action = _as_action(a, "add: action")
        self._actions_add(action)
        if not self._link(s, action, t):
            return False
        self._log(Operation("add", (s, t, action), None))
        return True

    def delete(self, s: int, t: int, a: int) -> bool:
        """Delete the transition ``s -a-> t``; ``True`` when it existed."""
        self._check(s, "delete")
        self._check(t, "delete")
        action = _as_action(a, "delete: action")
        if not self._unlink(s, action, t):
            return False
        self._log(Operation("delete", (s, t, action), None))
        return True

    def split(self, s: int) -> int:
        """Create ``s'`` with copies of every transition out of and into ``s``; return ``s'``.

        A self-loop on ``s`` yields ``s->s``, ``s->s'``, ``s'->s`` and ``s'->s'``,
        like duplicating the matrix row and column. The current state stays.
        """
        self._check(s, "split")
        new = self._next_id
        outgoing = [(a, t) for a, targets in self._out[s].items() for t in targets]
        into = self._incoming()
        incoming = [(u, a) for a, sources in into[s].items() for u in sources]
        self._next_id += 1
        self._out[new] = {}
        into[new] = {}
        self._states_changed()
        for a, t in outgoing:
            self._link(new, a, t)
            if t == s:
                self._link(new, a, new)
        for u, a in incoming:
            self._link(u, a, new)
        self._log(Operation("split", (s,), new))
        return new

    def merge(self, s: int, t: int) -> int:
        """Redirect every transition of ``t`` to ``s`` (union), remove ``t``; return ``s``.

        A current state of ``t`` becomes ``s``.
        """
        self._check(s, "merge")
        self._check(t, "merge")
        if s == t:
            raise ModelError(f"merge: cannot merge state {s} with itself")
        outgoing = [(a, v) for a, targets in self._out[t].items() for v in targets]
        into = self._incoming()
        incoming = [(u, a) for a, sources in into[t].items() for u in sources]
        for a, v in outgoing:
            self._unlink(t, a, v)
        for u, a in incoming:
            if u != t:  # self-loops went with the outgoing ones
                self._unlink(u, a, t)
        del self._out[t]
        del into[t]
        self._rows.pop(t, None)
        self._states_changed()
        for a, v in outgoing:
            self._link(s, a, s if v == t else v)
        for u, a in incoming:
            self._link(s if u == t else u, a, s)
        if self._current == t:
            self._current = s
        self._log(Operation("merge", (s, t), s))
        return s

    def sources_changed_by(self, kind: str, args: Sequence[int]) -> set[int]:
        """The states whose outgoing transitions an operation would change, asked before it is
        applied: the source of an ``add`` or ``delete``; a ``split``'s new state and every
        state with a transition into the split one; a ``merge``'s two states and every state
        with a transition into the one that goes. An operation that does not apply changes
        nothing (applying it raises)."""
        try:
            if kind == "split":
                return {self._next_id, *self.predecessors(args[0])}
            if kind == "merge":
                return {args[0], args[1], *self.predecessors(args[1])}
            return {args[0]}
        except (ModelError, IndexError):
            return set()

    def apply(self, op: Operation) -> None:
        """Replay a logged operation exactly; an inconsistent one raises :class:`ModelError`."""
        arity = _ARITY.get(op.kind)
        if arity is None:
            raise ModelError(f"apply: unknown operation kind {op.kind!r}")
        if len(op.args) != arity:
            raise ModelError(f"apply: {op.kind} takes {arity} arguments, got {op.args!r}")
        if op.kind == "split":
            (s,) = op.args
            self._check(s, "apply split")
            if op.result != self._next_id:
                raise ModelError(
                    f"apply: split of state {s} recorded new state {op.result!r}, "
                    f"but the next id here is {self._next_id}"
                )
            self.split(s)
        elif op.kind == "merge":
            s, t = op.args
            self._check(s, "apply merge")
            self._check(t, "apply merge")
            if op.result != s:
                raise ModelError(f"apply: merge({s}, {t}) recorded result {op.result!r}, not {s}")
            self.merge(s, t)
        else:
            s, t, a = op.args
            self._check(s, f"apply {op.kind}")
            self._check(t, f"apply {op.kind}")
            exists = t in self._out[s].get(a, ())
            if op.changed == (exists if op.kind == "add" else not exists):
                state = "already exists" if exists else "does not exist"
                raise ModelError(
                    f"apply: {op.kind}({s}, {t}, {a}) recorded changed={op.changed}, "
                    f"but the transition {state}"
                )
            if op.kind == "add":
                self.add(s, t, a)
            else:
                self.delete(s, t, a)

    def drain_operations(self) -> list[Operation]:
        """The operations applied since the last drain; clears that buffer."""
        ops, self._ops = self._ops, []
        return ops

    # ---------------------------------------------------- copies and formats

    def copy(self) -> TransitionSystem:
        """A deep copy (current, version, next id and actions included) with an empty op log."""
        other = TransitionSystem.__new__(TransitionSystem)
        other._out = {s: dict(out) for s, out in self._out.items()}
        other._in = None  # (built when first needed)
        other._actions = set(self._actions)
        other._actions_sorted = self._actions_sorted
        other._current = self._current
        other._version = self._version
        other._next_id = self._next_id
        other._n_nondeterministic = self._n_nondeterministic
        other._n_transitions = self._n_transitions
        other._ops = []
        other._states_sorted = self._states_sorted
        other._index = self._index
        other._rows = dict(self._rows)
        return other

    def snapshot(self) -> dict[str, object]:
        """A JSON-ready sparse form; :meth:`from_snapshot` reads it back."""
        return snapshot_form(
            self.states, self._next_id, self._current, self.actions, self.transitions()
        )

    @classmethod
    def from_snapshot(cls, data: Mapping[str, object], *, version: int = 0) -> TransitionSystem:
        """Rebuild a model from :meth:`snapshot` output, validating every field."""
        for key in ("states", "next_id", "current", "actions", "transitions"):
            if key not in data:
                raise ModelError(f"snapshot: missing key {key!r}")
        states = [as_int(s, "snapshot: states[]") for s in _as_list(data["states"], "states")]
        if not states or len(set(states)) != len(states) or min(states) < 0:
            raise ModelError(
                f"snapshot: states must be distinct non-negative ids, at least one; got {states}"
            )
        next_id = as_int(data["next_id"], "snapshot: next_id")
        if next_id <= max(states):
            raise ModelError(f"snapshot: next_id {next_id} must exceed every state id")
        current = as_int(data["current"], "snapshot: current")
        if current not in states:
            raise ModelError(f"snapshot: current {current} is not one of the states")
        actions = {
            _as_action(a, "snapshot: actions[]") for a in _as_list(data["actions"], "actions")
        }
        model = cls(1, actions=actions)
        model._out = {s: {} for s in states}
        model._in = {s: {} for s in states}
        model._states_changed()
        model._current = current
        model._next_id = next_id
        model._version = as_int(version, "version")
        for k, item in enumerate(_as_list(data["transitions"], "transitions")):
            where = f"snapshot: transitions[{k}]"
            triple = _as_list(item, f"transitions[{k}]")
            if len(triple) != 3:
                raise ModelError(f"{where} must be [source, action, target], got {item!r}")
            s, t = as_int(triple[0], where), as_int(triple[2], where)
            a = _as_action(triple[1], f"{where} action")
            if s not in model._out or t not in model._out:
                raise ModelError(f"{where} refers to an unknown state: {item!r}")
            if a not in actions:
                raise ModelError(f"{where} uses action {a}, not in actions {sorted(actions)}")
            model._link(s, a, t)
        return model

    @classmethod
    def from_columns(
        cls,
        states: Sequence[int],
        actions: Iterable[int],
        columns: tuple[Sequence[int], Sequence[int], Sequence[int]],
        *,
        next_id: int,
        current: int,
        version: int = 0,
    ) -> TransitionSystem:
        """A model from columns already checked (a recording's version, which its reader
        rebuilt and checked): ``states`` sorted, the transitions as ``(sources, actions,
        targets)`` sorted by source, action and target, all between known states. One pass,
        no check per transition (:meth:`from_snapshot` checks everything)."""
        model = cls(1, actions=actions)
        out: dict[int, dict[int, tuple[int, ...]]] = {s: {} for s in states}
        nondeterministic = 0
        for s, a, t in zip(*columns, strict=True):
            row = out[s]
            targets = row.get(a)
            if targets is None:
                row[a] = (t,)
            else:
                if len(targets) == 1:
                    nondeterministic += 1
                row[a] = (*targets, t)
        model._out, model._in = out, None  # (predecessors: built when first needed)
        model._n_nondeterministic = nondeterministic
        model._n_transitions = len(columns[0])
        model._states_sorted = tuple(states)
        model._current = current
        model._next_id = next_id
        model._version = version
        return model

    # -------------------------------------------------------------- internals

    def _check(self, s: object, operation: str) -> None:
        if s not in self._out:
            states = self.states
            known = f"states: {list(states)}" if len(states) <= 20 else f"{len(states)} states"
            raise ModelError(f"{operation}: unknown state {s!r} ({known})")

    def _log(self, op: Operation) -> None:
        self._ops.append(op)
        self._version += 1

    def _states_changed(self) -> None:
        self._states_sorted = None
        self._index = None

    def _actions_add(self, a: int) -> None:
        if a not in self._actions:
            self._actions.add(a)
            self._actions_sorted = None

    def _link(self, s: int, a: int, t: int) -> bool:
        """Insert ``s -a-> t`` keeping the tuples sorted and the counter right."""
        out = self._out[s]
        targets = out.get(a, ())
        i = bisect.bisect_left(targets, t)
        if i < len(targets) and targets[i] == t:
            return False
        out[a] = targets[:i] + (t,) + targets[i:]
        self._rows.pop(s, None)
        self._n_transitions += 1
        if len(targets) == 1:
            self._n_nondeterministic += 1
        if self._in is not None:
            self._in[t].setdefault(a, set()).add(s)
        return True

    def _unlink(self, s: int, a: int, t: int) -> bool:
        out = self._out[s]
        targets = out.get(a, ())
        if t not in targets:
            return False
        self._rows.pop(s, None)
        self._n_transitions -= 1
        if len(targets) == 1:
            del out[a]
        else:
            out[a] = tuple(v for v in targets if v != t)
            if len(targets) == 2:
                self._n_nondeterministic -= 1
        if self._in is not None:
            sources = self._in[t][a]
            sources.discard(s)
            if not sources:
                del self._in[t][a]
        return True

    def _incoming(self) -> dict[int, dict[int, set[int]]]:
        """``_in``, the predecessors by target and action, built from ``_out`` if it was left
        out (:meth:`copy` and :meth:`from_columns` leave it out: most copies and most models
        read from a recording never need it)."""
        if self._in is None:
            into: dict[int, dict[int, set[int]]] = {s: {} for s in self._out}
            for s, out in self._out.items():
                for a, targets in out.items():
                    for t in targets:
                        into[t].setdefault(a, set()).add(s)
            self._in = into
        return self._in


def _as_list(value: object, what: str) -> list[object]:
    if isinstance(value, str | bytes | Mapping) or not isinstance(value, Iterable):
        raise ModelError(f"snapshot: {what} must be a list, got {value!r}")
    return list(value)
