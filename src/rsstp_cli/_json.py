"""A JSON document as ``--json`` prints it: ``json.dumps(value, indent=2)``, the same text,
faster.

With an indent, :func:`json.dumps` encodes in Python, a token at a time; an audit's document
holds millions of numbers (a column per model version). Here only the containers that hold
other containers are walked in Python; a container of plain values (numbers, text, true,
false, null) is encoded by the C encoder in one call, with ``"\\0"`` between its items, and
each ``"\\0"`` becomes the indented line break: with ``ensure_ascii`` (the default) a control
character inside a string is escaped, so a bare ``"\\0"`` is always a separator.
"""

from __future__ import annotations

import json
from itertools import repeat
from json.encoder import encode_basestring_ascii  # type: ignore[attr-defined]
from typing import Any

__all__ = ["indented"]

_INDENT = 2
_CONTAINERS = (dict, list, tuple)
_plain = json.JSONEncoder(separators=("\0", ": ")).encode
"""A value in one line, ``"\\0"`` between a container's items."""


def indented(value: Any) -> str:
    """``json.dumps(value, indent=2)``."""
    parts: list[str] = []
    _write(value, 0, parts)
    return "".join(parts)


def _write(value: Any, depth: int, parts: list[str]) -> None:
    if type(value) is int:
        parts.append(int.__repr__(value))
        return
    if type(value) is str:
        parts.append(encode_basestring_ascii(value))
        return
    if not isinstance(value, _CONTAINERS) or not value:  # a plain value, [] or {}
        parts.append(_plain(value))
        return
    inner = "\n" + " " * (_INDENT * (depth + 1))
    closing = "\n" + " " * (_INDENT * depth)
    items = value.values() if isinstance(value, dict) else value
    if not any(map(isinstance, items, repeat(_CONTAINERS))):  # plain values: one call
        text = _plain(value)
        parts.append(text[0] + inner + text[1:-1].replace("\0", "," + inner) + closing + text[-1])
        return
    kinds = {dict if isinstance(item, dict) else isinstance(item, list | tuple) for item in items}
    if kinds in ({dict}, {True}) and not any(map(_nested, items)):  # containers of plain values
        _write_leaves(value, dict in kinds, inner, closing, parts)
        return
    if isinstance(value, dict):
        parts.append("{")
        for k, (key, item) in enumerate(value.items()):
            parts.append(("," if k else "") + inner + _name(key) + ": ")
            _write(item, depth + 1, parts)
        parts.append(closing + "}")
        return
    parts.append("[")
    for k, item in enumerate(value):
        parts.append(("," if k else "") + inner)
        _write(item, depth + 1, parts)
    parts.append(closing + "]")


def _nested(value: Any) -> bool:
    """Whether ``value`` (a container) holds a container."""
    items = value.values() if isinstance(value, dict) else value
    return any(map(isinstance, items, repeat(_CONTAINERS)))


def _write_leaves(value: Any, of_dicts: bool, inner: str, closing: str, parts: list[str]) -> None:
    """A container (``inner``, ``closing``: its line breaks) whose items are all containers
    of plain values, all dicts (``of_dicts``) or all lists: its items encoded in one call,
    then cut apart where one ends and the next begins (``}\\0{`` or ``]\\0[``: a bare
    ``"\\0"`` is never inside a string)."""
    items = list(value.values()) if isinstance(value, dict) else value
    opening, ending = ("{", "}") if of_dicts else ("[", "]")
    deeper = inner + " " * _INDENT
    pieces = _plain(items)[2:-2].split(ending + "\0" + opening)
    texts = [
        opening + deeper + piece.replace("\0", "," + deeper) + inner + ending
        if piece
        else opening + ending
        for piece in pieces
    ]
    if isinstance(value, dict):
        names = [_name(key) for key in value]
        texts = [name + ": " + text for name, text in zip(names, texts, strict=True)]
    outer = ("{", "}") if isinstance(value, dict) else ("[", "]")
    parts.append(outer[0] + inner + ("," + inner).join(texts) + closing + outer[1])


def _name(key: Any) -> str:
    """A key as json.dumps writes it (a number, true, false or null as text)."""
    if type(key) is str:
        return str(encode_basestring_ascii(key))
    return json.dumps({key: None})[1 : -len(": null}")]
