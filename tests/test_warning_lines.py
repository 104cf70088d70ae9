"""Every warning a user sees is one line in the errors' form, ``PROG: warning: ...``: ours and
the libraries' alike, never Python's format (source file, line number, code line)."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from rsstp_cli._commandline import Parser, run_command
from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def _parser(func: object) -> Parser:
    parser = Parser(prog="prog")
    parser.set_defaults(func=func)
    return parser


def test_a_library_warning_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    def divides_by_zero(args: argparse.Namespace) -> int:
        with np.errstate(divide="warn"):
            np.log(np.zeros(1))  # numpy's own RuntimeWarning
        return 0

    with warnings.catch_warnings():
        warnings.simplefilter("default")  # a user's interpreter, not pytest's "error"
        assert run_command("prog", _parser(divides_by_zero), []) == 0
    assert capsys.readouterr().err == "prog: warning: divide by zero encountered in log\n"


def test_a_warning_of_several_lines_is_folded_into_one(capsys: pytest.CaptureFixture[str]) -> None:
    def warns(args: argparse.Namespace) -> int:
        warnings.warn("first line\n  second line\n", UserWarning, stacklevel=1)
        return 0

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        assert run_command("prog", _parser(warns), []) == 0
    assert capsys.readouterr().err == "prog: warning: first line second line\n"


def test_pythons_own_display_comes_back_after_the_command() -> None:
    before = warnings.showwarning
    run_command("prog", _parser(lambda args: 0), [])
    assert warnings.showwarning is before


def test_an_unfinished_recording_is_one_warning_line(tmp_path: Path) -> None:
    """End to end: a recording cut short, as a killed writer leaves it."""
    whole = (ROOT / "recordings" / "three-joint-random.mcap").read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[: len(whole) * 2 // 3])
    done = subprocess.run(
        [str(BIN / "rsstp-replay"), "info", str(cut)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONWARNINGS": "default"},
        check=False,
        timeout=HANG_S,
    )
    assert done.returncode == 0, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("rsstp-replay: warning: ")
    assert "Warning:" not in done.stderr and ".py:" not in done.stderr
