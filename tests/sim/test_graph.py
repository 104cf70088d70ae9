"""Tests for the Graphviz drawing of a transition system (Graphviz in process, from
``pygraphviz``'s wheel: no Graphviz program is ever run)."""

from __future__ import annotations

import json
import os
import re
import struct
import subprocess
import sys
from pathlib import Path

import pytest
from pygraphviz import graphviz as gv

from rsstp_sim.errors import GraphvizFailed, ModelError, RsstpError
from rsstp_sim.graph import layout, render, run_graphviz, to_dot
from rsstp_sim.transition_system import TransitionSystem
from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[2]

FIGURE_16 = [
    [[0], [0, 1], [], []],
    [[0], [0], [0, 1], []],
    [[1], [], [], [0]],
    [[1], [0], [0, 1], []],
]


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


def test_layout_places_every_state_deterministically(model: TransitionSystem) -> None:
    model.split(1)
    positions = layout(model)
    assert sorted(positions) == list(model.states)
    assert len(set(positions.values())) == len(model)
    assert all(isinstance(c, float) for xy in positions.values() for c in xy)
    assert layout(model) == positions


def test_render_svg_writes_only_the_picture(model: TransitionSystem, tmp_path: Path) -> None:
    out = render(model, tmp_path / "model.svg")
    assert out == tmp_path / "model.svg"
    text = out.read_text(encoding="utf-8")
    assert "<svg" in text and "</svg>" in text
    assert ">0,1<" in text
    assert [p.name for p in tmp_path.iterdir()] == ["model.svg"]


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


def test_render_refuses_unknown_formats(model: TransitionSystem, tmp_path: Path) -> None:
    with pytest.raises(RsstpError, match=r"expected one of svg, png, pdf, dot, gv, got 'txt'"):
        render(model, tmp_path / "model.txt")
    with pytest.raises(RsstpError, match=r"got 'no suffix'"):
        render(model, tmp_path / "model")


def _failing_layout(
    monkeypatch: pytest.MonkeyPatch, message: bytes
) -> list[tuple[object, object, bytes]]:
    """Graphviz's layout call made to fail as it does: its error on file descriptor 2, status
    -1. Returns the calls it was given."""
    calls: list[tuple[object, object, bytes]] = []

    def fail(context: object, handle: object, engine: bytes) -> int:
        calls.append((context, handle, engine))
        os.write(2, message)
        return -1

    monkeypatch.setattr(gv, "gvLayout", fail)
    return calls


@pytest.mark.parametrize(("positions", "engine"), [(False, "dot"), (True, "nop2")])
def test_a_layout_that_fails_inside_graphviz_is_one_error(
    model: TransitionSystem,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
    positions: bool,
    engine: str,
) -> None:
    """GraphvizFailed naming the engine, the model and Graphviz's first error (fontconfig's
    complaint before it is not the error); nothing reaches stderr, nothing is written."""
    calls = _failing_layout(
        monkeypatch, b"Fontconfig warning: line 6: unknown element\nError: out of cheese\nmore\n"
    )
    places = {s: (40.0 * s, 0.0) for s in model.states} if positions else None
    out = tmp_path / "model.svg"
    with pytest.raises(GraphvizFailed) as raised:
        render(model, out, positions=places)
    assert str(raised.value) == (
        f"Graphviz ({engine}) failed drawing a model of 4 states and 13 transitions: "
        "Error: out of cheese; write .dot instead to keep the graph"
    )
    assert [call[2] for call in calls] == [engine.encode()]
    assert not out.exists()
    os.write(2, b"after\n")  # file descriptor 2 is the terminal's again
    assert capfd.readouterr().err == "after\n"


def test_a_failure_graphviz_says_nothing_about_is_still_one_error(
    model: TransitionSystem, monkeypatch: pytest.MonkeyPatch
) -> None:
    _failing_layout(monkeypatch, b"")
    with pytest.raises(
        GraphvizFailed,
        match=r"^Graphviz \(dot\) failed drawing a model of 4 states .*: the dot layout failed "
        r"\(status -1\); write \.dot",
    ):
        layout(model)


def test_what_graphviz_says_on_a_call_that_succeeds_is_dropped(
    model: TransitionSystem,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capfd: pytest.CaptureFixture[str],
) -> None:
    """As the wheel's sfdp says ``Error: remove_overlap: Graphviz not built with triangulation
    library`` on every layout that succeeds, and its fontconfig warns of the system's fonts."""
    lay_out = gv.gvLayout

    def noisy(context: object, handle: object, engine: bytes) -> int:
        os.write(2, b"Error: remove_overlap: Graphviz not built with triangulation library\n")
        status: int = lay_out(context, handle, engine)
        return status

    monkeypatch.setattr(gv, "gvLayout", noisy)
    assert render(model, tmp_path / "model.svg").read_text(encoding="utf-8").startswith("<?xml")
    assert capfd.readouterr().err == ""


@pytest.mark.parametrize(
    ("engine", "source", "output", "error"),
    [
        ("twirl", "digraph { a }", "svg", r'Error: Layout type: "twirl" not recognized'),
        ("dot", "digraph { a -> }", "svg", r"Error: syntax error in line 1"),
        ("dot", "digraph { a }", "gif9", r'Error: Format: "gif9" not recognized'),
    ],
)
def test_graphviz_own_errors_are_one_line_and_nothing_on_stderr(
    capfd: pytest.CaptureFixture[str], engine: str, source: str, output: str, error: str
) -> None:
    with pytest.raises(GraphvizFailed, match=rf"^Graphviz \({engine}\) failed drawing x: {error}"):
        run_graphviz(engine, source, output, what="x")
    assert capfd.readouterr().err == ""


_DRAW_EVERYTHING = """
import json, sys
from pathlib import Path
from rsstp_replay import open_recording
from rsstp_replay.viewer import graph_positions, render_graph
from rsstp_sim.graph import layout, render
from rsstp_sim.transition_system import TransitionSystem

out = Path(sys.argv[1])
model = TransitionSystem.from_matrix(json.loads(sys.argv[2]))
places = layout(model)
render(model, out / "laid-out.svg")
render(model, out / "laid-out.png")
render(model, out / "pinned.svg", positions=places)
render(model, out / "pinned.png", positions=places)
render(model, out / "pinned.pdf", positions=places)
with open_recording(sys.argv[3]) as recording:  # its union is laid out by sfdp
    union = graph_positions(recording.model_versions())
    render_graph(recording, recording.n_steps, out / "learner.svg")
print(json.dumps({"places": places, "union": len(union)}))
"""


def test_everything_is_drawn_with_no_graphviz_program_and_no_noise(tmp_path: Path) -> None:
    """In a fresh process whose PATH holds only Graphviz programs that would leave a mark and
    fail (``dot``, ``neato``, ``sfdp``...): ``dot`` laid out, ``nop2`` pinned, SVG, PNG and PDF,
    and the learner's union by ``sfdp``; stderr stays empty (fontconfig's warnings and sfdp's
    ``remove_overlap`` notice are kept off it) and no program ran."""
    fakes = tmp_path / "bin"
    fakes.mkdir()
    marks = tmp_path / "ran"
    for program in ("dot", "neato", "sfdp", "fdp", "circo", "twopi"):
        fake = fakes / program
        fake.write_text(f"#!/bin/sh\necho {program} >> {marks}\nexit 1\n")
        fake.chmod(0o755)
    pictures = tmp_path / "pictures"
    pictures.mkdir()
    done = subprocess.run(
        [sys.executable, "-c", _DRAW_EVERYTHING, str(pictures), json.dumps(FIGURE_16),
         str(ROOT / "recordings" / "two-joint-30-learner.mcap")],
        capture_output=True, text=True, timeout=HANG_S,
        env={"PATH": str(fakes), "PYTHONPATH": str(ROOT / "src"), "HOME": str(tmp_path)},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""
    assert not marks.exists()
    report = json.loads(done.stdout)
    assert sorted(report["places"]) == ["0", "1", "2", "3"] and report["union"] == 119
    for name in ("laid-out", "pinned"):
        svg = (pictures / f"{name}.svg").read_text(encoding="utf-8")
        assert svg.startswith("<?xml") and svg.rstrip().endswith("</svg>")
        assert re.findall(r"<title>(\d+)</title>", svg) == ["0", "1", "2", "3"]
        png = (pictures / f"{name}.png").read_bytes()
        assert png.startswith(b"\x89PNG\r\n\x1a\n") and png[12:16] == b"IHDR"
        width, height = struct.unpack(">II", png[16:24])
        assert width > 100 and height > 50
    assert (pictures / "pinned.pdf").read_bytes().startswith(b"%PDF")
    learner = (pictures / "learner.svg").read_text(encoding="utf-8")
    assert len(set(re.findall(r"<title>(\d+)</title>", learner))) == 119


def _graph_under_a_20_byte_file_limit(out: Path) -> subprocess.CompletedProcess[str]:
    """``rsstp-sim graph`` of a 2-state matrix onto ``out`` (an old picture there first) in a
    process that may write files of at most 20 bytes (RLIMIT_FSIZE)."""
    import resource

    out.write_text("the old picture")

    def tiny_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20, 20))

    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "graph", "--matrix", "[[[0],[1]],[[1],[0]]]",
         "-o", str(out), "--force"],
        capture_output=True, text=True, timeout=HANG_S, preexec_fn=tiny_files,
    )  # fmt: skip


@pytest.mark.parametrize("suffix", ["svg", "png"])
def test_a_file_size_limit_met_handing_the_source_to_graphviz_is_one_line(
    tmp_path: Path, suffix: str
) -> None:
    """pygraphviz hands the DOT source to Graphviz in a temporary file: past RLIMIT_FSIZE it
    cannot be written (EFBIG): one line, exit 1 (the disk failed, not the input), the old
    picture as it was."""
    out = tmp_path / f"model.{suffix}"
    done = _graph_under_a_20_byte_file_limit(out)
    assert done.returncode == 1
    assert done.stderr.strip() == (
        "rsstp-sim: error: cannot hand the DOT source of a model of 2 states and 4 transitions "
        "to Graphviz: a temporary file could not be written (File too large)"
    )
    assert out.read_text() == "the old picture"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_a_picture_that_cannot_be_written_whole_leaves_the_old_one(tmp_path: Path) -> None:
    """EFBIG (RLIMIT_FSIZE in the child) while writing: one line, exit 1, the old file as it
    was and no side file."""
    out = tmp_path / "model.dot"
    done = _graph_under_a_20_byte_file_limit(out)
    assert done.returncode == 1
    assert done.stderr.strip() == f"rsstp-sim: error: {out}: cannot write: File too large"
    assert out.read_text() == "the old picture"
    assert [p.name for p in tmp_path.iterdir()] == ["model.dot"]
