"""Draw a transition system with Graphviz.

The thesis (section 4.4) first drew the transition matrix with NetworkX and
dropped it for two reasons: edge labels and arrowheads overlapped the nodes,
and the same matrix was drawn at different coordinates every time, so
successive models could not be compared. Graphviz fixed both, and this module
keeps both properties on purpose:

- ``dot`` places edge labels as part of the layout (``forcelabels``, generous
  ``nodesep``/``ranksep``), so labels do not overlap; there is one edge per
  ``(source, target)`` pair, labelled like the thesis's matrix cell (``0,1``).
- :func:`to_dot` is deterministic (sorted iteration, nothing taken from
  memory addresses), and :func:`layout` plus ``to_dot(positions=...)`` pins
  nodes so a sequence of pictures keeps every state in place (rendered with
  ``neato -n2``, which uses the given positions as they are).

Writing ``.dot``/``.gv`` needs only the ``graphviz`` Python package; SVG, PNG
and PDF need the Graphviz programs (:class:`~rsstp_sim.errors.GraphvizMissing`
otherwise).
"""

from __future__ import annotations

import shutil
import signal
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path

import graphviz

from rsstp_sim.errors import GraphvizFailed, GraphvizMissing, ModelError, RsstpError
from rsstp_sim.files import write_whole
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["graphviz_failed", "layout", "plain_positions", "render", "run_graphviz", "to_dot"]

_IMAGE_FORMATS = ("svg", "png", "pdf")
_SOURCE_FORMATS = ("dot", "gv")
_MISSING = (
    "Graphviz {program!r} not found: install it (Debian: apt-get install graphviz) "
    "or write .dot instead"
)
_POINTS_PER_INCH = 72.0


def to_dot(
    model: TransitionSystem,
    *,
    current: int | None = None,
    positions: Mapping[int, tuple[float, float]] | None = None,
    title: str | None = None,
) -> str:
    """DOT source for ``model``: one node per state, one labelled edge per state pair.

    ``current`` (default: ``model.current``) is drawn filled. ``positions``
    (points, as :func:`layout` returns) pin every node with ``pos="x,y!"``;
    they must cover every state. The same arguments give byte-identical source.
    """
    highlighted = model.current if current is None else current
    if highlighted not in model:
        raise ModelError(f"to_dot: current state {highlighted!r} is not in the model")
    if positions is not None:
        missing = [s for s in model.states if s not in positions]
        if missing:
            raise ModelError(f"to_dot: positions missing for states {missing}")

    dot = graphviz.Digraph(
        name="transition_system",
        graph_attr={
            "rankdir": "LR",
            "nodesep": "0.6",
            "ranksep": "0.9",
            "forcelabels": "true",
            "splines": "true",
            "fontname": "Helvetica",
        },
        node_attr={"shape": "circle", "fontname": "Helvetica", "width": "0.5"},
        edge_attr={"fontname": "Helvetica", "fontsize": "11"},
    )
    if title is not None:
        dot.attr(label=title, labelloc="t")
    for s in model.states:
        attrs: dict[str, str] = {}
        if s == highlighted:
            attrs.update(style="filled", fillcolor="#ffd54f", penwidth="2")
        if positions is not None:
            x, y = positions[s]
            attrs["pos"] = f"{float(x):.2f},{float(y):.2f}!"
        dot.node(str(s), **attrs)
    for (s, t), actions in _edge_labels(model).items():
        dot.edge(str(s), str(t), label=",".join(map(str, actions)))
    source: str = dot.source
    return source


def layout(model: TransitionSystem) -> dict[int, tuple[float, float]]:
    """Node centres in points, computed by ``dot``; the same model gives the same positions."""
    plain = run_graphviz("dot", to_dot(model), ["-Tplain"], what=_describe(model))
    return plain_positions(plain.decode())


def plain_positions(plain: str) -> dict[int, tuple[float, float]]:
    """Node centres in points from Graphviz's ``-Tplain`` output (inches, y up)."""
    positions: dict[int, tuple[float, float]] = {}
    for line in plain.splitlines():
        fields = line.split()
        if fields and fields[0] == "node":
            positions[int(fields[1])] = (
                round(float(fields[2]) * _POINTS_PER_INCH, 2),
                round(float(fields[3]) * _POINTS_PER_INCH, 2),
            )
    return positions


def run_graphviz(
    engine: str,
    source: str,
    arguments: Sequence[str],
    *,
    what: str,
    timeout: float | None = None,
) -> bytes:
    """Run the Graphviz program ``engine`` on ``source`` and return what it wrote.

    A missing program is :class:`GraphvizMissing`; one that fails or crashes (even
    before reading its input) is one :class:`GraphvizFailed` line naming ``what``.
    ``timeout`` (seconds) raises :class:`subprocess.TimeoutExpired`.
    """
    if shutil.which(engine) is None:
        raise GraphvizMissing(_MISSING.format(program=engine))
    done = subprocess.run(
        [engine, *arguments],
        input=source.encode(),
        capture_output=True,
        timeout=timeout,
        check=False,
    )
    if done.returncode != 0:
        raise graphviz_failed(engine, done.returncode, done.stderr, what=what)
    return done.stdout


def _describe(model: TransitionSystem) -> str:
    return f"a model of {len(model)} states and {len(model.transitions())} transitions"


def render(
    model: TransitionSystem,
    path: str | Path,
    *,
    format: str | None = None,
    current: int | None = None,
    positions: Mapping[int, tuple[float, float]] | None = None,
) -> Path:
    """Write a picture of ``model`` to ``path`` and return the path.

    The format comes from the suffix (``.svg``, ``.png``, ``.pdf``, ``.dot``,
    ``.gv``) unless ``format`` is given. With ``positions`` the nodes stay
    where they are given (``neato -n2``). Only ``path`` is written.
    """
    out = Path(path)
    fmt = (format or out.suffix.removeprefix(".")).lower()
    if fmt not in _IMAGE_FORMATS + _SOURCE_FORMATS:
        raise RsstpError(
            f"render: cannot tell the picture format of {str(out)!r}: expected one of "
            f"{', '.join(_IMAGE_FORMATS + _SOURCE_FORMATS)}, got {fmt or 'no suffix'!r}"
        )
    source = to_dot(model, current=current, positions=positions)
    if fmt in _SOURCE_FORMATS:
        return write_whole(out, source.encode("utf-8"))
    if positions is None:
        data = run_graphviz("dot", source, [f"-T{fmt}"], what=_describe(model))
    else:
        data = run_graphviz("neato", source, ["-n2", f"-T{fmt}"], what=_describe(model))
    return write_whole(out, data)


def graphviz_failed(
    engine: str, returncode: int, stderr: bytes | str | None, *, what: str
) -> GraphvizFailed:
    """The one-line error for a Graphviz program that failed (exit status) or crashed
    (signal, e.g. SIGSEGV) drawing ``what``."""
    if returncode < 0:
        try:
            how = f"crashed ({signal.Signals(-returncode).name})"
        except ValueError:
            how = f"crashed (signal {-returncode})"
    else:
        how = f"failed (exit status {returncode})"
    text = stderr.decode(errors="replace") if isinstance(stderr, bytes) else stderr or ""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    detail = f": {lines[0][:200]}" if lines else ""
    return GraphvizFailed(
        f"Graphviz ({engine}) {how} drawing {what}{detail}; write .dot instead to keep the graph"
    )


def _edge_labels(model: TransitionSystem) -> dict[tuple[int, int], list[int]]:
    """Sorted actions per ``(source, target)``, in sorted pair order (the matrix cells)."""
    labels: dict[tuple[int, int], list[int]] = {}
    for s, a, t in sorted(model.transitions(), key=lambda sat: (sat[0], sat[2], sat[1])):
        labels.setdefault((s, t), []).append(a)
    return labels
