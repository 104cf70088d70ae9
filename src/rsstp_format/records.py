"""The records of a recording: msgspec structs, the one definition of ``schemas/*.json``.

Each message schema (``rsstp.Scenario``, ``rsstp.Step``, ``rsstp.Model``, ``rsstp.Event``)
has a record class, and each nested object of a schema has one too. The schema files are
written from these classes (:mod:`~rsstp_format.schema_text`): field names, order and
types, and in each field's ``Annotated`` metadata its description and bounds. JSON arrays are
tuples, points are :class:`PointRecord` ``{x, y}``, a model's transitions a
:class:`TransitionsRecord` of three parallel arrays. A field the schema makes optional is
``None`` in Python and left out of the JSON (schema 2.0 writes no ``null``: see
``schemas/README.md``); an event's ``data`` is a dict of the fields its kind has.

- ``record.to_json()`` gives the JSON-ready dict (keys in schema order, arrays as lists);
- ``Record.from_json(data)`` reads one back, ignoring keys it does not know (a later 2.x may
  add fields) and refusing missing or mistyped ones with a :class:`RecordFormatError` that
  names the field path; value ranges are the schema's business
  (:func:`rsstp_format.schemas.validate`);
- :func:`encode` and :func:`decode` turn records into the bytes of an MCAP message and back
  (msgspec, the fastest: see ``bench/encoding.py``); floats are written as their shortest
  round-trip representation, so ground truth survives exactly.

:mod:`rsstp_sim.recording.builders` (the simulator) makes records from the simulator's live objects.

>>> record = EventRecord(step=3, kind="note", text="exploring joint 1", data={})
>>> encode(record)
b'{"step":3,"kind":"note","text":"exploring joint 1","data":{}}'
>>> decode("rsstp.Event", encode(record)) == record
True
>>> encode(AgentRecord(internal_state=0, sensation=False, feedback=0.5, model_version=0,
...                    no_transition=False))
b'{"internal_state":0,"sensation":false,"feedback":0.5,"model_version":0,"no_transition":false}'
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Annotated, Any, ClassVar, Literal, Self, TypeAlias, TypeVar

import msgspec

from rsstp_format.errors import RecordFormatError
from rsstp_format.vocabulary import (
    BlockerKind,
    CollisionMode,
    FeedbackMode,
    Operation,
    OperationKind,
    snapshot_form,
)

__all__ = [
    "AgentRecord",
    "BlockedByRecord",
    "DistancesRecord",
    "EventRecord",
    "FeedbackRecord",
    "MessageRecord",
    "ModelRecord",
    "ObstacleRecord",
    "OperationRecord",
    "DoorRecord",
    "ParamRecord",
    "PointRecord",
    "RECORD_TYPES",
    "NO_TRANSITIONS",
    "STEP_RECORDS",
    "ScenarioMessage",
    "StepMessage",
    "RecordFormatError",
    "RegionRecord",
    "RoverRecord",
    "RoverScenarioRecord",
    "RoverStepRecord",
    "RoverTruthRecord",
    "ScenarioRecord",
    "SegmentRecord",
    "StepRecord",
    "StrategyRecord",
    "TransitionsRecord",
    "TruthRecord",
    "decode",
    "decode_many",
    "json_array",
    "encode",
]

EventKind = Literal[
    "blocked", "no_transition", "split", "merge", "add", "delete", "note", "contradiction"
]


class _Record(msgspec.Struct, frozen=True, omit_defaults=True, kw_only=True):
    """JSON conversion, shared by every record class."""

    def to_json(self) -> dict[str, Any]:
        """The JSON-ready dict: keys in schema order, arrays as lists, optional fields that
        are ``None`` left out.

        Exactly what the record's message bytes decode to.
        """
        result: dict[str, Any] = _DECODE_JSON(_ENCODER.encode(self))
        return result

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Self:
        """Read a record from decoded JSON; unknown keys are ignored, missing ones refused."""
        record = _convert(data, cls, getattr(cls, "schema_name", cls.__name__))
        record._check()
        return record

    def _check(self) -> None:
        """Checks beyond the field types (where the schema has them)."""


# ------------------------------------------------------------------ schema keywords


def _schema(description: str | None = None, **keywords: Any) -> msgspec.Meta:
    """A field's JSON Schema beyond its type: its ``description`` and the ``keywords`` that
    bound its value (``minimum``, ``minItems``, ``pattern``...), in the order the schema file
    has them. :mod:`~rsstp_format.schema_text` writes ``schemas/*.json`` from these;
    msgspec keeps the keywords for its own JSON Schema and does not check them when it
    decodes: value ranges are the schema's business
    (:func:`~rsstp_format.schemas.validate`)."""
    return msgspec.Meta(description=description, extra_json_schema=keywords or None)


_Id = Annotated[int, _schema(minimum=0)]
"""An array's id, index or count (state ids, action ids, link indices): integer >= 0."""
_Angle = Annotated[int, _schema(minimum=0, maximum=359)]
"""An array's angle: integer degrees in ``[0, 360)``."""
_ACTION_ID = (
    "action id (integer, 0..2n-1): joint a // 2 turns by +step_deg (counter-clockwise) for even "
    "a, by -step_deg for odd a"
)


# ---------------------------------------------------------------- shared shapes


class PointRecord(_Record, frozen=True, kw_only=True):
    """A point ``{x, y}`` in the world frame (length units)."""

    x: Annotated[float, _schema("x (length units, world frame)")]
    y: Annotated[float, _schema("y (length units, world frame)")]

    @classmethod
    def of(cls, xy: Sequence[float]) -> PointRecord:
        """The point of an ``(x, y)`` pair."""
        return cls(x=float(xy[0]), y=float(xy[1]))


_Point = Annotated[PointRecord, _schema("a point {x, y} (length units, world frame)")]


# ---------------------------------------------------------------- rsstp.Scenario


class ObstacleRecord(_Record, frozen=True, kw_only=True):
    """A circular obstacle: ``center`` ``{x, y}`` and ``radius``, in length units."""

    center: Annotated[
        PointRecord, _schema("centre {x, y} (length units, world frame, arm base at the origin)")
    ]
    radius: Annotated[float, _schema("radius (length units)", exclusiveMinimum=0)]


class FeedbackRecord(_Record, frozen=True, kw_only=True):
    """Where the tips must be for the sensation (``points``: one ``{x, y}`` per joint).

    ``tolerance`` is relative to the total arm length; ``tolerance_abs`` is in length
    units; ``target_deg`` is the pose defining the points, or ``None`` (absent) if they were
    given.
    """

    mode: Annotated[
        FeedbackMode,
        _schema(
            'the observation the scenario intends: "bool" (the sensation) or "float" (the '
            "feedback value); every step records both"
        ),
    ]
    tolerance: Annotated[
        float,
        _schema("tolerance relative to the total arm length (dimensionless ratio)", minimum=0),
    ]
    tolerance_abs: Annotated[
        float,
        _schema(
            "tolerance * total arm length: how far each tip may be from its feedback point "
            "(length units)",
            minimum=0,
        ),
    ]
    points: Annotated[
        tuple[_Point, ...],
        _schema(
            "feedback point of each link's tip, one {x, y} per joint, base first (length units, "
            "world frame)",
            minItems=1,
        ),
    ]
    target_deg: (
        Annotated[
            tuple[_Angle, ...],
            _schema(
                "the pose whose tips define the points (integer degrees in [0, 360), one per "
                "joint); absent when the scenario gives the points directly"
            ),
        ]
        | None
    ) = None


class ParamRecord(_Record, frozen=True, kw_only=True):
    """One strategy parameter: its ``name`` and its value as JSON text (``"0.1"``,
    ``"[0, 1]"``), so every parameter has the same type whatever its value."""

    name: Annotated[str, _schema("parameter name")]
    value: Annotated[
        str,
        _schema('its value as JSON text ("0.1", "[0, 1]", "\\"north\\""; units per strategy)'),
    ]


class StrategyRecord(_Record, frozen=True, kw_only=True):
    """The strategy: its name, where its class lives (``import_path``, ``package.module:Class``)
    and the distribution that provides it with that distribution's version (absent for a
    module that no installed distribution provides), and its parameters in name order."""

    name: Annotated[
        str,
        _schema(
            "the name the run was given the strategy by (built-in, entry point or "
            "package.module:Class)"
        ),
    ]
    import_path: Annotated[str, _schema("where its class lives: package.module:Class")]
    distribution: (
        Annotated[
            str,
            _schema(
                "the installed distribution that provides the class's top-level package (rsstp "
                "for the built-in strategies); absent for a module no distribution provides"
            ),
        ]
        | None
    ) = None
    version: Annotated[str, _schema("that distribution's version; absent with it")] | None = None
    params: Annotated[
        tuple[Annotated[ParamRecord, _schema("one parameter")], ...],
        _schema("the strategy's parameters, in name order"),
    ]

    def param_values(self) -> dict[str, Any]:
        """The parameters as the strategy took them: name -> JSON value."""
        return {p.name: _DECODE_JSON(p.value) for p in self.params}


_ScenarioName = Annotated[str, _schema("scenario name (no unit)")]
_ScenarioDescription = Annotated[str, _schema("one-line description of the scenario (no unit)")]
_ScenarioOrigin = Annotated[
    str,
    _schema(
        "where the scenario came from: a built-in scenario's name, or the scenario file's "
        "base name (never a directory: recordings are byte-identical across machines)"
    ),
]
_ScenarioSha256 = Annotated[
    str,
    _schema(
        "SHA-256 of the scenario file's text (UTF-8), 64 lowercase hex digits",
        pattern="^[0-9a-f]{64}$",
    ),
]
_Seed = Annotated[int, _schema("seed of the run's random generator (integer >= 0)", minimum=0)]
_Strategy = Annotated[StrategyRecord, _schema("the learning strategy of the run")]
"""The fields every body's scenario message has, defined once (``rsstp.Scenario``,
``rsstp.RoverScenario``)."""


class ScenarioRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Scenario`` on ``/rsstp/scenario``: the run's world, seed and strategy."""

    schema_name: ClassVar[str] = "rsstp.Scenario"
    schema_description: ClassVar[str] = (
        "The scenario of the run: the arm, its obstacles, its feedback points, the seed and the "
        "strategy. Topic /rsstp/scenario, one message, first in the file, log_time 0."
    )

    name: _ScenarioName
    description: _ScenarioDescription
    origin: _ScenarioOrigin
    sha256: _ScenarioSha256
    n_joints: Annotated[int, _schema("number of joints n, one link per joint (count)", minimum=1)]
    lengths: Annotated[
        tuple[Annotated[float, _schema(exclusiveMinimum=0)], ...],
        _schema("length of each link, base first (length units)", minItems=1),
    ]
    initial_deg: Annotated[
        tuple[_Angle, ...],
        _schema(
            "start pose: relative angle of each joint, base first (integer degrees in [0, 360))",
            minItems=1,
        ),
    ]
    step_deg: Annotated[
        int,
        _schema("how far one action turns its joint (integer degrees)", minimum=1, maximum=359),
    ]
    actions: Annotated[
        tuple[_Id, ...],
        _schema(f"the actions the agent may take, sorted ({_ACTION_ID})", minItems=1),
    ]
    obstacles: Annotated[
        tuple[Annotated[ObstacleRecord, _schema("one circular obstacle")], ...],
        _schema(
            "circular obstacles (closed disks: touching one counts as meeting it), in scenario "
            "order; obstacle j is truth.distances[k].obstacles[j] of a step"
        ),
    ]
    feedback: Annotated[
        FeedbackRecord,
        _schema(
            "where the tips must be for the sensation to be true, and how the feedback value is "
            "computed"
        ),
    ]
    collision: Annotated[
        CollisionMode,
        _schema(
            'collision model: "swept" (the whole swept motion must be free) or "endpoint" (only '
            "the end pose is checked, as in the thesis)"
        ),
    ]
    seed: _Seed
    strategy: _Strategy


# -------------------------------------------------------------------- rsstp.Step


class AgentRecord(_Record, frozen=True, kw_only=True):
    """What the agent knows after a step (``action`` and ``state_before`` None, absent from
    the JSON, at step 0)."""

    action: (
        Annotated[
            int,
            _schema(f"the action taken at this step, absent at step 0 ({_ACTION_ID})", minimum=0),
        ]
        | None
    ) = None
    state_before: (
        Annotated[
            int,
            _schema("internal state before the step (state id), absent at step 0", minimum=0),
        ]
        | None
    ) = None
    internal_state: Annotated[int, _schema("internal state after the step (state id)", minimum=0)]
    sensation: Annotated[
        bool,
        _schema(
            "the sensation after the step: every tip within tolerance_abs of its feedback point"
        ),
    ]
    feedback: Annotated[
        float,
        _schema(
            "feedback after the step: closeness to the feedback points, the mean over tips k of "
            "max(0, 1 - |tip_k - point_k| / (|point_k| + L_0 + ... + L_k)) (dimensionless, in "
            "[0, 1]; 1 exactly on the points), whatever the scenario's feedback mode",
            minimum=0,
            maximum=1,
        ),
    ]
    model_version: Annotated[
        int,
        _schema(
            "version of the internal model after the step (operations applied since the start, "
            "count): the latest /rsstp/model message at or before this step has this version",
            minimum=0,
        ),
    ]
    no_transition: Annotated[
        bool,
        _schema(
            "the model had no transition from state_before by action, so the internal state stayed"
        ),
    ]


class BlockedByRecord(_Record, frozen=True, kw_only=True):
    """Why a move was blocked: an arm's ``fold`` ``[joint]``, ``obstacle`` ``[link,
    obstacle]``, ``links`` ``[link_i, link_j]``; a rover's ``room`` ``[edge]``, ``obstacle``
    ``[0, obstacle]``, ``wall`` ``[wall]``, ``door`` ``[door]``."""

    kind: Annotated[
        BlockerKind,
        _schema(
            '"fold": a joint would fold back onto the previous link; "obstacle": a link (the '
            'rover: the robot) would meet an obstacle; "links": two links would intersect; '
            '"room": the rover would leave the room; "wall": it would meet a wall; "door": it '
            "would cross a one-way door the other way"
        ),
    ]
    indices: Annotated[
        tuple[_Id, ...],
        _schema(
            "fold: [joint]; obstacle: [link, obstacle] (the rover: [0, obstacle]); links: "
            "[link_i, link_j] with link_i < link_j - 1; room: [edge] (0 east, 1 north, 2 west, "
            "3 south); wall: [wall]; door: [door] (0-based indices)",
            minItems=1,
            maxItems=2,
        ),
    ]

    @classmethod
    def of(cls, blocker: Any) -> BlockedByRecord | None:
        """The record of a body's blocker (its ``kind`` and ``indices``); None stays None."""
        if blocker is None:
            return None
        return cls(kind=blocker.kind, indices=tuple(int(i) for i in blocker.indices))


class DistancesRecord(_Record, frozen=True, kw_only=True):
    """The distances from one link tip to each obstacle's surface (length units), in
    scenario order."""

    obstacles: Annotated[
        tuple[float, ...],
        _schema("one value per obstacle, in scenario order (length units)"),
    ]


class TruthRecord(_Record, frozen=True, kw_only=True):
    """Ground truth after a step: angles (degrees), positions and distances (length units);
    ``blocked_by`` None (absent) when the arm moved."""

    angles_deg: Annotated[
        tuple[_Angle, ...],
        _schema(
            "relative joint angles, base first (integer degrees in [0, 360))",
            minItems=1,
        ),
    ]
    joint_positions: Annotated[
        tuple[_Point, ...],
        _schema(
            "n + 1 points {x, y}: the base (origin) then each link's tip (length units, world "
            "frame)",
            minItems=2,
        ),
    ]
    blocked: Annotated[
        bool,
        _schema("the move was blocked, so the arm did not move (always false at step 0)"),
    ]
    blocked_by: (
        Annotated[BlockedByRecord, _schema("why the move was blocked; absent when it was not")]
        | None
    ) = None
    distances: Annotated[
        tuple[
            Annotated[
                DistancesRecord,
                _schema("the distances from one link tip to every obstacle's surface"),
            ],
            ...,
        ],
        _schema(
            "n entries, one per link tip (base first), each with m values, one per obstacle "
            "(scenario order): distances[k].obstacles[j] is |tip_k - centre_j| - radius_j "
            "(length units; 0 = touching)"
        ),
    ]


_StepIndex = Annotated[int, _schema("step index t (steps; 0 = the reset)", minimum=0)]
_Agent = Annotated[AgentRecord, _schema("what the agent knows after this step")]
"""The fields every body's step message starts with (``rsstp.Step``, ``rsstp.RoverStep``)."""


class StepRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Step`` on ``/rsstp/step``: one step (0 = the reset), agent view and truth."""

    schema_name: ClassVar[str] = "rsstp.Step"
    schema_description: ClassVar[str] = (
        "One coupled step. Topic /rsstp/step, one message per step, log_time = step * "
        "1_000_000 ns. Step 0 is the reset (no action). `agent` is what the agent knows; "
        "`truth` is the world's ground truth, which the agent never sees."
    )

    step: _StepIndex
    agent: _Agent
    truth: Annotated[TruthRecord, _schema("ground truth after the step (for analysis only)")]


# ------------------------------------------------------- rsstp.RoverScenario, RoverStep


_Cell = Annotated[
    tuple[_Id, ...],
    _schema(
        "a cell [x, y] of the room's grid (cells; cell [x, y] has its centre at "
        "(x + 0.5, y + 0.5))",
        minItems=2,
        maxItems=2,
    ),
]


class SegmentRecord(_Record, frozen=True, kw_only=True):
    """A wall: the segment from ``start`` to ``end`` (length units)."""

    start: Annotated[PointRecord, _schema("one end {x, y} (length units, world frame)")]
    end: Annotated[PointRecord, _schema("the other end {x, y} (length units, world frame)")]


class DoorRecord(_Record, frozen=True, kw_only=True):
    """A one-way door: a segment crossed only by a move along ``toward``."""

    start: Annotated[PointRecord, _schema("one end {x, y} (length units, world frame)")]
    end: Annotated[PointRecord, _schema("the other end {x, y} (length units, world frame)")]
    toward: Annotated[
        PointRecord,
        _schema(
            "the direction {x, y} a move must have a positive component along to cross the "
            "door; any other move that meets it is blocked"
        ),
    ]


class RoverRecord(_Record, frozen=True, kw_only=True):
    """The rover and its room: the grid, the start pose, the turn step, the robot's size,
    the walls and the one-way doors."""

    room: Annotated[
        tuple[Annotated[int, _schema(minimum=1)], ...],
        _schema("the room's width and height (cells, each 1 length unit)", minItems=2, maxItems=2),
    ]
    start: Annotated[_Cell, _schema("the start cell [x, y]")]
    heading_deg: Annotated[
        int,
        _schema(
            "the start heading, counter-clockwise from +x (integer degrees)", minimum=0, maximum=359
        ),
    ]
    turn_deg: Annotated[
        int,
        _schema("how far a turn turns the robot (integer degrees: 45 or 90)", enum=[45, 90]),
    ]
    radius: Annotated[float, _schema("the robot's radius (length units)", minimum=0)]
    walls: Annotated[
        tuple[Annotated[SegmentRecord, _schema("one wall")], ...],
        _schema("the walls, in scenario order"),
    ]
    doors: Annotated[
        tuple[Annotated[DoorRecord, _schema("one one-way door")], ...],
        _schema("the one-way doors, in scenario order"),
    ]


class RegionRecord(_Record, frozen=True, kw_only=True):
    """The rover's feedback region: a disk, and the heading it must face, if any."""

    mode: Annotated[
        FeedbackMode,
        _schema(
            'the observation the scenario intends: "bool" (the sensation) or "float" (the '
            "feedback value); every step records both"
        ),
    ]
    center: Annotated[PointRecord, _schema("the region's centre {x, y} (length units)")]
    radius: Annotated[
        float,
        _schema(
            "the region's radius: the sensation is true when the robot's centre is at "
            "most this far from the region's (length units)",
            minimum=0,
        ),
    ]
    heading_deg: (
        Annotated[
            int,
            _schema(
                "the heading the robot must face to sense (integer degrees); absent: any",
                minimum=0,
                maximum=359,
            ),
        ]
        | None
    ) = None


class RoverScenarioRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.RoverScenario`` on ``/rsstp/scenario`` of a rover's run."""

    schema_name: ClassVar[str] = "rsstp.RoverScenario"
    schema_description: ClassVar[str] = (
        "The scenario of a rover's run: the room, its walls, doors and obstacles, the feedback "
        "region, the seed and the strategy. Topic /rsstp/scenario, one message, first in the "
        "file, log_time 0."
    )

    name: _ScenarioName
    description: _ScenarioDescription
    origin: _ScenarioOrigin
    sha256: _ScenarioSha256
    rover: Annotated[RoverRecord, _schema("the robot and its room")]
    actions: Annotated[
        tuple[Annotated[int, _schema(minimum=0, maximum=3)], ...],
        _schema(
            "the actions the agent may take, sorted (0 forward, 1 back, 2 turn left, 3 turn right)",
            minItems=1,
        ),
    ]
    obstacles: Annotated[
        tuple[Annotated[ObstacleRecord, _schema("one circular obstacle")], ...],
        _schema("circular obstacles (closed disks), in scenario order"),
    ]
    feedback: Annotated[RegionRecord, _schema("where the robot senses, and how")]
    seed: _Seed
    strategy: _Strategy


class RoverTruthRecord(_Record, frozen=True, kw_only=True):
    """Ground truth of a rover after a step: its cell, heading and position; ``blocked_by``
    None (absent) when it moved."""

    cell: Annotated[_Cell, _schema("the robot's cell [x, y]")]
    heading_deg: Annotated[
        int,
        _schema(
            "the robot's heading, counter-clockwise from +x (integer degrees)",
            minimum=0,
            maximum=359,
        ),
    ]
    position: Annotated[
        PointRecord, _schema("the robot's centre {x, y} (length units, world frame)")
    ]
    blocked: Annotated[
        bool,
        _schema("the move was blocked, so the robot did not move (always false at step 0)"),
    ]
    blocked_by: (
        Annotated[BlockedByRecord, _schema("why the move was blocked; absent when it was not")]
        | None
    ) = None


class RoverStepRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.RoverStep`` on ``/rsstp/step`` of a rover's run."""

    schema_name: ClassVar[str] = "rsstp.RoverStep"
    schema_description: ClassVar[str] = (
        "One coupled step of a rover. Topic /rsstp/step, one message per step, log_time = "
        "step * 1_000_000 ns. Step 0 is the reset (no action). `agent` is what the agent "
        "knows; `truth` is the world's ground truth, which the agent never sees."
    )

    step: _StepIndex
    agent: _Agent
    truth: Annotated[RoverTruthRecord, _schema("ground truth after the step (for analysis only)")]


# ------------------------------------------------------------------- rsstp.Model


class TransitionsRecord(_Record, frozen=True, kw_only=True, gc=False):
    """Every transition of a model as three parallel arrays, sorted by source, action and
    target: transition ``i`` is ``source[i] -action[i]-> target[i]`` (state ids and action
    ids). Parallel arrays keep a model message as compact as a list of triples, in a shape
    every JSON-Schema viewer can address."""

    source: Annotated[tuple[_Id, ...], _schema("the source state of each transition (state ids)")]
    action: Annotated[tuple[_Id, ...], _schema("the action of each transition (action ids)")]
    target: Annotated[tuple[_Id, ...], _schema("the target state of each transition (state ids)")]

    def __len__(self) -> int:
        return len(self.source)

    def triples(self) -> tuple[tuple[int, int, int], ...]:
        """The ``(source, action, target)`` triples, as
        :meth:`~rsstp_sim.transition_system.TransitionSystem.transitions` gives them."""
        return tuple(zip(self.source, self.action, self.target, strict=True))

    def _check(self) -> None:
        if not len(self.source) == len(self.action) == len(self.target):
            raise RecordFormatError(
                f"transitions: source, action and target differ in length "
                f"({len(self.source)}, {len(self.action)}, {len(self.target)})"
            )


NO_TRANSITIONS = TransitionsRecord(source=(), action=(), target=())
"""A change's transitions as written: none (the one object, so that the encoder leaves the
field out, and a reader tells a change's from a keyframe's by identity)."""

_OPERATION_ARGS = _schema(
    "split: [s]; merge: [s, t]; add and delete: [s, t, a] (state ids, then an action id)",
    minItems=1,
    maxItems=3,
)


class OperationRecord(_Record, frozen=True, kw_only=True, gc=False):
    """One model operation, as :class:`~rsstp_sim.transition_system.Operation` (``result``
    None, absent, for the operations that create nothing).

    Not tracked by the garbage collector (``gc=False``, as :class:`ModelRecord`): frozen and
    holding ids alone, it can be part of no reference cycle, and a reader keeps one per
    operation of a run (tens of thousands), which every full collection walked."""

    kind: Annotated[
        OperationKind, _schema("split a state, merge two states, add or delete a transition")
    ]
    args: Annotated[tuple[_Id, ...], _OPERATION_ARGS]
    result: (
        Annotated[
            int,
            _schema(
                "split: the new state's id; merge: the surviving state s; absent for add and "
                "delete",
                minimum=0,
            ),
        ]
        | None
    ) = None
    changed: Annotated[
        bool,
        _schema(
            "false only for an add of an existing or a delete of a missing transition (a no-op)"
        ),
    ]

    def to_operation(self) -> Operation:
        """The operation, ready for :meth:`TransitionSystem.apply`."""
        return Operation(self.kind, self.args, self.result, self.changed)


class ModelRecord(_Record, frozen=True, kw_only=True, gc=False):
    """``rsstp.Model`` on ``/rsstp/model``: a model version, as a keyframe (the whole model)
    or as a change (the operations since the previous message, the whole model left out)."""

    schema_name: ClassVar[str] = "rsstp.Model"
    schema_description: ClassVar[str] = (
        "The agent's internal model (a transition system) after a change. Topic /rsstp/model, "
        "once at step 0 and at every step where the model changed, log_time = step * 1_000_000 "
        "ns. A keyframe (keyframe absent or true) holds the whole model, states and "
        "transitions; a change (keyframe false) leaves them out: applying each message's "
        "operations to the previous message's model gives this one. The first message is a "
        "keyframe."
    )

    version: Annotated[
        int, _schema("model version: operations applied since the start (count)", minimum=0)
    ]
    step: Annotated[int, _schema("step at which the model has this version (steps)", minimum=0)]
    states: Annotated[
        tuple[_Id, ...],
        _schema("state ids, sorted (never reused); a keyframe's only", minItems=1),
    ] = ()
    next_id: Annotated[int, _schema("the id the next split will create (state id)", minimum=1)]
    current: Annotated[int, _schema("the current internal state (state id)", minimum=0)]
    actions: Annotated[tuple[_Id, ...], _schema("the action alphabet, sorted (action ids)")]
    transitions: Annotated[
        TransitionsRecord,
        _schema(
            "every transition as three parallel arrays, sorted by source, action, target: "
            "transition i is source[i] -action[i]-> target[i]; a keyframe's only"
        ),
    ] = NO_TRANSITIONS
    operations: Annotated[
        tuple[Annotated[OperationRecord, _schema("one operation on the model")], ...],
        _schema("the operations applied since the previous model message, in order"),
    ]
    deterministic: Annotated[bool, _schema("every (state, action) pair has at most one successor")]
    nondeterministic_pairs: Annotated[
        int,
        _schema("number of (state, action) pairs with more than one successor (count)", minimum=0),
    ]
    keyframe: Annotated[
        bool,
        _schema(
            "true (or absent, as in schema 2.x): the message holds the whole model; false: a "
            "change, states and transitions left out"
        ),
    ] = True

    def triples(self) -> tuple[tuple[int, int, int], ...]:
        """The transitions as ``(source, action, target)`` triples, sorted as written (a
        keyframe's, or a change's once the reader has rebuilt it)."""
        return self.transitions.triples()

    def snapshot(self) -> dict[str, object]:
        """The model in :meth:`TransitionSystem.snapshot` form (for ``from_snapshot``)."""
        return snapshot_form(self.states, self.next_id, self.current, self.actions, self.triples())

    def _check(self) -> None:
        whole = (bool(self.states), self.transitions is not NO_TRANSITIONS)
        if whole != (self.keyframe, self.keyframe):
            said = "a keyframe" if self.keyframe else "a change (keyframe false)"
            raise RecordFormatError(
                f"{self.schema_name}: {said} has states {'present' if whole[0] else 'absent'} "
                f"and transitions {'present' if whole[1] else 'absent'}"
            )
        if whole[1]:
            try:
                self.transitions._check()
            except RecordFormatError as exc:
                raise RecordFormatError(f"{self.schema_name}: {exc}") from None


# ------------------------------------------------------------------- rsstp.Event

# An event's ``data`` by kind: one struct a kind (the fields it requires, and those it may
# have), which reads ``data`` when an event is read and gives the schema's ``allOf`` branch
# for that kind; and :class:`_EventData`, every field any kind has, all optional, which gives
# the schema's ``data`` object.

_EVENT_BLOCKED_BY = msgspec.Meta(
    description="why, as truth.blocked_by of rsstp.Step",
    extra={
        "descriptions": {
            "kind": "fold, obstacle or links",
            "indices": "as in rsstp.Step truth.blocked_by (0-based indices)",
        }
    },
)
_EVENT_ARGS = _schema(
    "as in rsstp.Model operations (state ids, then an action id)", minItems=1, maxItems=3
)
_EVENT_RESULT = _schema(
    "as in rsstp.Model operations (state id; absent for add and delete)", minimum=0
)
_EARLIER = _schema("the earlier step in that state (steps)", minimum=0)
_LATER = _schema("the later step in that state, j > i (steps)", minimum=0)
_AFTER = _schema(
    "the k >= 1 actions after both steps; the sensations agree until the last and differ after "
    "it (action ids)",
    minItems=1,
)
_ONE_LINE = "^[^\\n]*$"


class _BlockedData(msgspec.Struct):
    action: Annotated[int, _schema("the blocked action (action id)", minimum=0)]
    blocked_by: Annotated[BlockedByRecord, _EVENT_BLOCKED_BY]


class _NoTransitionData(msgspec.Struct):
    state: Annotated[int, _schema("the internal state that stayed (state id)", minimum=0)]
    action: Annotated[int, _schema("the action with no transition from it (action id)", minimum=0)]


class _NoteData(msgspec.Struct):
    phase: str | None = None
    stop: str | None = None
    budget: int | None = None


class _OperationData(msgspec.Struct):
    args: Annotated[tuple[_Id, ...], _EVENT_ARGS]
    result: Annotated[int, _EVENT_RESULT] | None = None


class _ContradictionData(msgspec.Struct):
    state: Annotated[int, _schema("the contradicted internal state (state id)", minimum=0)]
    i: Annotated[int, _EARLIER]
    j: Annotated[int, _LATER]
    actions: Annotated[tuple[_Id, ...], _AFTER]


class _EventData(msgspec.Struct, kw_only=True):
    action: (
        Annotated[
            int,
            _schema(
                "blocked: the blocked action; no_transition: the action with no transition from "
                "the state (action id)",
                minimum=0,
            ),
        ]
        | None
    ) = None
    blocked_by: Annotated[BlockedByRecord, _EVENT_BLOCKED_BY] | None = None
    state: (
        Annotated[
            int,
            _schema(
                "no_transition: the internal state that stayed; contradiction: the contradicted "
                "internal state (state id)",
                minimum=0,
            ),
        ]
        | None
    ) = None
    args: Annotated[tuple[_Id, ...], _EVENT_ARGS] | None = None
    result: Annotated[int, _EVENT_RESULT] | None = None
    i: Annotated[int, _EARLIER] | None = None
    j: Annotated[int, _LATER] | None = None
    actions: Annotated[tuple[_Id, ...], _AFTER] | None = None
    phase: (
        Annotated[
            str,
            _schema(
                "note: the phase the strategy entered at this step, for the steps from this one "
                "until the next phase note (one word, e.g. explore, identify, home, done); 2.1",
                pattern="^\\w+$",
            ),
        ]
        | None
    ) = None
    stop: (
        Annotated[
            str,
            _schema(
                "note: why the strategy ended the run at this step (one line); the step is the "
                "recording's last; 2.1",
                pattern=_ONE_LINE,
            ),
        ]
        | None
    ) = None
    budget: (
        Annotated[
            int,
            _schema(
                "note with stop: the steps the run was given (its --steps), of which it used "
                "this event's step (steps); 2.1",
                minimum=0,
            ),
        ]
        | None
    ) = None


_EVENT_DATA: dict[str, type[Any]] = {
    "blocked": _BlockedData,
    "no_transition": _NoTransitionData,
    "split": _OperationData,
    "merge": _OperationData,
    "add": _OperationData,
    "delete": _OperationData,
    "note": _NoteData,
    "contradiction": _ContradictionData,
}


class EventRecord(_Record, frozen=True, kw_only=True):
    """``rsstp.Event`` on ``/rsstp/event``: one line of log (``text``), ``data`` by ``kind``:

    - ``blocked``: ``{action, blocked_by: {kind, indices}}``;
    - ``no_transition``: ``{state, action}``;
    - ``split``, ``merge``, ``add``, ``delete``: ``{args}`` and ``result`` when the operation
      created a state, as in :class:`OperationRecord`;
    - ``note``: ``{}``, or ``{phase}`` (the strategy entered that phase), or ``{stop, budget}``
      (the strategy ended the run: its reason, and the steps it was given when known);
    - ``contradiction``: ``{state, i, j, actions}``.
    """

    schema_name: ClassVar[str] = "rsstp.Event"
    schema_description: ClassVar[str] = (
        "Something worth a line in the log. Topic /rsstp/event, log_time = step * 1_000_000 ns."
    )

    step: Annotated[int, _schema("step at which it happened (steps)", minimum=0)]
    kind: Annotated[EventKind, _schema("what happened")]
    text: Annotated[str, _schema("one human-readable line (no newline)", pattern=_ONE_LINE)]
    data: Annotated[
        dict[str, Any],
        msgspec.Meta(
            description=(
                "details, by kind (every field is optional here; the kind says which are "
                "present, see allOf): blocked: {action, blocked_by}; no_transition: {state, "
                "action}; split, merge, add, delete: {args, result (split and merge only)} as "
                "in rsstp.Model operations; note: {}, or {phase} (the strategy entered that "
                "phase at this step; 2.1), or {stop, budget} (the strategy ended the run at this "
                "step, the last event of the file; 2.1); contradiction: {state, i, j, actions} "
                "(the internal state, two steps i < j in it, and the actions after both after "
                "which the sensations differ)"
            ),
            extra={"fields": _EventData, "by_kind": _EVENT_DATA},
        ),
    ]

    def _check(self) -> None:
        try:
            msgspec.convert(self.data, _EVENT_DATA[self.kind])
        except msgspec.ValidationError as exc:
            raise RecordFormatError(
                f"rsstp.Event: {_format_error(exc, '.data')} (kind {self.kind!r})"
            ) from None


MessageRecord = (
    ScenarioRecord | StepRecord | ModelRecord | EventRecord | RoverScenarioRecord | RoverStepRecord
)
"""The records that are MCAP messages (one per schema)."""

RECORD_TYPES: dict[str, type[MessageRecord]] = {
    cls.schema_name: cls
    for cls in (
        ScenarioRecord,
        StepRecord,
        ModelRecord,
        EventRecord,
        RoverScenarioRecord,
        RoverStepRecord,
    )
}
"""Schema name -> record class."""

ScenarioMessage: TypeAlias = ScenarioRecord | RoverScenarioRecord
"""The scenario message of any body (one member a body)."""

StepMessage: TypeAlias = StepRecord | RoverStepRecord
"""The step message of any body (one member a body)."""

STEP_RECORDS: dict[type, type[StepMessage]] = {
    TruthRecord: StepRecord,
    RoverTruthRecord: RoverStepRecord,
}
"""A body's truth record -> its step message's record (one line a body)."""

_DECODERS = {name: msgspec.json.Decoder(cls) for name, cls in RECORD_TYPES.items()}
_MANY = {name: msgspec.json.Decoder(list[cls]) for name, cls in RECORD_TYPES.items()}  # type: ignore[valid-type]


# ----------------------------------------------------------------------- bytes


def encode(record: MessageRecord) -> bytes:
    """The message bytes: compact UTF-8 JSON, keys in schema order, shortest float reprs.

    msgspec serialises the struct directly, without building a dict (the fastest of
    json, orjson and msgspec: ``bench/encoding.py``); the JSON equals ``record.to_json()``.
    """
    return _ENCODER.encode(record)


def decode(schema_name: str, data: bytes) -> MessageRecord:
    """Read a message's bytes as the record of ``schema_name`` (``rsstp.Step``, ...).

    Unknown keys are ignored; a missing or mistyped field raises :class:`RecordFormatError`
    naming its path. Value ranges are checked by :func:`~rsstp_format.schemas.validate`.
    """
    decoder = _DECODERS.get(schema_name)
    if decoder is None:
        raise RecordFormatError(
            f"unknown schema {schema_name!r} (known: {', '.join(RECORD_TYPES)})"
        )
    try:
        record: MessageRecord = decoder.decode(data)
    except msgspec.ValidationError as exc:
        raise RecordFormatError(f"{schema_name}: {_format_error(exc)}") from None
    except msgspec.DecodeError as exc:
        raise RecordFormatError(f"{schema_name}: invalid JSON: {exc}") from None
    except RecursionError:
        raise RecordFormatError(f"{schema_name}: nested too deeply") from None
    record._check()
    return record


def decode_many(schema_name: str, parts: Sequence[bytes | memoryview]) -> list[MessageRecord]:
    """:func:`decode` of many messages of one schema at once (one parser call for them all:
    a chunk's events, say). Raises :class:`RecordFormatError` when any of them is bad; which
    one, and why, is what :func:`decode` of each says."""
    decoder = _MANY.get(schema_name)
    if decoder is None:
        raise RecordFormatError(
            f"unknown schema {schema_name!r} (known: {', '.join(RECORD_TYPES)})"
        )
    try:
        found: list[MessageRecord] = decoder.decode(json_array(parts))
    except msgspec.DecodeError as exc:
        raise RecordFormatError(f"{schema_name}: a message of the batch: {exc}") from None
    except RecursionError:
        raise RecordFormatError(f"{schema_name}: a message of the batch nests too deeply") from None
    if len(found) != len(parts):  # a part that is several JSON values, or none
        raise RecordFormatError(f"{schema_name}: {len(parts)} messages decode as {len(found)}")
    for record in found:
        record._check()
    return found


def json_array(parts: Sequence[bytes | memoryview]) -> bytes:
    """The JSON array of ``parts`` (each the bytes of one JSON value, a message's, say), built
    with one copy of their bytes (a chunk's messages: a megabyte).

    >>> json_array([b'{"a":1}', memoryview(b"2")])
    b'[{"a":1},2]'
    """
    if len(parts) < 2:
        return b"".join((b"[", *parts, b"]"))
    return b",".join([b"[" + parts[0], *parts[1:-1], b"".join((parts[-1], b"]"))])


# ------------------------------------------------------------- msgspec plumbing


_ENCODER = msgspec.json.Encoder()
encode_json = _ENCODER.encode
"""JSON bytes of plain values (dicts, lists, numbers, text), as the records are written."""
_DECODE_JSON = msgspec.json.Decoder().decode
_MISSING = re.compile(r"Object missing required field `(?P<field>[^`]*)`(?: - at `\$(?P<at>.*)`)?")
_AT = re.compile(r"(?P<message>.*) - at `\$(?P<at>.*)`")


def _format_error(exc: msgspec.MsgspecError, prefix: str = "") -> str:
    """msgspec's message as ``path: problem`` (``data.blocked_by.indices[0]: expected ...``)."""
    text = str(exc)
    missing = _MISSING.fullmatch(text)
    if missing is not None:
        path = prefix + (missing["at"] or "") + "." + missing["field"]
        return f"{path.lstrip('.')}: missing"
    located = _AT.fullmatch(text)
    message, path = (located["message"], prefix + located["at"]) if located else (text, prefix)
    message = message[:1].lower() + message[1:]
    return f"{path.lstrip('.')}: {message}" if path else message


_R = TypeVar("_R")


def _convert(data: object, cls: type[_R], label: str) -> _R:
    try:
        record = msgspec.convert(data, cls)
    except msgspec.ValidationError as exc:
        raise RecordFormatError(f"{label}: {_format_error(exc)}") from None
    return record
