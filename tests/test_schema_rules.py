"""The pure-Python viewer rules (``schema_rules``): the project's schemas obey them, each rule is
caught where it is broken, and the verdicts agree with the viewers' own ``parseChannel``."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from lichtblick.harness import channels_by_topic, require_node, write_recording
from schema_rules import (
    ARRAY_OF_ARRAYS,
    CONTENT_ENCODING,
    ITEM_CONTENT_ENCODING,
    NO_ITEMS,
    NO_PROPERTIES,
    NO_TYPE,
    ONE_OF_NOT_NUMERIC,
    ROOT_NOT_OBJECT,
    TYPE_LIST,
    UNSUPPORTED_TYPE,
    Problem,
    problems,
)

SCHEMAS = sorted((Path(__file__).parents[1] / "schemas").glob("*.json"))

VALUE = "/properties/sample/properties/value"
"""Where :func:`sample` puts its field."""


def sample(field: object) -> dict[str, object]:
    """A schema whose one nested field ``sample.value`` is ``field``."""
    inner = {"type": "object", "properties": {"value": field}}
    return {"type": "object", "properties": {"sample": inner}}


def test_there_are_schemas() -> None:
    assert SCHEMAS, "schemas/*.json: no schema"


@pytest.mark.parametrize("path", SCHEMAS, ids=lambda path: path.name)
def test_a_project_schema_obeys_the_viewer_rules(path: Path) -> None:
    found = problems(json.loads(path.read_text(encoding="utf-8")))
    assert not found, f"{path.name}:\n" + "\n".join(map(str, found))


# Each rule broken once: the schema, then where and which rule problems() must name.
BROKEN: dict[str, tuple[object, str, str]] = {
    "root-array": ({"type": "array", "items": {"type": "number"}}, "", ROOT_NOT_OBJECT),
    "root-type-list": ({"type": ["object", "null"], "properties": {}}, "", ROOT_NOT_OBJECT),
    "root-without-properties": ({"type": "object"}, "", NO_PROPERTIES),
    "object-without-properties": (
        sample({"type": "object", "additionalProperties": True}),
        VALUE,
        NO_PROPERTIES,
    ),
    "type-list": (sample({"type": ["integer", "null"]}), VALUE, TYPE_LIST),
    "nullable-object": (
        sample({"type": ["object", "null"], "properties": {"x": {"type": "number"}}}),
        VALUE,
        TYPE_LIST,
    ),
    "null": (sample({"type": "null"}), VALUE, UNSUPPORTED_TYPE),
    "ref": (sample({"$ref": "#/$defs/point"}), VALUE, NO_TYPE),
    "enum-alone": (sample({"enum": ["fold", "links"]}), VALUE, NO_TYPE),
    "any-of": (sample({"anyOf": [{"type": "integer"}, {"type": "null"}]}), VALUE, NO_TYPE),
    "true-schema": (sample(True), VALUE, NO_TYPE),
    "one-of-strings": (
        sample({"oneOf": [{"const": "fold"}, {"const": "links"}]}),
        VALUE,
        ONE_OF_NOT_NUMERIC,
    ),
    "content-encoding": (
        sample({"type": "string", "contentEncoding": "base16"}),
        VALUE,
        CONTENT_ENCODING,
    ),
    "array-without-items": (sample({"type": "array"}), VALUE + "/items", NO_ITEMS),
    "tuple": (
        sample({"type": "array", "prefixItems": [{"type": "number"}] * 2, "items": False}),
        VALUE + "/items",
        NO_ITEMS,
    ),
    "array-of-arrays": (
        sample({"type": "array", "items": {"type": "array", "items": {"type": "number"}}}),
        VALUE + "/items",
        ARRAY_OF_ARRAYS,
    ),
    "item-type-list": (
        sample({"type": "array", "items": {"type": ["number", "null"]}}),
        VALUE + "/items",
        TYPE_LIST,
    ),
    "items-without-properties": (
        sample({"type": "array", "items": {"type": "object"}}),
        VALUE + "/items",
        NO_PROPERTIES,
    ),
    "item-content-encoding": (
        sample({"type": "array", "items": {"type": "string", "contentEncoding": "base64"}}),
        VALUE + "/items",
        ITEM_CONTENT_ENCODING,
    ),
}

# Schemas that obey every rule, with keywords the parser does not read.
OBEYING: dict[str, object] = {
    "scalars": sample({"type": "integer", "minimum": 0, "description": "a count"}),
    "string-enum": sample({"type": "string", "enum": ["fold", "obstacle", "links"]}),
    "numeric-one-of": sample({"oneOf": [{"title": "A", "const": 0}, {"title": "B", "const": 1}]}),
    "base64": sample({"type": "string", "contentEncoding": "base64"}),
    "empty-object": sample({"type": "object", "properties": {}}),
    "point-array": sample(
        {
            "type": "array",
            "items": {
                "type": "object",
                "required": ["x", "y"],
                "additionalProperties": False,
                "properties": {"x": {"type": "number"}, "y": {"type": "number"}},
            },
        }
    ),
    "all-of-beside-properties": {
        "type": "object",
        "properties": {"kind": {"type": "string"}},
        "allOf": [{"if": {"properties": {"kind": {"const": "a"}}}, "then": {"required": ["kind"]}}],
    },
}


@pytest.mark.parametrize(("schema", "pointer", "rule"), BROKEN.values(), ids=BROKEN.keys())
def test_a_broken_rule_is_named_with_its_place(schema: object, pointer: str, rule: str) -> None:
    found = problems(schema)
    assert [(p.pointer, p.rule) for p in found] == [(pointer, rule)]


@pytest.mark.parametrize("schema", OBEYING.values(), ids=OBEYING.keys())
def test_a_schema_that_obeys_the_rules_has_no_problem(schema: object) -> None:
    assert problems(schema) == []


def test_every_problem_is_listed_not_only_the_first() -> None:
    schema = {
        "type": "object",
        "properties": {
            "action": {"type": ["integer", "null"], "description": "null at step 0"},
            "joint_positions": {
                "type": "array",
                "items": {"type": "array", "items": {"type": "number"}, "description": "[x, y]"},
            },
            "params": {"type": "object"},
        },
    }
    assert list(map(str, problems(schema))) == [
        '/properties/action: a type list (a field takes one "type"); found ["integer","null"]',
        "/properties/joint_positions/items: an array of arrays; "
        'found {"type":"array","items":{"type":"number"}}',
        '/properties/params: an object without "properties" (Foxglove 1.48 throws; Lichtblick '
        "shows no field); found null",
    ]


def test_a_pointer_escapes_slash_and_tilde() -> None:
    schema = {"type": "object", "properties": {"a/b~c": {"type": "null"}}}
    assert problems(schema) == [Problem("/properties/a~1b~0c", UNSUPPORTED_TYPE, '"null"')]


# Every schema above, and the project's, as one channel each of a recording that the viewers'
# parseChannel reads: its verdict (refused or not) must be problems()'s.
CORPUS: dict[str, object] = {
    **{f"broken-{name}": schema for name, (schema, _, _) in BROKEN.items()},
    **{f"obeying-{name}": schema for name, schema in OBEYING.items()},
    **{f"project-{path.stem}": json.loads(path.read_text(encoding="utf-8")) for path in SCHEMAS},
}


@pytest.fixture(scope="module")
def viewer_verdicts(tmp_path_factory: pytest.TempPathFactory) -> dict[str, dict[str, Any]]:
    """parseChannel's report on each :data:`CORPUS` schema, by name."""
    require_node()
    path = tmp_path_factory.mktemp("corpus") / "corpus.mcap"
    recording = write_recording(path, {f"/{n}": (s, [b"{}"]) for n, s in CORPUS.items()})
    return {topic.lstrip("/"): channel for topic, channel in channels_by_topic(recording).items()}


@pytest.mark.parametrize("name", CORPUS.keys())
def test_the_python_rules_agree_with_parse_channel(
    name: str, viewer_verdicts: dict[str, dict[str, Any]]
) -> None:
    channel = viewer_verdicts[name]
    found = problems(CORPUS[name])
    assert (channel["ok"], channel["error"] is None) == (not found, not found), (
        f"parseChannel: {channel['error']}; problems(): {list(map(str, found))}"
    )
