"""The JSON Schemas of a recording, written from the record classes.

Each message's fields are declared once, in :mod:`~rsstp_format.records`: their
names, order and types, and (in each field's ``Annotated`` metadata) their description and
the keywords that bound their values. This module writes ``schemas/*.json`` from them, byte
for byte (2-space indent, UTF-8, a final newline): a recording registers the files' bytes,
so the text is part of the contract, and ``tests/sim/test_schema_text.py`` fails when a
checked-in file differs from what this gives. After changing a record class::

    python -m rsstp_format.schema_text            # rewrites schemas/*.json
    python -m rsstp_format.schema_text --check    # exit 1 if a file differs

How a field's type reads: ``int`` ``integer``, ``float`` ``number``, ``bool`` ``boolean``,
``str`` ``string``, a ``Literal`` a string with its ``enum``, a tuple an ``array`` of its
``items``, a record an open ``object`` (required: its fields without a default), ``X | None``
the same field left out of ``required``. An event's ``data`` (a dict in the record) takes its
properties from ``records._EventData`` and gives the schema's ``allOf``, one branch per
struct of ``records._EVENT_DATA`` that requires a field.

>>> from rsstp_format.schemas import schema_bytes
>>> schema_text("rsstp.Step") == schema_bytes("rsstp.Step").decode("utf-8")
True
"""

from __future__ import annotations

import argparse
import json
import sys
import types
import typing
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import msgspec

from rsstp_format.errors import RecordFormatError
from rsstp_format.records import RECORD_TYPES
from rsstp_format.schemas import SCHEMA_NAMES, SCHEMA_VERSION

__all__ = ["SCHEMA_DIALECT", "main", "schema_document", "schema_text", "write_schemas"]

SCHEMA_DIALECT = "https://json-schema.org/draft/2020-12/schema"

_SCALARS: dict[object, str] = {int: "integer", float: "number", bool: "boolean", str: "string"}


def schema_document(name: str) -> dict[str, Any]:
    """The schema of message ``name`` (``rsstp.Step``, ...), as a dict in the file's key
    order."""
    cls = RECORD_TYPES[name]
    document: dict[str, Any] = {
        "$schema": SCHEMA_DIALECT,
        "title": name,
        "version": SCHEMA_VERSION,
        "description": cls.schema_description,
    }
    document |= _object(cls)
    branches = [
        branch
        for field, hint in _fields(cls)
        for branch in _branches(field.name, _meta(hint).get("by_kind"))
    ]
    if branches:
        document["allOf"] = branches
    return document


def schema_text(name: str) -> str:
    """The text of ``schemas/{name}.json``."""
    return json.dumps(schema_document(name), indent=2, ensure_ascii=False) + "\n"


def write_schemas(directory: Path, *, check: bool = False) -> list[Path]:
    """Write every schema file into ``directory`` (with ``check``, write nothing); the files
    that differed from the generated text."""
    stale = []
    for name in SCHEMA_NAMES:
        path = directory / f"{name}.json"
        data = schema_text(name).encode("utf-8")
        if not path.is_file() or path.read_bytes() != data:
            stale.append(path)
            if not check:
                path.write_bytes(data)
    return stale


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m rsstp_format.schema_text [--check] [DIRECTORY]``."""
    parser = argparse.ArgumentParser(
        prog="python -m rsstp_format.schema_text",
        description="Write the recording's JSON Schemas from the record classes.",
    )
    parser.add_argument(
        "directory",
        nargs="?",
        type=Path,
        default=Path(__file__).resolve().parent / "schemas",
        help="where the schema files are (default: the package's schemas, the repository's "
        "schemas/ folder)",
    )
    parser.add_argument(
        "--check", action="store_true", help="write nothing; exit 1 if a file differs"
    )
    args = parser.parse_args(argv)
    stale = write_schemas(args.directory, check=args.check)
    for path in stale:
        print(f"{path}: {'differs from the records' if args.check else 'written'}")
    return 1 if args.check and stale else 0


# ------------------------------------------------------------------ the emitter


def _fields(cls: type) -> list[tuple[msgspec.structs.FieldInfo, Any]]:
    """The struct's fields in order, each with its type hint (``Annotated`` kept)."""
    hints = typing.get_type_hints(cls, include_extras=True)
    return [(field, hints[field.name]) for field in msgspec.structs.fields(cls)]


def _meta(hint: Any) -> dict[str, Any]:
    """The ``extra`` of the ``msgspec.Meta`` of ``hint`` (``X | None`` looked through)."""
    hint = _required_form(hint)
    if typing.get_origin(hint) is not Annotated:
        return {}
    found: dict[str, Any] = {}
    for meta in hint.__metadata__:
        if isinstance(meta, msgspec.Meta) and meta.extra:
            found |= meta.extra
    return found


def _required_form(hint: Any) -> Any:
    """``X`` for ``X | None``; any other hint as it is."""
    if typing.get_origin(hint) in (Union, types.UnionType):
        (hint,) = [arg for arg in typing.get_args(hint) if arg is not type(None)]
    return hint


def _value(hint: Any, descriptions: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The schema of a value of type ``hint``: its description, its type and what goes with
    the type (``enum``, ``items``, an object's properties), then its bounds."""
    hint = _required_form(hint)
    if typing.get_origin(hint) is Annotated:
        metas = [meta for meta in hint.__metadata__ if isinstance(meta, msgspec.Meta)]
        extra = {key: value for meta in metas for key, value in (meta.extra or {}).items()}
        if "fields" in extra:  # a dict whose properties a struct declares
            inner = _object(extra["fields"])
        else:
            inner = _value(hint.__origin__, extra.get("descriptions"))
        description = next((m.description for m in metas if m.description), None)
        description = description or inner.pop("description", None)
        result = {"description": description} if description else {}
        result |= inner
        for meta in metas:
            result |= meta.extra_json_schema or {}
        return result
    if hint in _SCALARS:
        return {"type": _SCALARS[hint]}
    origin = typing.get_origin(hint)
    if origin is Literal:
        return {"type": "string", "enum": list(typing.get_args(hint))}
    if origin is tuple:
        item, ellipsis = typing.get_args(hint)
        if ellipsis is not Ellipsis:
            raise RecordFormatError(f"a record's array is tuple[X, ...], found {hint}")
        return {"type": "array", "items": _value(item)}
    if isinstance(hint, type) and issubclass(hint, msgspec.Struct):
        return _object(hint, descriptions=descriptions)
    raise RecordFormatError(f"no JSON Schema for a field of type {hint!r}")


def _object(
    cls: type, *, descriptions: Mapping[str, str] | None = None, typed: bool = True
) -> dict[str, Any]:
    """The schema of a record: an open object, its required fields, its properties (their
    descriptions replaced by ``descriptions``, by field name, where it has them). With
    ``typed=False``, without ``type`` and ``additionalProperties`` (an ``allOf`` branch, which
    only adds requirements)."""
    fields = _fields(cls)
    result: dict[str, Any] = {"type": "object", "additionalProperties": True} if typed else {}
    required = [field.name for field, _ in fields if field.required]
    if required:
        result["required"] = required
    properties = {}
    for field, hint in fields:
        schema = _value(hint)
        if descriptions and field.name in descriptions:
            schema["description"] = descriptions[field.name]
        properties[field.name] = schema
    result["properties"] = properties
    return result


def _branches(field: str, by_kind: Mapping[str, type] | None) -> list[dict[str, Any]]:
    """The ``allOf`` branches of a field declared by kind: for each struct that requires a
    field, ``if`` the message's ``kind`` is one of its kinds ``then`` ``field`` has its
    fields."""
    if not by_kind:
        return []
    kinds_of: dict[type, list[str]] = {}
    for kind, cls in by_kind.items():
        kinds_of.setdefault(cls, []).append(kind)
    branches = []
    for cls, kinds in kinds_of.items():
        if not any(f.required for f in msgspec.structs.fields(cls)):
            continue  # nothing to require
        test = {"const": kinds[0]} if len(kinds) == 1 else {"enum": kinds}
        named = ", ".join(kinds[:-1]) + " or " + kinds[-1] if len(kinds) > 1 else kinds[0]
        data = {"description": f"the data of a {named} event"}
        data |= _object(cls, typed=False)
        branches.append(
            {"if": {"properties": {"kind": test}}, "then": {"properties": {field: data}}}
        )
    return branches


if __name__ == "__main__":
    sys.exit(main())
