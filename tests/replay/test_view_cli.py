"""``rsstp-replay view`` and ``graph`` on a real recording (no viewer: .rrd files only)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "recordings" / "thesis-roulette-script.mcap"
LEARNER = ROOT / "recordings" / "two-joint-30-learner.mcap"


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_replay", *args],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(ROOT / "src"), "PATH": "/usr/bin:/bin", "HOME": "/tmp"},
        timeout=120,
    )


def test_view_saves_an_rrd_and_says_how_to_open_it(tmp_path: Path) -> None:
    out = tmp_path / "run.rrd"
    done = run_cli("view", str(REFERENCE), "--save", str(out))
    assert done.returncode == 0, done.stderr
    assert out.stat().st_size > 0
    assert out.read_bytes()[:4] == b"RRF2"  # Rerun's file magic
    assert f"open it with: rerun {out}" in done.stdout
    again = run_cli("view", str(REFERENCE), "--save", str(out))
    assert again.returncode == 2
    assert (
        again.stderr.strip()
        == f"rsstp-replay: error: {out}: already exists (use --force to overwrite)"
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--from", "5", "--to", "500"], "the end step 500 is out of range"),
        (
            ["--save", "/nonexistent/dir/x.rrd"],
            "the output directory /nonexistent/dir does not exist",
        ),
    ],
)
def test_view_bad_arguments_are_one_line(args: list[str], message: str, tmp_path: Path) -> None:
    save = [] if "--save" in args else ["--save", str(tmp_path / "x.rrd")]
    done = run_cli("view", str(REFERENCE), *save, *args)
    assert done.returncode == 2
    assert message in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


def test_graph_draws_the_model_at_a_step(tmp_path: Path) -> None:
    out = tmp_path / "model.svg"
    done = run_cli("graph", str(REFERENCE), "--step", "10", "-o", str(out))
    assert done.returncode == 0, done.stderr
    assert out.read_text().lstrip().startswith(("<?xml", "<svg", "<!DOCTYPE"))
    bad = run_cli("graph", str(REFERENCE), "--step", "1000", "-o", str(tmp_path / "m.svg"))
    assert bad.returncode == 2 and "out of range" in bad.stderr


@pytest.mark.parametrize(
    ("extra", "engine", "what"),
    [((), "sfdp", "the layout of every model version"), (("--on-world",), "neato", "a model of")],
)
def test_a_graphviz_crash_is_one_line(
    tmp_path: Path, extra: tuple[str, ...], engine: str, what: str
) -> None:
    """Graphviz programs that die of SIGSEGV (fakes first on PATH; the learner's union of
    versions has over 400 state pairs, so sfdp lays it out): one line naming the
    program and the signal, exit 2, nothing written."""
    fakes = tmp_path / "bin"
    fakes.mkdir()
    for program in ("dot", "neato", "sfdp"):
        fake = fakes / program
        fake.write_text("#!/bin/sh\nkill -SEGV $$\n")
        fake.chmod(0o755)
    out = tmp_path / "model.svg"
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "rsstp_replay",
            "graph",
            str(LEARNER),
            "--step",
            "9000",
            "-o",
            str(out),
            *extra,
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, "PATH": f"{fakes}:{os.environ['PATH']}"},
    )
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert lines[0].startswith(f"rsstp-replay: error: Graphviz ({engine}) crashed (SIGSEGV) ")
    assert what in lines[0] and lines[0].endswith("write .dot instead to keep the graph")
    assert not out.exists()
