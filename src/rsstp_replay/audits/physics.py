"""The physics check: does the recording's world follow from its scenario and its actions?

A recording states a scenario (the attached scenario file, and the ``/rsstp/scenario`` message)
and, at every step, the action taken and the world's answer: the pose, the joint positions,
the sensation and feedback, the obstacle distances, whether the move was blocked and by what
(and a ``blocked`` event for it). The world is deterministic, so all of that follows from the
scenario and the actions alone. :func:`check_physics` re-simulates it with
:class:`~rsstp_sim.arm.world.World`, never importing the strategy (no code of the recording's
runs), and compares every recorded ground-truth field at every step, naming the first
difference by step and field.

It is fast because the world's answers repeat: the ground truth of a step is a function of
its pose and its blocker, so the expected bytes of each (pose, blocker) pair are encoded once,
as the recorder encodes them, and each step's recorded truth bytes are compared with them; a
step whose bytes differ is decoded whole and compared field by field (a file rewritten by
another JSON writer, say ``"x": 1.0`` for ``"x":1.0``, still passes when the values agree).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import msgspec
import numpy as np
import pandas as pd
from numpy.typing import NDArray

from rsstp_format import records
from rsstp_replay.errors import PhysicsDifference
from rsstp_sim.arrays import distinct
from rsstp_sim.bodies import make_world
from rsstp_sim.errors import ActionError
from rsstp_sim.recording import builders
from rsstp_sim.strategies import StrategyOrigin

IntArray = NDArray[np.int64]  # (rsstp_sim.arrays is the simulator's own)

if TYPE_CHECKING:
    import pandas as pd

    from rsstp_replay.reader.recording import Recording

__all__ = ["PhysicsFindings", "check_physics"]

_TRUTH_KEY = b',"truth":'


@dataclass(frozen=True, slots=True)
class PhysicsFindings:
    """What :func:`check_physics` found: ``difference`` is None when the recording's world
    follows from its scenario and actions at every step, else the first difference (``step``
    is None for one in the scenario)."""

    steps: int
    step: int | None
    field: str | None
    difference: str | None

    @property
    def holds(self) -> bool:
        return self.difference is None

    def to_text(self) -> str:
        if self.difference is None:
            return (
                f"physics: the world follows from the scenario and the actions at every one of "
                f"the {self.steps + 1:,} steps"
            )
        where = "the scenario" if self.step is None else f"step {self.step:,}"
        return f"physics: broken at {where}, {self.field}: {self.difference}"

    def to_json(self) -> dict[str, Any]:
        return {
            "holds": self.holds,
            "steps": self.steps,
            "step": self.step,
            "field": self.field,
            "difference": self.difference,
        }


def check_physics(
    recording: Recording,
    steps: pd.DataFrame | None = None,
    *,
    events: pd.DataFrame | None = None,
) -> PhysicsFindings:
    """Re-simulate ``recording``'s world from its attached scenario and recorded actions and
    compare every ground-truth field of every step (see the module docstring). ``steps``, when
    given, is the recording's steps table already read (its ``action``, ``sensation`` and
    ``feedback`` columns are used; the audit passes the one it has, saving a second decoding
    of every step); ``events`` likewise its events table (its ``text`` and ``data`` may be
    categorical)."""
    try:
        world = make_world(recording.scenario)
        _check_scenario_message(recording, world)
        if steps is None:
            steps = recording.steps(geometry=False)
        actions = steps["action"].to_numpy(dtype=np.int64, na_value=-1)
        rows, blockers = _simulate(recording, world, actions, steps)
        _check_agent_view(steps, world, rows)
        _check_truth(recording, world, rows, blockers)
        _check_blocked_events(
            recording.events() if events is None else events, world, actions, blockers
        )
    except PhysicsDifference as broken:
        return PhysicsFindings(recording.n_steps, broken.step, broken.field, broken.difference)
    return PhysicsFindings(recording.n_steps, None, None, None)


def _check_scenario_message(recording: Recording, world: Any) -> None:
    """The ``/rsstp/scenario`` message must be what the attached scenario file gives (its
    ``world``)."""
    found = recording.scenario_record
    strategy = found.strategy
    expected = builders.scenario_record(
        world,
        seed=found.seed,
        strategy_name=strategy.name,
        strategy_params=strategy.param_values(),
        strategy_origin=StrategyOrigin(
            strategy.import_path, strategy.distribution, strategy.version
        ),
    )
    for name in found.__struct_fields__:
        want, got = getattr(expected, name), getattr(found, name)
        if want != got:
            raise PhysicsDifference(
                None,
                f"/rsstp/scenario {name}",
                f"the message says {_plain(got)}, the attached scenario file gives {_plain(want)}",
            )


def _plain(value: object) -> str:
    return json.dumps(msgspec.to_builtins(value), separators=(",", ":"))


def _simulate(
    recording: Recording, world: Any, actions: IntArray, steps: pd.DataFrame
) -> tuple[IntArray, IntArray]:
    """``world`` walked through the recorded actions: the table row of every step's pose and
    the blocker code of every move (step 0 is the start pose, not blocked)."""
    try:
        rows, blockers = world.follow(actions, steps)
    except ActionError:
        raise _unknown_action(actions, recording.scenario.actions) from None
    # Kept for the whole check: a long run's rows and blockers in the narrowest dtypes.
    return _narrowed(rows), _narrowed(blockers)


def _narrowed(values: IntArray) -> Any:
    """``values`` (non-negative) in the narrowest signed dtype that holds them."""
    return values.astype(np.min_scalar_type(-int(values.max(initial=0)) - 1), copy=False)


def _unknown_action(actions: IntArray, known: tuple[int, ...]) -> PhysicsDifference:
    step = 1 + int(np.flatnonzero(~np.isin(actions[1:], list(known)))[0])
    return PhysicsDifference(
        step,
        "agent.action",
        f"{actions[step]} is not one of the scenario's actions {sorted(known)}",
    )


def _check_agent_view(steps: pd.DataFrame, world: Any, rows: IntArray) -> None:
    """The sensation and the feedback the agent was given are the world's at its pose."""
    all_sensations, all_feedback = world.senses()
    recorded = (steps["sensation"].to_numpy(bool), steps["feedback"].to_numpy(np.float64))
    for start in range(0, len(rows), _ROWS_AT_ONCE):  # a long run: a block of steps at a time
        block = rows[start : start + _ROWS_AT_ONCE]
        for name, want, got in (
            ("agent.sensation", all_sensations[block], recorded[0][start : start + len(block)]),
            ("agent.feedback", all_feedback[block], recorded[1][start : start + len(block)]),
        ):
            wrong = np.flatnonzero(want != got)
            if wrong.size:
                t = int(wrong[0])
                raise PhysicsDifference(
                    start + t,
                    name,
                    f"recorded {_scalar(got[t])}, the world gives {_scalar(want[t])}",
                )


_ROWS_AT_ONCE = 1 << 20
"""Steps whose sensation and feedback :func:`_check_agent_view` compares together."""


def _check_truth(recording: Recording, world: Any, rows: IntArray, blockers: IntArray) -> None:
    """Every step message's truth, against the bytes the recorder writes for its pose and
    blocker (each pair encoded once)."""
    width = int(blockers.max(initial=0)) + 1

    def keys_of(start: int, stop: int) -> IntArray:
        return rows[start:stop].astype(np.int64) * width + blockers[start:stop]

    found = distinct(  # a block of steps at a time: no int64 key per step kept
        np.concatenate(
            [distinct(keys_of(a, a + _ROWS_AT_ONCE)) for a in range(0, len(rows), _ROWS_AT_ONCE)]
            or [np.empty(0, np.int64)]
        )
    )
    expected = []
    for key in found.tolist():
        row, code = divmod(key, width)
        truth = world.truth_at(row, code)
        expected.append(_TRUTH_KEY + records.encode_json(truth) + b"}")
    step = 0
    for data, starts, ends in recording.step_message_bytes():
        chunk_keys = np.searchsorted(found, keys_of(step, step + len(starts))).tolist()
        if len(chunk_keys) != len(starts):  # pragma: no cover - the steps were counted
            raise PhysicsDifference(step, "truth", "more step messages than steps")
        tails = list(map(expected.__getitem__, chunk_keys))
        # One C-level pass over the chunk's messages, in place; Python looks closer only
        # at a mismatch.
        if not all(map(data.endswith, tails, starts, ends)):
            for offset, (a, b, tail) in enumerate(zip(starts, ends, tails, strict=True)):
                if not data.endswith(tail, a, b):
                    _compare_decoded(step + offset, data[a:b], tail[len(_TRUTH_KEY) : -1])
        step += len(starts)


def _compare_decoded(step: int, data: bytes, want: bytes) -> None:
    """A message whose truth bytes differ from the world's: compare the values, field by
    field (equal values written another way pass)."""
    try:
        found = msgspec.json.decode(data)
        expected = msgspec.json.decode(want)
    except (msgspec.DecodeError, RecursionError) as exc:  # pragma: no cover - read before
        raise PhysicsDifference(step, "truth", f"the message does not decode: {exc}") from None
    truth = found.get("truth") if isinstance(found, dict) else None
    if not isinstance(truth, dict):
        raise PhysicsDifference(step, "truth", "the message has no truth object")
    for name, value in expected.items():
        got = truth.get(name)
        if name == "blocked_by" and got is None and value is None:
            continue
        path = _first_difference(value, got, f"truth.{name}")
        if path is not None:
            raise PhysicsDifference(
                step,
                path[0],
                f"recorded {_plain(path[2])}, the world gives {_plain(path[1])}",
            )
    extra = sorted(set(truth) - set(expected))
    if extra:
        raise PhysicsDifference(
            step, f"truth.{extra[0]}", "recorded, but the world has no such field"
        )


def _first_difference(want: object, got: object, path: str) -> tuple[str, object, object] | None:
    if isinstance(want, dict) and isinstance(got, dict):
        for key in sorted(set(want) | set(got)):
            found = _first_difference(want.get(key), got.get(key), f"{path}.{key}")
            if found is not None:
                return found
        return None
    if isinstance(want, list) and isinstance(got, list) and len(want) == len(got):
        for i, (w, g) in enumerate(zip(want, got, strict=True)):
            found = _first_difference(w, g, f"{path}[{i}]")
            if found is not None:
                return found
        return None
    same = type(want) is type(got) or (
        isinstance(want, int | float)
        and isinstance(got, int | float)
        and not (isinstance(want, bool) or isinstance(got, bool))
    )
    return None if same and want == got else (path, want, got)


def _scalar(value: object) -> str:
    return repr(value.item() if isinstance(value, np.generic) else value)


def _check_blocked_events(
    events: pd.DataFrame, world: Any, actions: IntArray, blockers: IntArray
) -> None:
    """A ``blocked`` event at exactly the blocked steps, with the action and the blocker.

    An event's text and data depend only on the action and the blocker, so each pair's are
    built once, and each distinct (pair, recorded text, recorded data) is compared once: data
    as decoded JSON (key order and spacing do not count). The events are matched in numpy (a
    long run has millions); the first that differs is named."""
    blocked_steps = np.flatnonzero(blockers)
    width_blocker = int(blockers.max(initial=0)) + 1
    pair_codes, pairs = _factorized_ints(
        actions[blocked_steps].astype(np.int64) * width_blocker + blockers[blocked_steps]
    )
    made: list[tuple[str, object]] = []
    for action, code in (divmod(int(pair), width_blocker) for pair in pairs):
        blocker = world.blocker_of(code)
        assert blocker is not None  # a non-zero code always names a blocker
        event = builders.blocked_event(0, action=action, blocker=blocker)
        made.append((event.text, msgspec.to_builtins(event.data)))
    # The blocked events' rows by position: no copy of the table's text columns.
    rows = np.flatnonzero((events["kind"] == "blocked").to_numpy())
    found_steps = events["step"].to_numpy(np.int64)[rows]
    texts, text_codes = _factorized(events["text"])
    datas, data_codes = _factorized(events["data"])
    text_codes, data_codes = text_codes[rows], data_codes[rows]
    common = min(len(blocked_steps), len(found_steps))
    same = blocked_steps[:common] == found_steps[:common]
    # Each distinct (pair, text, data) among the events at the right steps, judged once.
    width_text, width_data = max(len(texts), 1), max(len(datas), 1)
    triple = (pair_codes[:common] * width_text + text_codes[:common]) * width_data + data_codes[
        :common
    ]
    triple_codes, distinct = _factorized_ints(triple[same])
    right = np.ones(len(distinct), np.bool_)
    decode = msgspec.json.decode
    for index, value in enumerate(distinct):
        rest, data = divmod(value, width_data)
        pair, text = divmod(rest, width_text)
        right[index] = made[pair][0] == texts[text] and made[pair][1] == decode(datas[data])
    ok = same.copy()
    ok[same] = right[triple_codes]
    wrong = np.flatnonzero(~ok)
    if len(wrong):
        at = int(wrong[0])
        want_step, want_text = int(blocked_steps[at]), made[int(pair_codes[at])][0]
        got_step, got_text = int(found_steps[at]), str(texts[text_codes[at]])
        if want_step < got_step:
            raise PhysicsDifference(
                want_step, "blocked event", f"none recorded; the world: {want_text!r}"
            )
        if got_step < want_step:
            raise PhysicsDifference(
                got_step, "blocked event", f"recorded {got_text!r}; the world moves"
            )
        raise PhysicsDifference(
            want_step, "blocked event", f"recorded {got_text!r}; the world: {want_text!r}"
        )
    if len(found_steps) > common:
        raise PhysicsDifference(
            int(found_steps[common]),
            "blocked event",
            f"recorded {str(texts[text_codes[common]])!r}; the world moves",
        )
    if len(blocked_steps) > common:
        raise PhysicsDifference(
            int(blocked_steps[common]),
            "blocked event",
            f"none recorded; the world: {made[int(pair_codes[common])][0]!r}",
        )


def _factorized_ints(values: IntArray) -> tuple[IntArray, list[int]]:
    """Each value's index among the distinct values, and those values (hashing, in C)."""
    codes, uniques = pd.factorize(values)
    return np.asarray(codes, np.int64), [int(value) for value in uniques]


def _factorized(column: Any) -> tuple[Any, IntArray]:
    """A text column's distinct values and each row's index among them (hashing, in C)."""
    codes, uniques = pd.factorize(column)
    return np.asarray(uniques, dtype=object), np.asarray(codes, np.int64)
