"""The replay side's decode-only step structs agree with the records, field for field.

``rsstp_replay.reader`` reads step messages with structs of its own (the agent's in
``_decode``, each body's truth in ``_arm`` and ``_rover``), for speed: they skip
what a batch does not need (the joint positions and distances that follow from the angles)
and are not tracked by the garbage collector, and decoding a chunk's steps with them takes
about a third of the time :class:`~rsstp_format.records.StepRecord` takes (2026-11-28,
the 10,001 steps of ``recordings/three-joint-random.mcap``: 1.1 us a step against 3.0 us).
So they are kept, and checked here against the records, which the schemas are generated
from: the same fields in the same order, the same optional fields, the same types, and the
schema's bounds (which the decode structs check while decoding, where the records leave them
to the schema). Two differences are theirs: a count or id is bounded to int64 (it goes into
an int64 column), and an array's length is checked on the columns (exactly ``n`` angles,
``n + 1`` points), not by the struct.
"""

from __future__ import annotations

from typing import Any

import msgspec
import pytest

from rsstp_format import records
from rsstp_replay.reader import _arm, _decode, _rover

WHOLE = [
    (_arm._Step, records.StepRecord),
    (_decode.Agent, records.AgentRecord),
    (_arm._Truth, records.TruthRecord),
    (_decode.BlockedBy, records.BlockedByRecord),
    (_decode.Point, records.PointRecord),
    (_arm._Distances, records.DistancesRecord),
    (_rover._RoverStep, records.RoverStepRecord),
    (_rover._RoverTruth, records.RoverTruthRecord),
]
"""Decode struct -> the record it reads, every field."""
PARTS = [
    (_arm._PoseStep, records.StepRecord),
    (_arm._PoseTruth, records.TruthRecord),
    (_decode._AgentStep, records.StepRecord),
]
"""Decode struct -> the record of which it reads some fields (the parser skips the others)."""
INT64_MAX = 2**63 - 1


def json_shape(cls: type) -> dict[str, Any]:
    """msgspec's JSON Schema of ``cls`` with every reference inlined, without titles and
    descriptions: what the struct reads, whatever its classes are called."""
    (ref,), components = msgspec.json.schema_components([cls])

    def inline(schema: Any) -> Any:
        if isinstance(schema, dict):
            if "$ref" in schema:
                return inline(components[schema["$ref"].rsplit("/", 1)[1]])
            return {k: inline(v) for k, v in schema.items() if k not in ("title", "description")}
        if isinstance(schema, list):
            return [inline(item) for item in schema]
        return schema

    shape: dict[str, Any] = inline(ref)
    return shape


def differences(decoding: Any, record: Any, where: str) -> list[str]:
    """Where the decode struct's shape differs from the record's, but for its own two
    differences (see the module docstring)."""
    if isinstance(decoding, dict) and isinstance(record, dict):
        found = []
        for key in dict.fromkeys([*record, *decoding]):
            if key not in decoding and key in ("minItems", "maxItems"):
                continue  # checked on the columns
            if key not in record and key == "maximum" and decoding[key] == INT64_MAX:
                continue  # an int64 column
            if key not in decoding or key not in record:
                side = "decode struct" if key in decoding else "record"
                found.append(f"{where}: {key!r} only in the {side}")
                continue
            found += differences(decoding[key], record[key], f"{where}.{key}")
        if list(decoding.get("properties", {})) != list(record.get("properties", {})):
            found.append(f"{where}: fields in another order")
        return found
    if isinstance(decoding, list) and isinstance(record, list) and len(decoding) == len(record):
        return [
            d
            for i, (a, b) in enumerate(zip(decoding, record, strict=True))
            for d in differences(a, b, f"{where}[{i}]")
        ]
    return [] if decoding == record else [f"{where}: {decoding!r} != {record!r}"]


@pytest.mark.parametrize(("decoding", "record"), WHOLE, ids=lambda cls: cls.__name__)
def test_a_decode_struct_reads_its_record_field_for_field(decoding: type, record: type) -> None:
    assert differences(json_shape(decoding), json_shape(record), record.__name__) == []


def restricted(whole: Any, part: Any) -> Any:
    """``whole`` with only the fields that ``part`` has, in its objects at every level."""
    if isinstance(whole, dict) and isinstance(part, dict):
        kept = {key: restricted(value, part.get(key)) for key, value in whole.items()}
        if "properties" in whole and "properties" in part:
            names = part["properties"]
            missing = [name for name in names if name not in whole["properties"]]
            assert not missing, f"not fields of the record: {missing}"
            kept["properties"] = {
                name: restricted(sub, names[name])
                for name, sub in whole["properties"].items()
                if name in names
            }
            kept["required"] = [name for name in whole.get("required", ()) if name in names]
        return kept
    if isinstance(whole, list) and isinstance(part, list) and len(whole) == len(part):
        return [restricted(a, b) for a, b in zip(whole, part, strict=True)]
    return whole


@pytest.mark.parametrize(("decoding", "record"), PARTS, ids=lambda cls: cls.__name__)
def test_a_partial_decode_struct_reads_some_of_its_record_s_fields(
    decoding: type, record: type
) -> None:
    part = json_shape(decoding)
    assert differences(part, restricted(json_shape(record), part), record.__name__) == []


def test_the_check_finds_a_difference() -> None:
    class Agent(msgspec.Struct, kw_only=True):  # _decode.Agent with a field mistyped
        action: int | None = None
        state_before: int | None = None
        internal_state: int
        sensation: int
        feedback: float
        model_version: int
        no_transition: bool

    found = differences(json_shape(Agent), json_shape(records.AgentRecord), "AgentRecord")
    assert "AgentRecord.properties.sensation.type: 'integer' != 'boolean'" in found
    assert "AgentRecord.properties.feedback: 'minimum' only in the record" in found
