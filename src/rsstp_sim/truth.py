"""Ground truth: the world as a finite Moore machine, minimised (docs/model.md).

Joint angles are integers, so the poses reachable from the start pose are
finitely many. With a blocked move read as a self-loop, those poses and the
scenario's actions form a deterministic machine whose output in a pose is the
boolean sensation: a Moore machine. Its minimisation (partition refinement) is
the smallest internal model that predicts every sensation correctly, the
reference against which a learned model is judged (:func:`check_equivalence`).

Poses are identified by their code ``sum_i angle_i * 360**i`` (as in
:class:`~rsstp_sim.world.World`). The reachable poses, their moves and their
sensations come from the scenario's :class:`~rsstp_sim.world_table.WorldTable`
completed (breadth first, whole frontiers per vectorised batch); nothing
here loops over poses in Python.

>>> from rsstp_sim.scenario import load_scenario
>>> truth = compute_truth(load_scenario("thesis-roulette"))
>>> truth.n_poses, truth.n_sensed, truth.n_classes
(4, 1, 4)
>>> truth.class_of([180]), truth.class_next.tolist()
(2, [[1], [2], [3], [0]])
>>> check_equivalence(truth.minimal_model(), {0: True, 1: False, 2: False, 3: False}, truth)
>>> check_equivalence(truth.minimal_model(), {0: True, 1: False, 2: True, 3: False}, truth)
(0, 0)
"""

from __future__ import annotations

import operator
import time
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from rsstp_sim._arrays import BoolArray, IntArray
from rsstp_sim.errors import ModelError, TruthError
from rsstp_sim.moore import moore_classes
from rsstp_sim.scenario import Scenario
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.world_table import (
    MAX_TABULATION_CHECKS,
    WorldTable,
    pose_space_size,
    tabulation_checks,
)

__all__ = [
    "MAX_TRUTH_CHECKS",
    "GroundTruth",
    "TruthError",
    "check_truth_size",
    "check_equivalence",
    "compute_truth",
    "format_truth",
    "pose_space_size",
]


@dataclass(frozen=True, eq=False)
class GroundTruth:
    """The reachable poses of a scenario as a Moore machine, and its minimisation.

    Pose index ``p`` (``0 .. P-1``) follows the sorted pose codes. For action
    ``actions[k]`` (see :class:`~rsstp_sim.world.World`), ``next_pose[p, k]``
    is the pose reached from ``p`` (``p`` itself when ``blocked[p, k]``).
    ``true_class[p]`` is the pose's class in the minimal machine; classes are
    numbered breadth-first from the start pose's class (0) over the actions in
    order, so the numbering depends only on the machine's behaviour.
    ``seconds`` (wall time of the computation) takes no part in equality.
    Arrays are read-only.
    """

    scenario_name: str
    actions: tuple[int, ...]
    pose_codes: IntArray
    angles_deg: IntArray
    sensation: BoolArray
    next_pose: IntArray
    blocked: BoolArray
    start_index: int
    true_class: IntArray
    class_next: IntArray
    class_sensation: BoolArray
    seconds: float = field(default=0.0, compare=False)

    def __post_init__(self) -> None:
        for array in self._arrays():
            array.flags.writeable = False

    def _arrays(self) -> tuple[np.ndarray, ...]:
        return (
            self.pose_codes,
            self.angles_deg,
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
    def n_joints(self) -> int:
        return int(self.angles_deg.shape[1])

    def pose_index(self, angles_deg: Sequence[int]) -> int:
        """Index of the pose with these joint angles (degrees, taken modulo 360)."""
        angles = list(angles_deg)
        if len(angles) != self.n_joints:
            raise TruthError(
                f"{self.scenario_name}: expected {self.n_joints} joint angles, "
                f"found {len(angles)}: {angles!r}"
            )
        try:
            code = sum((operator.index(a) % 360) * 360**i for i, a in enumerate(angles))
        except TypeError:
            raise TruthError(
                f"{self.scenario_name}: joint angles must be integers, found {angles!r}"
            ) from None
        index = int(np.searchsorted(self.pose_codes, code))
        if index == self.n_poses or int(self.pose_codes[index]) != code:
            raise TruthError(
                f"{self.scenario_name}: the pose {[a % 360 for a in angles]} "
                f"is not reachable from the start pose"
            )
        return index

    def poses_of(self, angles_deg: ArrayLike) -> NDArray[np.int64]:
        """Pose indices of many poses at once: ``angles_deg`` has shape ``(B, n)``.

        Raises :class:`TruthError` naming the first pose that is not reachable.
        """
        angles = np.asarray(angles_deg, dtype=np.int64).reshape(-1, self.n_joints) % 360
        codes = angles @ (360 ** np.arange(self.n_joints, dtype=np.int64))
        index = np.searchsorted(self.pose_codes, codes)
        index = np.minimum(index, len(self.pose_codes) - 1)
        unreachable = self.pose_codes[index] != codes
        if unreachable.any():
            first = int(np.argmax(unreachable))
            raise TruthError(
                f"{self.scenario_name}: the pose {angles[first].tolist()} is not reachable "
                f"from the start"
            )
        return np.asarray(index, dtype=np.int64)

    def classes_of(self, angles_deg: ArrayLike) -> NDArray[np.int64]:
        """Classes of many poses at once: ``angles_deg`` has shape ``(B, n)`` (see
        :meth:`poses_of`)."""
        return np.asarray(self.true_class[self.poses_of(angles_deg)], dtype=np.int64)

    def class_of(self, angles_deg: Sequence[int]) -> int:
        """Class (minimal machine state) of the pose with these joint angles."""
        return int(self.true_class[self.pose_index(angles_deg)])

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
        return _reached(sources, self.class_next.ravel(), c, self.n_classes)

    def classes_returning_to(self, c: int) -> BoolArray:
        """From which classes some action sequence leads to class ``c`` (``c`` included)."""
        sources = np.repeat(np.arange(self.n_classes, dtype=np.int64), len(self.actions))
        return _reached(self.class_next.ravel(), sources, c, self.n_classes)

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


def _reached(tail: IntArray, head: IntArray, start: int, n: int) -> BoolArray:
    """The nodes ``0 .. n-1`` reached from ``start`` along the edges ``tail[i] -> head[i]``,
    breadth first, a whole frontier per numpy call."""
    order = np.argsort(tail, kind="stable")
    heads = head[order]
    bounds = np.searchsorted(tail[order], np.arange(n + 1, dtype=np.int64))
    seen = np.zeros(n, np.bool_)
    seen[start] = True
    frontier = np.array([start], np.int64)
    while len(frontier):
        lo, hi = bounds[frontier], bounds[frontier + 1]
        sizes = hi - lo
        offsets = np.repeat(lo - np.cumsum(sizes) + sizes, sizes) + np.arange(int(sizes.sum()))
        following = np.unique(heads[offsets])
        frontier = following[~seen[following]]
        seen[frontier] = True
    return seen


# --------------------------------------------------------------- enumeration


MAX_TRUTH_CHECKS = MAX_TABULATION_CHECKS
"""The most link-against-obstacle move checks :func:`compute_truth` takes on, counted over the
pose lattice (:func:`~rsstp_sim.world_table.tabulation_checks`): about 20 s on this project's
machine. Three joints at 5 degrees among 1,000 obstacles count 6.7 billion; they took 130 s and
8.6 GB before this bound."""


def check_truth_size(
    scenario: Scenario, *, max_poses: int = 2_000_000, max_checks: int = MAX_TRUTH_CHECKS
) -> None:
    """Refuse (:class:`TruthError`) a world whose :func:`pose_space_size` exceeds
    ``max_poses``, or whose every move of every pose checked against every obstacle would take
    more than ``max_checks`` link-obstacle checks: before any work, and the same whether the
    truth is computed or read from the cache."""
    bound = pose_space_size(scenario)
    if bound > max_poses:
        raise TruthError(
            f"{scenario.name}: the pose space has {bound:,} poses, more than the "
            f"limit of {max_poses:,} (pass a larger max_poses)"
        )
    n_actions, n_links = len(scenario.actions), scenario.n_joints
    checks = tabulation_checks(scenario)
    if checks > max_checks:
        raise TruthError(
            f"{scenario.name}: refused: tabulating the world would take about {checks:,} "
            f"link-obstacle checks ({bound:,} poses x {n_actions} moves x {n_links} links x "
            f"{len(scenario.obstacles):,} obstacles), more than the {max_checks:,} (about "
            "20 s) the ground truth takes on"
        )


def compute_truth(
    scenario: Scenario, *, max_poses: int = 2_000_000, max_checks: int = MAX_TRUTH_CHECKS
) -> GroundTruth:
    """Enumerate the reachable poses of ``scenario`` and minimise their Moore machine.

    Refuses (:class:`TruthError`, before any work) when :func:`pose_space_size` exceeds
    ``max_poses``, or when checking every move of every pose against every obstacle would
    take more than ``max_checks`` link-obstacle checks (:data:`MAX_TRUTH_CHECKS`).
    """
    started = time.perf_counter()
    check_truth_size(scenario, max_poses=max_poses, max_checks=max_checks)
    table = WorldTable(scenario)
    table.complete()
    # The table's rows are in the order the poses were reached; the truth's are by code.
    codes = np.frombuffer(table.codes, dtype=np.int64)
    order = np.argsort(codes, kind="stable")
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    pose_codes = codes[order].copy()
    next_pose = rank[table.next_array()[order]]
    angles = table.angles()[order]
    sensation = table.sensations()[order]
    start_index = int(rank[0])
    blocked = next_pose == np.arange(len(pose_codes))[:, None]

    classes = moore_classes(next_pose, sensation)
    true_class, class_next, class_sensation = _canonical(classes, next_pose, sensation, start_index)
    return GroundTruth(
        scenario_name=scenario.name,
        actions=tuple(scenario.actions),
        pose_codes=pose_codes,
        angles_deg=angles,
        sensation=sensation,
        next_pose=next_pose,
        blocked=blocked,
        start_index=start_index,
        true_class=true_class,
        class_next=class_next,
        class_sensation=class_sensation,
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
