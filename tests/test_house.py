"""House rules a reader relies on: errors live in the errors modules and every error raised on
purpose is the package's own (``except RsstpError`` catches them all)."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
BUILT_IN = {"Exception", "ValueError", "TypeError", "KeyError", "IndexError", "RuntimeError"}
SIGNALS = {"Refuted", "Confined"}
"""Exceptions used as control flow inside one module, never raised to a caller outside it:
the learner's walk tells its planner that the hypothesis was refuted, or that the agent is
confined to a part of the world that never senses."""


def _modules() -> list[tuple[Path, ast.Module]]:
    return [(path, ast.parse(path.read_text(encoding="utf-8"))) for path in SRC.rglob("*.py")]


def test_exception_and_warning_classes_live_in_errors_modules() -> None:
    outside = [
        f"{path.relative_to(SRC)}: {node.name}"
        for path, tree in _modules()
        if path.name != "errors.py"
        for node in ast.walk(tree)
        if isinstance(node, ast.ClassDef)
        and node.name not in SIGNALS
        and any(
            isinstance(base, ast.Name) and base.id.endswith(("Error", "Exception", "Warning"))
            for base in node.bases
        )
    ]
    assert outside == []


def test_no_built_in_exception_is_raised_on_purpose() -> None:
    raised = [
        f"{path.relative_to(SRC)}:{node.lineno}: {node.exc.func.id}"
        for path, tree in _modules()
        for node in ast.walk(tree)
        if isinstance(node, ast.Raise)
        and isinstance(node.exc, ast.Call)
        and isinstance(node.exc.func, ast.Name)
        and node.exc.func.id in BUILT_IN
    ]
    assert raised == []
