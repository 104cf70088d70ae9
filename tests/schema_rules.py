"""What a channel's JSON Schema must obey for Lichtblick and Foxglove Studio 1.48 to show it.

Both viewers open an MCAP channel with ``parseChannel`` (their ``mcap-support`` package). For a
JSON channel it calls ``parseJsonSchema``, which turns the schema into message definitions (the
datatypes that panels address fields by) and throws on anything it cannot turn; the viewer then
reports the error and skips the topic. :func:`problems` names every such spot, where
``parseJsonSchema`` stops at the first. Its rules, in the order the parser checks them:

- The root has ``"type": "object"``.
- Every object has ``properties`` (Foxglove 1.48 throws a ``TypeError`` without; Lichtblick
  reads none as ``{}`` and shows the object with no field, so nothing in it can be plotted).
- A property with a ``oneOf`` is an enumeration: every alternative has a numeric ``const``.
- Otherwise a property has one ``type``, a string: ``boolean``, ``string``, ``number``,
  ``integer``, ``object`` or ``array``. A list such as ``["integer", "null"]`` is refused, and
  so are ``"null"``, no type at all (``$ref``, ``anyOf``, ``enum`` or ``const`` alone) and a
  property that is not a schema object (``true``).
- A string's ``contentEncoding`` is absent or ``base64``.
- An array has ``items``, one schema object whose ``type`` is one of ``boolean``, ``string``
  (without ``contentEncoding``), ``number``, ``integer`` or ``object``: no arrays of arrays,
  no type lists, no tuples (``prefixItems``).

Keywords the parser does not read are free: ``description``, ``required``, ``enum`` beside a
``type``, ``minimum``, ``additionalProperties``, ``allOf``/``if``/``then`` at an object (though
properties declared only inside those are not shown).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

ROOT_NOT_OBJECT = 'the root is not "type": "object"'
NO_PROPERTIES = 'an object without "properties" (Foxglove 1.48 throws; Lichtblick shows no field)'
ONE_OF_NOT_NUMERIC = 'a "oneOf" whose alternatives are not all numeric "const"s'
TYPE_LIST = 'a type list (a field takes one "type")'
NO_TYPE = 'no "type"'
UNSUPPORTED_TYPE = 'a "type" the parser does not take'
CONTENT_ENCODING = 'a "contentEncoding" other than "base64"'
NO_ITEMS = 'an array without "items" (one schema object)'
ARRAY_OF_ARRAYS = "an array of arrays"
ITEM_CONTENT_ENCODING = 'array items of type string with a "contentEncoding"'

SCALARS = ("boolean", "number", "integer")
"""The types that become one primitive field (``bool``, ``float64``/``int32``/``uint32``)."""


@dataclass(frozen=True)
class Problem:
    """One spot of a schema that ``parseJsonSchema`` refuses: where, which rule, what it found."""

    pointer: str
    """JSON Pointer (RFC 6901) to the offending schema in the schema document ("" is the root)."""
    rule: str
    """One of this module's rule constants (:data:`TYPE_LIST`, ...)."""
    found: str
    """The offending value, as JSON."""

    def __str__(self) -> str:
        return f"{self.pointer or '/'}: {self.rule}; found {self.found}"


def problems(schema: object) -> list[Problem]:
    """Every spot of ``schema`` (a parsed JSON Schema) that makes Lichtblick's or Foxglove
    1.48's ``parseChannel`` refuse the channel; an empty list when both accept it."""
    found: list[Problem] = []
    if not isinstance(schema, dict) or schema.get("type") != "object":
        kind = schema.get("type") if isinstance(schema, dict) else schema
        return [Problem("", ROOT_NOT_OBJECT, _json(kind))]
    _check_object(schema, "", found)
    return found


def _check_object(schema: dict[str, Any], pointer: str, found: list[Problem]) -> None:
    properties = schema.get("properties")
    if not isinstance(properties, dict):
        found.append(Problem(pointer, NO_PROPERTIES, _json(properties)))
        return
    for name, field in properties.items():
        _check_field(field, f"{pointer}/properties/{_escape(name)}", found)


def _check_field(field: object, pointer: str, found: list[Problem], *, items: bool = False) -> None:
    """A property's schema, or (``items``) the ``items`` of an array property."""
    if not isinstance(field, dict):
        found.append(Problem(pointer, NO_ITEMS if items else NO_TYPE, _json(field)))
        return
    one_of = field.get("oneOf")
    if not items and isinstance(one_of, list):
        if not all(isinstance(a, dict) and _is_number(a.get("const")) for a in one_of):
            found.append(Problem(pointer, ONE_OF_NOT_NUMERIC, _json(one_of)))
        return
    kind = field.get("type")
    if kind in SCALARS:
        return
    encoding = field.get("contentEncoding")
    if kind == "string" and items:
        if encoding is not None:
            found.append(Problem(pointer, ITEM_CONTENT_ENCODING, _json(encoding)))
    elif kind == "string":
        if "contentEncoding" in field and encoding != "base64":
            found.append(Problem(pointer, CONTENT_ENCODING, _json(encoding)))
    elif kind == "object":
        _check_object(field, pointer, found)
    elif kind == "array" and items:
        found.append(Problem(pointer, ARRAY_OF_ARRAYS, _json(_outline(field))))
    elif kind == "array":
        _check_field(field.get("items"), f"{pointer}/items", found, items=True)
    else:
        found.append(_type_problem(pointer, field))


def _type_problem(pointer: str, schema: dict[str, Any]) -> Problem:
    kind = schema.get("type")
    if isinstance(kind, list):
        return Problem(pointer, TYPE_LIST, _json(kind))
    if kind is None:
        return Problem(pointer, NO_TYPE, _json(_outline(schema)))
    return Problem(pointer, UNSUPPORTED_TYPE, _json(kind))


def _is_number(value: object) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _outline(value: object) -> object:
    """``value`` without its prose (descriptions, titles, comments), to quote it short."""
    if isinstance(value, dict):
        return {k: _outline(v) for k, v in value.items() if k not in _PROSE}
    if isinstance(value, list):
        return [_outline(v) for v in value]
    return value


_PROSE = ("description", "title", "$comment", "examples")


def _escape(name: str) -> str:
    return name.replace("~", "~0").replace("/", "~1")


def _json(value: object) -> str:
    text = json.dumps(value, separators=(",", ":"))
    return text if len(text) <= 80 else text[:77] + "..."
