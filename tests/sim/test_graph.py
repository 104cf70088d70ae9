"""Tests for the Graphviz drawing of a transition system."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from rsstp_sim.errors import GraphvizFailed, GraphvizMissing, ModelError, RsstpError
from rsstp_sim.graph import layout, render, to_dot
from rsstp_sim.transition_system import TransitionSystem

FIGURE_16 = [
    [[0], [0, 1], [], []],
    [[0], [0], [0, 1], []],
    [[1], [], [], [0]],
    [[1], [0], [0, 1], []],
]

needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz 'dot' not installed")


@pytest.fixture
def model() -> TransitionSystem:
    return TransitionSystem.from_matrix(FIGURE_16)


def _edges(source: str) -> dict[tuple[str, str], str]:
    found = re.findall(r'^\s*(\d+) -> (\d+) \[label="?([\d,]+)"?\]$', source, flags=re.M)
    return {(s, t): label for s, t, label in found}


def test_to_dot_has_one_labelled_edge_per_matrix_cell(model: TransitionSystem) -> None:
    source = to_dot(model)
    expected = {
        (str(i), str(j)): ",".join(map(str, cell))
        for i, row in enumerate(FIGURE_16)
        for j, cell in enumerate(row)
        if cell
    }
    assert _edges(source) == expected
    assert "forcelabels=true" in source
    assert source.startswith("digraph transition_system {")


def test_to_dot_is_deterministic(model: TransitionSystem) -> None:
    rebuilt = TransitionSystem(4)
    for s, a, t in reversed(model.transitions()):
        rebuilt.add(s, t, a)
    assert to_dot(model) == to_dot(model.copy()) == to_dot(rebuilt)


def test_to_dot_highlights_the_current_state(model: TransitionSystem) -> None:
    filled = re.compile(r"^\s*(\d+) \[.*style=filled.*\]$", flags=re.M)
    assert filled.findall(to_dot(model)) == ["0"]
    model.current = 2
    assert filled.findall(to_dot(model)) == ["2"]
    assert filled.findall(to_dot(model, current=3)) == ["3"]
    with pytest.raises(ModelError, match=r"to_dot: current state 9 is not in the model"):
        to_dot(model, current=9)


def test_to_dot_title_and_positions(model: TransitionSystem) -> None:
    positions = {s: (10.0 * s, 5.5) for s in model.states}
    source = to_dot(model, positions=positions, title="Figure 16")
    assert 'label="Figure 16"' in source
    assert '2 [pos="20.00,5.50!"]' in source
    with pytest.raises(ModelError, match=r"positions missing for states \[3\]"):
        to_dot(model, positions={0: (0, 0), 1: (1, 1), 2: (2, 2)})


@needs_dot
def test_layout_places_every_state_deterministically(model: TransitionSystem) -> None:
    model.split(1)
    positions = layout(model)
    assert sorted(positions) == list(model.states)
    assert len(set(positions.values())) == len(model)
    assert all(isinstance(c, float) for xy in positions.values() for c in xy)
    assert layout(model) == positions


@needs_dot
def test_render_svg_writes_only_the_picture(model: TransitionSystem, tmp_path: Path) -> None:
    out = render(model, tmp_path / "model.svg")
    assert out == tmp_path / "model.svg"
    text = out.read_text(encoding="utf-8")
    assert "<svg" in text and "</svg>" in text
    assert ">0,1<" in text
    assert [p.name for p in tmp_path.iterdir()] == ["model.svg"]


@needs_dot
def test_render_with_positions_keeps_nodes_in_place(
    model: TransitionSystem, tmp_path: Path
) -> None:
    bigger = model.copy()
    bigger.split(3)
    positions = layout(bigger)
    first = render(model, tmp_path / "a.svg", positions=positions).read_text(encoding="utf-8")
    second = render(bigger, tmp_path / "b.svg", positions=positions).read_text(encoding="utf-8")

    def node_centres(svg: str) -> dict[str, tuple[str, str]]:
        pattern = r"<title>(\d+)</title>\s*<ellipse [^>]*cx=\"([-\d.]+)\" cy=\"([-\d.]+)\""
        return {m[0]: (m[1], m[2]) for m in re.findall(pattern, svg)}

    a, b = node_centres(first), node_centres(second)
    assert sorted(a) == ["0", "1", "2", "3"]
    assert sorted(b) == ["0", "1", "2", "3", "4"]
    assert all(a[s] == b[s] for s in a)


@needs_dot
def test_render_png_and_explicit_format(model: TransitionSystem, tmp_path: Path) -> None:
    png = render(model, tmp_path / "model.png")
    assert png.read_bytes().startswith(b"\x89PNG")
    pdf = render(model, tmp_path / "picture", format="pdf")
    assert pdf.read_bytes().startswith(b"%PDF")


@pytest.mark.parametrize("suffix", ["dot", "gv"])
def test_render_source_needs_no_program(
    model: TransitionSystem, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str
) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))
    out = render(model, tmp_path / f"model.{suffix}", current=1)
    assert out.read_text(encoding="utf-8") == to_dot(model, current=1)


@pytest.mark.parametrize("suffix", ["svg", "png", "pdf"])
def test_render_without_graphviz_says_how_to_fix_it(
    model: TransitionSystem, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str
) -> None:
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(GraphvizMissing, match=r"apt-get install graphviz\) or write \.dot"):
        render(model, tmp_path / f"model.{suffix}")
    assert list(tmp_path.iterdir()) == []


def test_layout_without_graphviz(model: TransitionSystem, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shutil, "which", lambda _name: None)
    with pytest.raises(GraphvizMissing, match=r"Graphviz 'dot' not found"):
        layout(model)


def test_render_refuses_unknown_formats(model: TransitionSystem, tmp_path: Path) -> None:
    with pytest.raises(RsstpError, match=r"expected one of svg, png, pdf, dot, gv, got 'txt'"):
        render(model, tmp_path / "model.txt")
    with pytest.raises(RsstpError, match=r"got 'no suffix'"):
        render(model, tmp_path / "model")


@pytest.mark.parametrize("positions", [False, True])
def test_a_program_that_dies_before_reading_is_one_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, positions: bool
) -> None:
    """A Graphviz program that crashes before reading its input (source larger than a
    pipe's buffer, so writing it would break the pipe) is GraphvizFailed naming the
    signal, never a broken pipe; nothing is written."""
    for program in ("dot", "neato"):
        fake = tmp_path / program
        fake.write_text("#!/bin/sh\nkill -SEGV $$\n")
        fake.chmod(0o755)
    monkeypatch.setenv("PATH", str(tmp_path))
    n = 3000
    big = TransitionSystem.from_matrix(
        [[[0] if t in (s, (s + 1) % n) else [] for t in range(n)] for s in range(n)]
    )
    assert len(to_dot(big)) > 1 << 16
    places = {s: (float(s), 0.0) for s in big.states} if positions else None
    out = tmp_path / "model.svg"
    with pytest.raises(GraphvizFailed, match=r"crashed \(SIGSEGV\) drawing a model of 3000 states"):
        render(big, out, positions=places)
    assert not out.exists()


def test_a_picture_that_cannot_be_written_whole_leaves_the_old_one(tmp_path: Path) -> None:
    """EFBIG (RLIMIT_FSIZE in the child) while writing: one line, exit 1, the old file as it
    was and no side file."""
    import resource
    import subprocess
    import sys

    out = tmp_path / "model.dot"
    out.write_text("the old picture")

    def tiny_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20, 20))

    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "graph", "--matrix", "[[[0],[1]],[[1],[0]]]",
         "-o", str(out), "--force"],
        capture_output=True, text=True, timeout=60, preexec_fn=tiny_files,
    )  # fmt: skip
    assert done.returncode == 1
    assert done.stderr.strip() == f"rsstp-sim: error: {out}: cannot write: File too large"
    assert out.read_text() == "the old picture"
    assert [p.name for p in tmp_path.iterdir()] == ["model.dot"]
