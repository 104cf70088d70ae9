"""What every body's scenario validator starts from: errors that name the file, the key path
and what was expected, and the refusal of keys the format does not have."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from rsstp_sim.errors import ScenarioError

__all__ = ["MISSING", "KeyedValidator"]


class _Missing:
    def __repr__(self) -> str:
        return "missing"


MISSING: object = _Missing()
"""What a key that is not there reads as (``table.get(key, MISSING)``)."""


class KeyedValidator:
    """Validation errors of one scenario file, ``origin``."""

    def __init__(self, origin: str) -> None:
        self.origin = origin

    def fail(self, key: str, expected: str, found: object) -> ScenarioError:
        """``ORIGIN: KEY: expected EXPECTED, found FOUND`` (or ``missing``)."""
        shown = "missing" if found is MISSING else f"found {found!r}"
        return ScenarioError(f"{self.origin}: {key}: expected {expected}, {shown}")

    def unknown_keys(
        self, table: Mapping[str, object], allowed: frozenset[str], where: str
    ) -> None:
        """Refuse the first key of ``table`` (at ``where``) not in ``allowed``."""
        for key in sorted(set(table) - allowed):
            path = f"{where}.{key}" if where else key
            raise ScenarioError(
                f"{self.origin}: {path}: unknown key (allowed: {', '.join(sorted(allowed))})"
            )

    def name_and_description(self, data: Mapping[str, object]) -> tuple[str, str]:
        """The scenario's ``name`` (default: the file's stem, or the built-in's name) and its
        one-line ``description`` (default empty)."""
        name = data.get(
            "name", Path(self.origin).stem if self.origin.endswith(".toml") else self.origin
        )
        if not isinstance(name, str):
            raise self.fail("name", "a string", name)
        description = data.get("description", "")
        if not isinstance(description, str):
            raise self.fail("description", "a string", description)
        return name, description
