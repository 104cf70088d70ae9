"""A step's message bytes from templates: no encoder call per step.

A recorded run writes one ``rsstp.Step`` message a step and a ``blocked`` event for every
blocked move. Most of a step's JSON depends on the pose alone (its sensation, feedback and
ground truth), so :class:`StepMessages` encodes that once per pose and a step's own numbers
with one ``%`` format. A message comes as two parts, the step's head and the pose's tail,
which the chunk writer joins with the rest of the chunk (the tail is not copied per step).
A step that moved (most steps) has a head of its four numbers alone: its tail, the pose's
part with the model's version in it, is kept per pose while the version stays.
A blocked event's JSON after its step number depends on the action and the blocker alone,
and is encoded once per pair.

Floats are msgspec's (the encoder of :func:`~rsstp_sim.recording.records.encode`), and the
bytes are those of :func:`~rsstp_sim.recording.records.encode` on
:func:`~rsstp_sim.recording.builders.step_record` and
:func:`~rsstp_sim.recording.builders.blocked_event`: ``tests/sim/test_step_messages.py``
compares them over live runs (obstacles or none, blocked moves, steps with no transition,
float feedback, one to seven links).
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterable, Sized
from typing import TYPE_CHECKING

from rsstp_sim.recording import builders
from rsstp_sim.recording.chunks import Message
from rsstp_sim.recording.records import encode, encode_json
from rsstp_sim.recording.schemas import STEP_NS

if TYPE_CHECKING:
    from rsstp_sim.coupling import StepOutcome
    from rsstp_sim.geometry import Blocker
    from rsstp_sim.transition_system import TransitionSystem
    from rsstp_sim.world import Pose, World

__all__ = ["POSE_CACHE_BYTES", "StepMessages"]

POSE_CACHE_BYTES = 128 * 1024 * 1024
"""The most bytes of poses' encoded parts and tails kept for the poses met again
(three-joint's 39,232 poses take 23 MB of parts and as much of tails; a pose among 1,000
obstacles 60 KB, its 3,000 distances): the poses met after that are encoded at each visit."""

_STEP = b'{"step":%d,"agent":{"action":%d,"state_before":%d,"internal_state":%d'
_HEAD = _STEP + b"%b%d"
_FIRST_HEAD = b'{"step":0,"agent":{"internal_state":%d%b%d'
_AGENT = b',"sensation":%b,"feedback":%b,"model_version":'
_MOVED = b',"no_transition":false},"truth":{'
_UNBLOCKED = b'"blocked":false'
_TAIL = b',"no_transition":%b},"truth":{%b%b%b}}'


class StepMessages:
    """The ``rsstp.Step`` and ``blocked`` event message bytes of one run's steps.

    Poses are the world's cached objects (compared by identity), so the per-pose parts are
    kept for as long as the run's world keeps its poses.
    """

    def __init__(self, *, cache_bytes: int = POSE_CACHE_BYTES) -> None:
        # pose -> (the agent part after internal_state, the tail of a step that moved with
        # a transition, where its truth's "blocked" field starts in that tail)
        self._poses: dict[Pose, tuple[bytes, bytes, int]] = {}
        self._room = cache_bytes  # bytes the kept parts and tails may still take
        self._truth: tuple[bytes, bytes] | None = None  # templates around "blocked"
        self._blocked_truth: dict[Blocker, bytes] = {}
        self._blocked_events: dict[tuple[int, Blocker], bytes] = {}
        # pose -> a plain step's tail at model version ``_version`` (see _tail)
        self._version = -1
        self._tails: dict[Pose, bytes] = {}
        self._tail_bytes = 0

    def _parts(self, pose: Pose) -> tuple[bytes, bytes, int]:
        angles, positions, distances = pose.truth_values()
        if self._truth is None:
            self._truth = _truth_templates(len(angles), len(distances) // len(angles))
        texts = encode_json([pose.feedback, *positions, *distances])[1:-1].split(b",")
        points = 1 + len(positions)
        before = self._truth[0] % (*angles, *texts[1:points])
        after = self._truth[1] % tuple(texts[points:])
        head = _AGENT % (b"true" if pose.sensation else b"false", texts[0])
        moved = b"".join((_MOVED, before, _UNBLOCKED, after, b"}}"))
        parts = (head, moved, len(_MOVED) + len(before))
        if self._room > 0:  # bounded: many obstacles, long runs
            self._poses[pose] = parts
            self._room -= len(head) + len(moved)
        return parts

    def _new_version(self, version: int) -> dict[Pose, bytes]:
        """Drop the tails kept for the version before: the model changed."""
        self._room += self._tail_bytes
        self._version, self._tails, self._tail_bytes = version, {}, 0
        return self._tails

    def _tail(self, pose: Pose) -> bytes:
        """A plain step's message after its own numbers, at ``pose`` and the current version:
        the pose's agent part, the version and the rest, one bytes object."""
        head, moved, _ = self._poses.get(pose) or self._parts(pose)
        tail = b"%b%d%b" % (head, self._version, moved)
        if self._room > 0:
            self._tails[pose] = tail
            self._room -= len(tail)
            self._tail_bytes += len(tail)
        return tail

    def first(self, pose: Pose, *, internal_state: int, model_version: int) -> tuple[bytes, bytes]:
        """Step 0's message (the reset, at ``pose``): head and tail."""
        head, moved, _ = self._poses.get(pose) or self._parts(pose)
        return _FIRST_HEAD % (internal_state, head, model_version), moved

    def stream(
        self,
        outcomes: Iterable[StepOutcome],
        world: World,
        model: TransitionSystem,
        *,
        channel: int,
        waiting: Sized,
        then: Callable[[StepOutcome], Iterable[Message]],
    ) -> Generator[Message, None, None]:
        """The messages of each step of ``outcomes``, as it is taken: its ``rsstp.Step``
        message on ``channel`` (at the world's pose and the model's version after the step),
        then, if the step was blocked, found no transition, or ``waiting`` is not empty, the
        messages of ``then(outcome)``."""
        kept, parts_of = self._poses.get, self._parts
        version, tails = self._version, self._tails
        for outcome in outcomes:
            t, action, state_before, state_after, blocker, no_transition, _ = outcome
            pose = world.current
            if blocker is None and not no_transition:
                if model.version != version:
                    version, tails = model.version, self._new_version(model.version)
                tail = tails.get(pose)
                if tail is None:
                    tail = self._tail(pose)
                yield channel, t * STEP_NS, _STEP % (t, action, state_before, state_after), tail
                if waiting:
                    yield from then(outcome)
                continue
            head, moved, cut = kept(pose) or parts_of(pose)
            first = _HEAD % (t, action, state_before, state_after, head, model.version)
            tail = _TAIL % (
                b"true" if no_transition else b"false",
                moved[len(_MOVED) : cut],
                _UNBLOCKED if blocker is None else self._blocked(blocker),
                moved[cut + len(_UNBLOCKED) : -2],
            )
            yield channel, t * STEP_NS, first, tail
            yield from then(outcome)

    def _blocked(self, blocker: Blocker) -> bytes:
        truth = self._blocked_truth.get(blocker)
        if truth is None:
            by = encode_json(builders.blocked_by_record(blocker))
            truth = self._blocked_truth[blocker] = b'"blocked":true,"blocked_by":' + by
        return truth

    def blocked_event(self, step: int, action: int, blocker: Blocker) -> bytes:
        """The ``blocked`` event of ``action`` at ``step``."""
        key = (action, blocker)
        tail = self._blocked_events.get(key)
        if tail is None:
            whole = encode(builders.blocked_event(0, action=action, blocker=blocker))
            tail = self._blocked_events[key] = whole.removeprefix(b'{"step":0')
        return b'{"step":%d%b' % (step, tail)


def _truth_templates(n: int, m: int) -> tuple[bytes, bytes]:
    """The truth record of an arm of ``n`` links among ``m`` obstacles, before its
    ``blocked`` field (angles, then the points' float texts) and after it (the distances')."""
    angles = b",".join([b"%d"] * n)
    points = b",".join([b'{"x":%b,"y":%b}'] * (n + 1))
    tips = b",".join([b'{"obstacles":[' + b",".join([b"%b"] * m) + b"]}"] * n)
    return (
        b'"angles_deg":[' + angles + b'],"joint_positions":[' + points + b"],",
        b',"distances":[' + tips + b"]",
    )
