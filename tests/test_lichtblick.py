"""The viewers' own parser over the recordings: Foxglove Studio 1.48's ``parseChannel`` (the code
Lichtblick forked), bundled unchanged in ``tests/lichtblick/vendor/check_channels.mjs``, run with
node over every channel of every reference recording. A channel it refuses is a topic Lichtblick
or Foxglove skips; a field missing from its datatypes is a field no panel can plot."""

from __future__ import annotations

import json
import subprocess
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest
from mcap.reader import make_reader

from lichtblick.harness import BUNDLE, channels_by_topic, require_node, write_recording

RECORDINGS = sorted((Path(__file__).parents[1] / "recordings").glob("*.mcap"))


def unaddressable(
    schema: Mapping[str, Any], datatypes: Mapping[str, Any], type_name: str, prefix: str = ""
) -> list[str]:
    """The property paths of ``schema`` (nested objects and arrays of objects included) that
    the datatypes ``parseChannel`` produced do not define, starting at ``type_name``."""
    definitions = {d["name"]: d for d in datatypes.get(type_name, {}).get("definitions", [])}
    missing: list[str] = []
    for name, field in (schema.get("properties") or {}).items():
        path = f"{prefix}{name}"
        definition = definitions.get(name)
        if definition is None:
            missing.append(path)
            continue
        nested, path = (
            (field.get("items"), f"{path}[]") if field.get("type") == "array" else (field, path)
        )
        if isinstance(nested, dict) and nested.get("type") == "object":
            if not definition.get("isComplex"):
                missing.append(f"{path} (not a message type)")
            else:
                missing += unaddressable(nested, datatypes, definition["type"], f"{path}.")
    return missing


def recorded_channels(recording: Path) -> dict[str, tuple[dict[str, Any], int]]:
    """Each topic's JSON Schema and message count, as the Python ``mcap`` reader sees them."""
    with recording.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None, f"{recording}: no summary"
    counts = summary.statistics.channel_message_counts
    return {
        channel.topic: (json.loads(summary.schemas[channel.schema_id].data), counts.get(id_, 0))
        for id_, channel in summary.channels.items()
    }


def viewer_problems(recording: Path) -> list[str]:
    """Every channel ``parseChannel`` refuses, every message it could not deserialize, and every
    schema field missing from its datatypes, one line each."""
    expected = recorded_channels(recording)
    found = channels_by_topic(recording)
    lines = [f"{topic}: no channel in the runner's report" for topic in expected.keys() - found]
    for topic, channel in sorted(found.items()):
        schema, count = expected[topic]
        if not channel["ok"]:
            lines.append(f"{topic} ({channel['schema']}): {channel['error']}")
            continue
        if channel["messages"] != count:
            lines.append(f"{topic}: {channel['messages']} of {count} messages deserialized")
        lines += [
            f"{topic}: field {path} is not in the datatypes"
            for path in unaddressable(schema, channel["datatypes"], channel["schema"])
        ]
    return lines


def test_there_are_reference_recordings() -> None:
    assert RECORDINGS, "recordings/*.mcap: no reference recording"


@pytest.mark.parametrize("recording", RECORDINGS, ids=lambda path: path.name)
def test_every_channel_of_a_reference_recording_opens_in_the_viewers(recording: Path) -> None:
    problems = viewer_problems(recording)
    assert not problems, f"{recording.name}:\n" + "\n".join(problems)


def test_a_field_missing_from_the_datatypes_is_named() -> None:
    datatypes: dict[str, Any] = {
        "good": {"definitions": [{"name": "step", "type": "float64"}]},
        "good.points": {"definitions": [{"name": "x", "type": "float64"}]},
    }
    datatypes["good"]["definitions"] += [
        {"name": "tip", "type": "float64"},
        {"name": "points", "type": "good.points", "isComplex": True, "isArray": True},
    ]
    assert unaddressable(GOOD_SCHEMA, datatypes, "good") == [
        "ok",
        "name",
        "blob",
        "kind",
        "angles_deg",
        "tip (not a message type)",
        "points[].y",
    ]


# A schema that obeys every rule: nested objects, arrays of scalars and of objects, a numeric
# oneOf enumeration, a base64 string. The viewers must accept it whole.
GOOD_SCHEMA = {
    "type": "object",
    "properties": {
        "step": {"type": "integer", "minimum": 0},
        "ok": {"type": "boolean"},
        "name": {"type": "string", "enum": ["a", "b"]},
        "blob": {"type": "string", "contentEncoding": "base64"},
        "kind": {"oneOf": [{"title": "FOLD", "const": 0}, {"title": "LINKS", "const": 1}]},
        "angles_deg": {"type": "array", "items": {"type": "integer"}},
        "tip": {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}}},
        "points": {
            "type": "array",
            "items": {
                "type": "object",
                "properties": {"x": {"type": "number"}, "y": {"type": "number"}},
            },
        },
    },
}
GOOD_MESSAGES = [
    b'{"step":0,"ok":true,"name":"a","blob":"AAE=","kind":0,"angles_deg":[0,90],'
    b'"tip":{"x":1.5,"y":0.5},"points":[{"x":0.0,"y":0.0}]}',
    b'{"step":1,"ok":false,"tip":{"x":1.0,"y":1.0},"points":[]}',
]


def sample(field: object) -> dict[str, object]:
    """A schema whose one nested field ``sample.value`` is ``field``."""
    inner = {"type": "object", "properties": {"value": field}}
    return {"type": "object", "properties": {"sample": inner}}


def test_the_viewers_accept_a_schema_that_obeys_the_rules(tmp_path: Path) -> None:
    require_node()
    recording = write_recording(tmp_path / "good.mcap", {"/good": (GOOD_SCHEMA, GOOD_MESSAGES)})
    channel = channels_by_topic(recording)["/good"]
    assert (channel["ok"], channel["error"], channel["messages"]) == (True, None, 2)
    assert unaddressable(GOOD_SCHEMA, channel["datatypes"], "good") == []
    assert viewer_problems(recording) == []


# What Foxglove 1.48's parseChannel throws for each rule the issue names (Lichtblick throws the
# same for the first two; for an object without properties it shows the object with no field).
@pytest.mark.parametrize(
    ("field", "error"),
    [
        pytest.param(
            {"type": ["integer", "null"]},
            'Error: Unsupported type ["integer","null"] for sample.value',
            id="type-list",
        ),
        pytest.param(
            {"type": "array", "items": {"type": "array", "items": {"type": "number"}}},
            'Error: Unsupported type "array" for array item sample.value',
            id="array-of-arrays",
        ),
        pytest.param(
            {"type": "object", "additionalProperties": True},
            "TypeError: Cannot convert undefined or null to object",
            id="object-without-properties",
        ),
    ],
)
def test_the_viewers_refuse_a_schema_that_breaks_a_rule(
    tmp_path: Path, field: object, error: str
) -> None:
    require_node()
    messages = [b'{"sample":{"value":null}}']
    recording = write_recording(tmp_path / "bad.mcap", {"/bad": (sample(field), messages)})
    channel = channels_by_topic(recording)["/bad"]
    assert (channel["ok"], channel["error"], channel["messages"]) == (False, error, 0)
    assert viewer_problems(recording) == [f"/bad (bad): {error}"]


def test_a_message_the_deserializer_refuses_is_reported(tmp_path: Path) -> None:
    require_node()
    messages = [GOOD_MESSAGES[0], b"{not json"]
    recording = write_recording(tmp_path / "broken.mcap", {"/good": (GOOD_SCHEMA, messages)})
    channel = channels_by_topic(recording)["/good"]
    assert (channel["ok"], channel["messages"], channel["failed_messages"]) == (False, 1, 1)
    assert channel["error"].startswith("message at log_time 1: SyntaxError")


def test_the_runner_refuses_a_truncated_file(tmp_path: Path) -> None:
    recording = write_recording(tmp_path / "good.mcap", {"/good": (GOOD_SCHEMA, GOOD_MESSAGES)})
    truncated = tmp_path / "truncated.mcap"
    truncated.write_bytes(recording.read_bytes()[:-100])
    done = subprocess.run(
        [require_node(), str(BUNDLE), str(truncated)], capture_output=True, text=True, check=False
    )
    assert done.returncode == 2
    assert done.stderr.startswith(f"{truncated}: ")
