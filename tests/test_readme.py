"""The README's Python examples run (docs that cannot rot)."""

from __future__ import annotations

import re
import textwrap
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_readme_has_python_examples():
    assert BLOCKS


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One folder for every example, in order, as a reader follows them; it already holds the
    recordings the README's command lines write (their names, at least)."""
    found = tmp_path_factory.mktemp("readme")
    for name in re.findall(r"-o (\S+\.mcap)", README.read_text()):
        (found / name).write_bytes(b"written by a command line example")
    return found


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_example_runs(index: int, folder: Path, monkeypatch: pytest.MonkeyPatch):
    monkeypatch.chdir(folder)
    code = textwrap.dedent(BLOCKS[index])  # a block inside a list item is indented
    exec(compile(code, f"README.md python block {index}", "exec"), {})
