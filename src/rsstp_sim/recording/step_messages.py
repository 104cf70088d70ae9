"""A step's message bytes from templates: no encoder call per step.

A recorded run writes one ``rsstp.Step`` message a step and a ``blocked`` event for every
blocked move. Most of a step's JSON depends on the pose alone (its sensation, feedback and
ground truth), so :class:`StepMessages` encodes that once per pose and a step's own numbers
with one ``%`` format. A message comes as two parts, the step's head and the pose's tail,
which the chunk writer joins with the rest of the chunk (the tail is not copied per step).
A step that moved (most steps) has a head of its four numbers alone: its tail, the pose's
part with the model's version in it, is kept per pose while the version stays.

The steps come in blocks (:meth:`StepMessages.blocks`) that say such a plain step in four
integers, its action, states and tail number (:class:`Steps`), and give every other message
whole; :class:`BlockMessages` turns blocks into messages, in this process or in the helper
process that builds a long run's chunks (:mod:`~rsstp_sim.recording.chunk_process`), where
the blocks go as a few integers a step.
A blocked event's JSON after its step number depends on the action and the blocker alone,
and is encoded once per pair.

Floats are msgspec's (the encoder of :func:`~rsstp_format.records.encode`), and the
bytes are those of :func:`~rsstp_format.records.encode` on
:func:`~rsstp_sim.recording.builders.step_record` and
:func:`~rsstp_sim.recording.builders.blocked_event`: ``tests/sim/test_step_messages.py``
compares them over live runs (obstacles or none, blocked moves, steps with no transition,
float feedback, one to seven links), and with the records of random steps built field by
field (hypothesis: any floats, ids, blockers and model versions).
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterable, Sized
from typing import TYPE_CHECKING, NamedTuple

from rsstp_format.records import BlockedByRecord, encode, encode_json
from rsstp_format.schemas import STEP_NS
from rsstp_sim.recording import builders
from rsstp_sim.recording.chunks import Message

if TYPE_CHECKING:
    from rsstp_sim.interface import Blocker, Pose, World
    from rsstp_sim.runner import StepOutcome
    from rsstp_sim.transition_system import TransitionSystem

__all__ = ["POSE_CACHE_BYTES", "Block", "BlockMessages", "StepMessages", "Steps"]

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
_EVENT = b'{"step":%d'


class Steps(NamedTuple):
    """Plain steps in a row from step ``first``: ``columns`` holds each one's action, state
    before, internal state and tail number, in turn. A tail number counts the tails of
    ``epoch`` (one epoch a model version): ``new_tails`` are the next ones, in order. A
    blocked step's number is ``~k``: its tail is number ``k`` and the tail of its ``blocked``
    event, which follows it, number ``k + 1``."""

    first: int
    epoch: int
    new_tails: list[bytes]
    columns: list[int]


Block = list["Steps | Message"]
"""Steps' messages in order: plain steps as :class:`Steps`, every other message whole."""


class BlockMessages:
    """Turns blocks into messages, keeping the tails their :class:`Steps` gave: one a run
    (or a helper's part of it), fed its blocks in order."""

    def __init__(self, step_channel: int, event_channel: int) -> None:
        self._channels = step_channel, event_channel
        self._tails: list[bytes] = []
        self._epoch = -1

    def of(self, blocks: Iterable[Block]) -> Generator[Message, None, None]:
        """The messages of ``blocks``, in order: a plain step's on the step channel, a
        blocked step's event on the event channel."""
        step_channel, event_channel = self._channels
        tails = self._tails
        for block in blocks:
            for item in block:
                if item.__class__ is not Steps:
                    yield item  # type: ignore[misc]  # (a Message: not Steps)
                    continue
                first, epoch, new_tails, columns = item  # type: ignore[misc]
                if epoch != self._epoch:
                    tails = self._tails = []
                    self._epoch = epoch
                tails += new_tails
                t = first
                each = iter(columns)
                for action, before, state, tail in zip(each, each, each, each, strict=True):
                    head = _STEP % (t, action, before, state)
                    if tail >= 0:
                        yield step_channel, t * STEP_NS, head, tails[tail]
                    else:
                        at = t * STEP_NS
                        yield step_channel, at, head, tails[~tail]
                        yield event_channel, at, _EVENT % t, tails[-tail]  # (number ~tail + 1)
                    t += 1


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
        self._blocked_truth: dict[Blocker, bytes] = {}
        self._blocked_events: dict[tuple[int, Blocker], bytes] = {}
        # pose -> the number of a plain step's tail at model version ``_version`` (see
        # _tail), counted in the ``_epoch`` th version met
        self._version = -1
        self._epoch = 0
        self._tail_ids: dict[Pose, int] = {}
        self._blocked_ids: dict[tuple[Pose, int], int] = {}  # (pose, action) -> ~number
        self._tails_given = 0  # tails numbered in this epoch
        self._tail_bytes = 0
        self.heavy_bytes = 0
        """The bytes of the new tails and whole messages the blocks have held so far: what
        a block costs beyond its plain steps' integers."""
        self.column_events = 0
        """Blocked events given as a blocked step's tail in :class:`Steps` (not by ``then``)."""

    def _parts(self, pose: Pose) -> tuple[bytes, bytes, int]:
        before, after = pose.truth_json()
        feedback = encode_json(pose.feedback)
        head = _AGENT % (b"true" if pose.sensation else b"false", feedback)
        moved = b"".join((_MOVED, before, _UNBLOCKED, after, b"}}"))
        parts = (head, moved, len(_MOVED) + len(before))
        if self._room > 0:  # bounded: many obstacles, long runs
            self._poses[pose] = parts
            self._room -= len(head) + len(moved)
        return parts

    def restart_tails(self) -> None:
        """Number the tails from 0 again, in a new epoch: the blocks go to a new
        :class:`BlockMessages` (a helper process's, or back from it)."""
        self._new_version()

    def _new_version(self) -> None:
        """Drop the tails kept for the version before: the model changed."""
        self._room += self._tail_bytes
        self._epoch += 1
        self._tail_ids, self._blocked_ids, self._tails_given, self._tail_bytes = {}, {}, 0, 0

    def _tail(self, pose: Pose, version: int) -> bytes:
        """A plain step's message after its own numbers, at ``pose`` and model ``version``:
        the pose's agent part, the version and the rest, one bytes object."""
        head, moved, _ = self._poses.get(pose) or self._parts(pose)
        return b"%b%d%b" % (head, version, moved)

    def first(self, pose: Pose, *, internal_state: int, model_version: int) -> tuple[bytes, bytes]:
        """Step 0's message (the reset, at ``pose``): head and tail."""
        head, moved, _ = self._poses.get(pose) or self._parts(pose)
        return _FIRST_HEAD % (internal_state, head, model_version), moved

    def blocks(
        self,
        outcomes: Iterable[StepOutcome],
        world: World,
        model: TransitionSystem,
        *,
        channel: int,
        waiting: Sized,
        then: Callable[[StepOutcome], Iterable[Message]],
        steps: int,
        max_bytes: int,
    ) -> Generator[Block, None, None]:
        """The messages of the steps of ``outcomes``, as each is taken, in blocks of
        ``steps`` steps (the last one shorter; a block ends sooner once the tails and whole
        messages in it pass ``max_bytes``: a world of many obstacles): a step's
        ``rsstp.Step`` message (at the world's pose and the model's version after the
        step), then, if the step was
        blocked, found no transition, or ``waiting`` is not empty, the messages of
        ``then(outcome)`` (built then). A step that moved by a transition, or was blocked
        while nothing waits, goes into a :class:`Steps` while its tails are kept (then
        ``then`` is not called for it: its only message after is its blocked event); the
        other messages are whole, a step's on ``channel`` (the step channel of the
        :class:`BlockMessages` they go to). When ``outcomes`` fails, the block so far comes
        first."""
        version, tail_ids = self._version, self._tail_ids
        block: Block = []
        columns: list[int] = []
        fresh: list[bytes] = []
        follows = -1  # the step that goes on ``columns``
        taken = 0
        started = self.heavy_bytes  # when the block began
        try:
            for outcome in outcomes:
                t, action, state_before, state_after, blocker, no_transition, _ = outcome
                pose = world.current
                if not no_transition and (blocker is None or not waiting):
                    if model.version != version:
                        version = self._version = model.version
                        self._new_version()
                        tail_ids, follows = self._tail_ids, -1
                    if t != follows:
                        columns, fresh = [], []
                        block.append(Steps(t, self._epoch, fresh, columns))
                    tail: int | bytes | None
                    if blocker is None:
                        tail = tail_ids.get(pose)
                        if tail is None:
                            tail = self._new_tail(pose, version, fresh)
                    else:
                        tail = self._blocked_tail(pose, action, blocker, version, fresh)
                    if tail.__class__ is int:
                        columns += (action, state_before, state_after, tail)
                        follows = t + 1
                    elif blocker is None:  # not kept (the bound): the message whole
                        head = _STEP % (t, action, state_before, state_after)
                        block.append((channel, t * STEP_NS, head, tail))  # type: ignore[arg-type]
                        follows = -1
                    else:  # the same, and its event after it
                        whole = self._whole_step(outcome, pose, model.version)
                        block.append((channel, t * STEP_NS, *whole))
                        self._follow(block, then, outcome)
                        follows = -1
                    if waiting:
                        self._follow(block, then, outcome)
                        follows = -1
                else:
                    whole = self._whole_step(outcome, pose, model.version)
                    block.append((channel, t * STEP_NS, *whole))
                    self._follow(block, then, outcome)
                    follows = -1
                taken += 1
                if taken == steps or self.heavy_bytes - started > max_bytes:
                    yield block
                    block, taken, follows, started = [], 0, -1, self.heavy_bytes
        except GeneratorExit:
            raise
        except BaseException:
            if block:
                yield block
            raise
        if block:
            yield block

    def _follow(
        self, block: Block, then: Callable[[StepOutcome], Iterable[Message]], outcome: StepOutcome
    ) -> None:
        """Add ``then(outcome)``'s messages to ``block``, counted in :attr:`heavy_bytes`."""
        for message in then(outcome):
            block.append(message)
            self.heavy_bytes += len(message[2]) + len(message[3])

    def _whole_step(self, outcome: StepOutcome, pose: Pose, version: int) -> tuple[bytes, bytes]:
        """The message of a step that was blocked or found no transition: head and tail
        (counted in the block's bytes)."""
        t, action, state_before, state_after, blocker, no_transition, _ = outcome
        head, rest = self._agent_and_rest(pose, blocker, no_transition=no_transition)
        self.heavy_bytes += len(rest)
        return _HEAD % (t, action, state_before, state_after, head, version), rest

    def _agent_and_rest(
        self, pose: Pose, blocker: Blocker | None, *, no_transition: bool
    ) -> tuple[bytes, bytes]:
        """A step's message at ``pose`` around its model version: the agent's part before it,
        and everything after it (its ``no_transition`` and its truth, ``blocker`` in it)."""
        head, moved, cut = self._poses.get(pose) or self._parts(pose)
        rest = _TAIL % (
            b"true" if no_transition else b"false",
            moved[len(_MOVED) : cut],
            _UNBLOCKED if blocker is None else self._blocked(blocker),
            moved[cut + len(_UNBLOCKED) : -2],
        )
        return head, rest

    def _blocked_tail(
        self, pose: Pose, action: int, blocker: Blocker, version: int, fresh: list[bytes]
    ) -> int | None:
        """The number of a step blocked at ``pose`` by ``action`` at ``version`` (see
        :class:`Steps`), its tails added to ``fresh`` if new; None past the bound."""
        key = (pose, action)
        number = self._blocked_ids.get(key)
        if number is None:
            if self._room <= 0:
                return None
            head, rest = self._agent_and_rest(pose, blocker, no_transition=False)
            step = b"%b%d%b" % (head, version, rest)
            number = self._blocked_ids[key] = ~self._give(
                fresh, step, self._event_tail(action, blocker)
            )
        self.column_events += 1
        return number

    def _new_tail(self, pose: Pose, version: int, fresh: list[bytes]) -> int | bytes:
        """The tail number of ``pose`` at ``version``, its tail added to ``fresh``; or,
        past the bound, the tail itself (not kept). Either counts in the block's bytes."""
        tail = self._tail(pose, version)
        if self._room <= 0:
            self.heavy_bytes += len(tail)
            return tail
        number = self._tail_ids[pose] = self._give(fresh, tail)
        return number

    def _give(self, fresh: list[bytes], *tails: bytes) -> int:
        """Number ``tails`` next in this epoch and add them to ``fresh`` (kept, counted in the
        bound and in the block's bytes); the first one's number."""
        first = self._tails_given
        size = sum(map(len, tails))
        fresh += tails
        self._tails_given += len(tails)
        self._room -= size
        self._tail_bytes += size
        self.heavy_bytes += size
        return first

    def _blocked(self, blocker: Blocker) -> bytes:
        truth = self._blocked_truth.get(blocker)
        if truth is None:
            by = encode_json(BlockedByRecord.of(blocker))
            truth = self._blocked_truth[blocker] = b'"blocked":true,"blocked_by":' + by
        return truth

    def blocked_event(self, step: int, action: int, blocker: Blocker) -> bytes:
        """The ``blocked`` event of ``action`` at ``step``."""
        return _EVENT % step + self._event_tail(action, blocker)

    def _event_tail(self, action: int, blocker: Blocker) -> bytes:
        """The ``blocked`` event of ``action`` after its step number."""
        key = (action, blocker)
        tail = self._blocked_events.get(key)
        if tail is None:
            whole = encode(builders.blocked_event(0, action=action, blocker=blocker))
            tail = self._blocked_events[key] = whole.removeprefix(_EVENT % 0)
        return tail
