"""What a user installing the package relies on: its version, its licence, its dependencies."""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from importlib import metadata
from pathlib import Path

import pytest

import rsstp_sim

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())


@pytest.mark.parametrize(
    ("program", "name"), [("rsstp_cli.sim", "rsstp-sim"), ("rsstp_cli.replay", "rsstp-replay")]
)
def test_both_commands_print_the_installed_version(program: str, name: str) -> None:
    done = subprocess.run(
        [sys.executable, "-m", program, "--version"], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0
    assert done.stdout.strip() == f"{name} {metadata.version('rsstp')}"
    assert rsstp_sim.__version__ == metadata.version("rsstp") == PYPROJECT["project"]["version"]


def test_the_licence_file_is_the_declared_one() -> None:
    assert PYPROJECT["project"]["license"] == "MIT"
    assert PYPROJECT["project"]["license-files"] == ["LICENSE"]
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")


def test_every_third_party_import_is_declared() -> None:
    """Every module the packages import from outside the standard library and themselves is
    a declared dependency (by its distribution's top-level name)."""
    declared = {
        requirement.split(">")[0].split("<")[0].split("=")[0].strip().lower()
        for requirement in PYPROJECT["project"]["dependencies"]
    }
    provided = {
        module: {dist.lower() for dist in dists}
        for module, dists in metadata.packages_distributions().items()
    }
    imported: set[str] = set()
    for source in (ROOT / "src").rglob("*.py"):
        for node in ast.walk(ast.parse(source.read_text())):
            if isinstance(node, ast.Import):
                imported |= {alias.name.split(".")[0] for alias in node.names}
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                imported.add(node.module.split(".")[0])
    third_party = {
        name
        for name in imported
        if name not in sys.stdlib_module_names
        and name not in {"rsstp_sim", "rsstp_replay", "rsstp_sweep", "rsstp_cli"}
    }
    assert third_party
    for name in sorted(third_party):
        assert provided.get(name, set()) & declared, f"{name} is imported but not declared"
