"""The ground truth's machine: the reachable poses enumerated, minimised, and a model checked
against them (:mod:`rsstp_sim.truth` says what it is)."""

from __future__ import annotations

import operator
import time
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rsstp_sim.arrays import BoolArray, IntArray
from rsstp_sim.bodies import body_of
from rsstp_sim.errors import ModelError, TruthError
from rsstp_sim.interface import PoseMachine, World, WorldScenario
from rsstp_sim.moore import moore_classes, reached
from rsstp_sim.transition_system import TransitionSystem

__all__ = [
    "GroundTruth",
    "TruthError",
    "check_truth_size",
    "check_equivalence",
    "compute_truth",
    "format_truth",
]


_POSES_AT_ONCE = 1 << 20
"""Rows :meth:`GroundTruth.poses_of` turns into pose indices together."""


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """The reachable poses of a scenario as a Moore machine, and its minimisation.

    Pose index ``p`` (``0 .. P-1``) follows the sorted pose codes. For action
    ``actions[k]`` (see :class:`~rsstp_sim.arm.world.World`), ``next_pose[p, k]``
    is the pose reached from ``p`` (``p`` itself when ``blocked[p, k]``).
    ``true_class[p]`` is the pose's class in the minimal machine; classes are
    numbered breadth-first from the start pose's class (0) over the actions in
    order, so the numbering depends only on the machine's behaviour.

    ``pose_values[p]`` is what a recording's steps table says of the pose, one column a
    value, named ``value_names`` (the arm's joint angles, the rover's cell and heading). A
    value ``v`` is the digit ``v // units[i]`` of the pose code in base ``radices[i]`` (the
    last digit most significant); with ``wrap`` a digit is taken modulo its radix (angles),
    else one out of range names no pose.
    ``seconds`` (wall time of the computation) takes no part in equality.
    Arrays are read-only.
    """

    scenario_name: str
    actions: tuple[int, ...]
    pose_codes: IntArray
    pose_values: IntArray
    sensation: BoolArray
    next_pose: IntArray
    blocked: BoolArray
    start_index: int
    true_class: IntArray
    class_next: IntArray
    class_sensation: BoolArray
    value_names: tuple[str, ...]
    radices: tuple[int, ...]
    units: tuple[int, ...]
    wrap: bool
    seconds: float = field(default=0.0, compare=False)

    def __post_init__(self) -> None:
        for array in self._arrays():
            array.flags.writeable = False

    def _arrays(self) -> tuple[np.ndarray, ...]:
        return (
            self.pose_codes,
            self.pose_values,
            self.sensation,
            self.next_pose,
            self.blocked,
            self.true_class,
            self.class_next,
            self.class_sensation,
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, GroundTruth):
            return NotImplemented
        return (self.scenario_name, self.actions, self.start_index) == (
            other.scenario_name,
            other.actions,
            other.start_index,
        ) and all(
            np.array_equal(a, b) for a, b in zip(self._arrays(), other._arrays(), strict=True)
        )

    __hash__ = None  # type: ignore[assignment]

    @property
    def n_poses(self) -> int:
        """Reachable poses."""
        return int(self.pose_codes.shape[0])

    @property
    def n_classes(self) -> int:
        """States of the minimal Moore machine."""
        return int(self.class_sensation.shape[0])

    @property
    def n_sensed(self) -> int:
        """Reachable poses whose sensation is true."""
        return int(np.count_nonzero(self.sensation))

    @property
    def n_values(self) -> int:
        """How many values say a pose (:attr:`value_names`)."""
        return len(self.radices)

    @property
    def angles_deg(self) -> IntArray:
        """:attr:`pose_values`, by the arm's name for them."""
        return self.pose_values

    def pose_index(self, values: Sequence[int]) -> int:
        """Index of the pose with these values (an arm's joint angles in degrees, taken modulo
        360; a rover's cell and heading)."""
        items = list(values)
        if len(items) != self.n_values:
            raise TruthError(
                f"{self.scenario_name}: expected {self.n_values} values "
                f"({', '.join(self.value_names)}), found {len(items)}: {items!r}"
            )
        try:
            items = [operator.index(v) for v in items]
        except TypeError:
            raise TruthError(
                f"{self.scenario_name}: pose values must be integers, found {items!r}"
            ) from None
        if self.wrap:
            items = [v % (r * u) for v, r, u in zip(items, self.radices, self.units, strict=True)]
        return int(self.poses_of(np.array([items], dtype=object))[0])

    def poses_of(self, values: ArrayLike) -> NDArray[np.int64]:
        """Pose indices of many poses at once: ``values`` has shape ``(B, n_values)``.

        Raises :class:`TruthError` naming the first pose that is not reachable.
        """
        raw = np.asarray(values)
        if raw.dtype == object:  # Python integers of any size: out of int64 names no pose
            big = [v for v in raw.ravel().tolist() if not -(2**62) < v < 2**62]
            if big:
                raise TruthError(f"{self.scenario_name}: no pose has the value {big[0]}")
        given = raw.reshape(-1, self.n_values)
        found = np.empty(len(given), np.int64)
        for start in range(0, len(given), _POSES_AT_ONCE):  # a long run's columns: bounded
            block = given[start : start + _POSES_AT_ONCE]
            found[start : start + len(block)] = self._pose_block(block.astype(np.int64))
        return found

    def _pose_block(self, given: NDArray[np.int64]) -> NDArray[np.int64]:
        units = np.asarray(self.units, np.int64)
        radices = np.asarray(self.radices, np.int64)
        digits = given // units
        if self.wrap:
            digits %= radices
        else:
            bad = ((digits < 0) | (digits >= radices) | (given % units != 0)).any(axis=1)
            if bad.any():
                first = int(np.argmax(bad))
                raise TruthError(
                    f"{self.scenario_name}: {given[first].tolist()} is not a pose "
                    f"({', '.join(self.value_names)})"
                )
        place = np.concatenate([[1], np.cumprod(radices[:-1])]).astype(np.int64)
        codes = digits @ place
        index = np.searchsorted(self.pose_codes, codes)
        index = np.minimum(index, len(self.pose_codes) - 1)
        unreachable = self.pose_codes[index] != codes
        if unreachable.any():
            first = int(np.argmax(unreachable))
            shown = digits[first] * units if self.wrap else given[first]
            raise TruthError(
                f"{self.scenario_name}: the pose {shown.tolist()} is not reachable from the start"
            )
        return np.asarray(index, dtype=np.int64)

    def classes_of(self, values: ArrayLike) -> NDArray[np.int64]:
        """Classes of many poses at once: ``values`` has shape ``(B, n_values)`` (see
        :meth:`poses_of`)."""
        return np.asarray(self.true_class[self.poses_of(values)], dtype=np.int64)

    def classes_of_table(self, table: Any) -> NDArray[np.int64]:
        """The class of every row of a steps table (its columns :attr:`value_names`), read a
        column at a time (no copy of the table's pose columns as one int64 block)."""
        columns = [table[name].to_numpy() for name in self.value_names]
        if all(column.dtype.kind in "iu" for column in columns):
            return self.classes_of(np.stack(columns, axis=1))
        return self.classes_of(table[list(self.value_names)].to_numpy(dtype=np.int64))

    def class_of(self, values: Sequence[int]) -> int:
        """Class (minimal machine state) of the pose with these values (see
        :meth:`pose_index`)."""
        return int(self.true_class[self.pose_index(values)])

    def minimal_model(self) -> TransitionSystem:
        """The minimal machine as a deterministic, complete model; current = start class 0."""
        model = TransitionSystem(self.n_classes, actions=self.actions)
        for c, row in enumerate(self.class_next.tolist()):
            for action, target in zip(self.actions, row, strict=True):
                model.add(c, target, action)
        model.drain_operations()
        return model

    def classes_reached_from(self, c: int) -> BoolArray:
        """Which classes some action sequence leads to from class ``c`` (``c`` included)."""
        sources = np.repeat(np.arange(self.n_classes, dtype=np.int64), len(self.actions))
        return reached(sources, self.class_next.ravel(), c, self.n_classes)

    def classes_returning_to(self, c: int) -> BoolArray:
        """From which classes some action sequence leads to class ``c`` (``c`` included)."""
        sources = np.repeat(np.arange(self.n_classes, dtype=np.int64), len(self.actions))
        return reached(self.class_next.ravel(), sources, c, self.n_classes)

    def class_labels(self) -> dict[int, bool]:
        """The sensation of every class, as :func:`check_equivalence` takes labels."""
        return dict(enumerate(self.class_sensation.tolist()))

    def to_json(self) -> dict[str, object]:
        """A JSON-ready summary (sizes and timing, not the machine itself)."""
        return {
            "scenario": self.scenario_name,
            "actions": list(self.actions),
            "reachable_poses": self.n_poses,
            "sensed_poses": self.n_sensed,
            "minimal_model_states": self.n_classes,
            "seconds": round(self.seconds, 6),
        }


def format_truth(truth: GroundTruth) -> str:
    """Human-readable summary lines (for ``rsstp-sim truth``)."""
    return "\n".join(
        [
            f"scenario: {truth.scenario_name}",
            f"actions: {' '.join(map(str, truth.actions))}",
            f"reachable poses: {truth.n_poses:,}",
            f"sensed poses: {truth.n_sensed:,}",
            f"minimal model: {truth.n_classes:,} states",
            f"seconds: {truth.seconds:.3f}",
        ]
    )


# --------------------------------------------------------------- enumeration


def check_truth_size(
    scenario: WorldScenario,
    *,
    max_poses: int = 2_000_000,
    max_checks: int | None = None,
    world: World | None = None,
) -> None:
    """Refuse (:class:`TruthError`), before any work, a world too large to enumerate: more
    than ``max_poses`` poses, or (an arm among obstacles) more than ``max_checks``
    link-obstacle checks (None: the body's own bound, the arm's about 20 s of checks); the
    same whether the truth is computed or read from the cache. ``world``: the scenario's
    world when already built (a run's), asked instead of its body."""
    if world is None:
        body_of(scenario).check_size(scenario, max_poses=max_poses, max_checks=max_checks)
    else:
        world.check_size(max_poses=max_poses, max_checks=max_checks)


def compute_truth(
    scenario: WorldScenario,
    *,
    max_poses: int = 2_000_000,
    max_checks: int | None = None,
    world: World | None = None,
) -> GroundTruth:
    """Enumerate the reachable poses of ``scenario`` and minimise their Moore machine.

    Refuses (:class:`TruthError`, before any work) when the body's pose space exceeds
    ``max_poses``, or when checking every move of every pose against every obstacle would
    take more than ``max_checks`` link-obstacle checks (:func:`check_truth_size`).
    ``world``: the scenario's world when already built (a run's): its own table is
    completed (:meth:`~rsstp_sim.interface.World.machine`), not another one; the same truth.
    """
    started = time.perf_counter()
    check_truth_size(scenario, max_poses=max_poses, max_checks=max_checks, world=world)
    machine = body_of(scenario).machine(scenario) if world is None else world.machine()
    return _minimised(scenario.name, tuple(scenario.actions), machine, started)


def _minimised(
    name: str, actions: tuple[int, ...], machine: PoseMachine, started: float
) -> GroundTruth:
    """The machine of reachable poses (by sorted code) and its minimisation."""
    next_pose, sensation = machine.next_pose, machine.sensation
    blocked = next_pose == np.arange(len(machine.codes))[:, None]
    classes = moore_classes(next_pose, sensation)
    true_class, class_next, class_sensation = _canonical(
        classes, next_pose, sensation, machine.start_index
    )
    return GroundTruth(
        scenario_name=name,
        actions=actions,
        pose_codes=machine.codes,
        pose_values=machine.values,
        sensation=sensation,
        next_pose=next_pose,
        blocked=blocked,
        start_index=machine.start_index,
        true_class=true_class,
        class_next=class_next,
        class_sensation=class_sensation,
        value_names=machine.value_names,
        radices=machine.radices,
        units=machine.units,
        wrap=machine.wrap,
        seconds=time.perf_counter() - started,
    )


# -------------------------------------------------------------- minimisation


def _canonical(
    classes: IntArray, next_pose: IntArray, sensation: BoolArray, start_index: int
) -> tuple[IntArray, IntArray, BoolArray]:
    """Renumber classes breadth-first from the start class; the quotient machine."""
    n_classes = int(classes.max()) + 1
    representative = np.empty(n_classes, dtype=np.int64)
    representative[classes] = np.arange(len(classes))
    quotient_next = classes[next_pose[representative]]

    number = np.full(n_classes, -1, dtype=np.int64)
    frontier = classes[[start_index]]
    number[frontier] = 0
    assigned = 1
    while frontier.size:
        successors = quotient_next[frontier].ravel()
        first = np.sort(np.unique(successors, return_index=True)[1])
        candidates = successors[first]
        frontier = candidates[number[candidates] < 0]
        number[frontier] = np.arange(assigned, assigned + len(frontier))
        assigned += len(frontier)

    class_next = np.empty_like(quotient_next)
    class_next[number] = number[quotient_next]
    class_sensation = np.empty(n_classes, dtype=bool)
    class_sensation[number] = sensation[representative]
    return number[classes], class_next, class_sensation


# --------------------------------------------------------------- equivalence


def check_equivalence(
    model: TransitionSystem,
    labels: Mapping[int, bool],
    truth: GroundTruth,
    *,
    start_state: int | None = None,
    start_class: int = 0,
) -> tuple[int, ...] | None:
    """The shortest action sequence on which ``model`` and the truth disagree, or None.

    ``labels[s]`` is the sensation the model predicts in state ``s``. From
    ``start_state`` (default: ``model.current``) and ``start_class`` (default:
    the start pose's class, 0), the
    product of model states and true classes is explored breadth-first over
    ``truth.actions`` in order. The answer is the first sequence found (so the
    shortest, ties broken by action order) after which the model's state has
    no label or the wrong one, or whose last action has no successor or
    several successors in the model. ``()`` means the start already disagrees;
    None means the model is equivalent on everything reachable.
    """
    start = model.current if start_state is None else start_state
    if start not in model:
        raise ModelError(f"check_equivalence: unknown start state {start!r}")
    class_next = truth.class_next.tolist()
    class_sensation = truth.class_sensation.tolist()

    def wrong(state: int, c: int) -> bool:
        label = labels.get(state)
        return label is None or bool(label) != class_sensation[c]

    if not 0 <= start_class < truth.n_classes:
        raise ModelError(
            f"check_equivalence: start class {start_class!r} is not in 0..{truth.n_classes - 1}"
        )
    origin = (start, start_class)
    if wrong(*origin):
        return ()
    parent: dict[tuple[int, int], tuple[tuple[int, int], int]] = {}
    seen = {origin}
    queue = deque([origin])

    def path(pair: tuple[int, int], last: int) -> tuple[int, ...]:
        sequence = [last]
        while pair != origin:
            pair, action = parent[pair]
            sequence.append(action)
        return tuple(reversed(sequence))

    while queue:
        pair = queue.popleft()
        state, c = pair
        for k, action in enumerate(truth.actions):
            successors = model.successors(state, action)
            if len(successors) != 1:
                return path(pair, action)
            following = (successors[0], class_next[c][k])
            if following in seen:
                continue
            if wrong(*following):
                return path(pair, action)
            seen.add(following)
            parent[following] = (pair, action)
            queue.append(following)
    return None
