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
  nodes so a sequence of pictures keeps every state in place (drawn by
  ``neato -n2``'s engine, ``nop2``, which uses the given positions as they are).

Graphviz runs in this process, from the libraries inside ``pygraphviz``'s wheel (a dependency):
no Graphviz program is needed. What Graphviz prints is kept off the terminal and a failure is one
:class:`~rsstp_sim.errors.GraphvizFailed` line (:func:`run_graphviz`). Writing ``.dot``/``.gv``
runs no Graphviz at all.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

from rsstp_sim._graphviz import run_graphviz
from rsstp_sim.errors import ModelError, RsstpError
from rsstp_sim.files import write_whole
from rsstp_sim.transition_system import TransitionSystem

__all__ = ["layout", "plain_positions", "render", "run_graphviz", "to_dot"]

_IMAGE_FORMATS = ("svg", "png", "pdf")
_SOURCE_FORMATS = ("dot", "gv")
_POINTS_PER_INCH = 72.0
_BARE_ID = re.compile(r"[a-zA-Z_][a-zA-Z0-9_]*|-?(\.[0-9]+|[0-9]+(\.[0-9]*)?)")
_KEYWORDS = frozenset({"node", "edge", "graph", "digraph", "subgraph", "strict"})


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

    lines = [
        "digraph transition_system {",
        "\tgraph [fontname=Helvetica forcelabels=true nodesep=0.6 rankdir=LR ranksep=0.9 "
        "splines=true]",
        "\tnode [fontname=Helvetica shape=circle width=0.5]",
        "\tedge [fontname=Helvetica fontsize=11]",
    ]
    if title is not None:
        lines.append(f"\tlabel={_quote(title)} labelloc=t")
    for s in model.states:
        attrs: dict[str, str] = {}
        if s == highlighted:
            attrs.update(style="filled", fillcolor="#ffd54f", penwidth="2")
        if positions is not None:
            x, y = positions[s]
            attrs["pos"] = f"{float(x):.2f},{float(y):.2f}!"
        lines.append(f"\t{_quote(str(s))}{_attributes(attrs)}")
    for (s, t), actions in _edge_labels(model).items():
        label = {"label": ",".join(map(str, actions))}
        lines.append(f"\t{_quote(str(s))} -> {_quote(str(t))}{_attributes(label)}")
    return "\n".join([*lines, "}"]) + "\n"


def _attributes(attrs: Mapping[str, str]) -> str:
    """`` [key=value ...]`` by key (nothing for no attributes), values quoted as DOT needs."""
    if not attrs:
        return ""
    return " [" + " ".join(f"{key}={_quote(attrs[key])}" for key in sorted(attrs)) + "]"


def _quote(value: str) -> str:
    """``value`` as a DOT ID: bare when it is a name or a number (and no keyword), otherwise a
    quoted string of the same text (a backslash stays a backslash: no DOT escapes)."""
    if _BARE_ID.fullmatch(value) and value.lower() not in _KEYWORDS:
        return value
    return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'


def layout(model: TransitionSystem) -> dict[int, tuple[float, float]]:
    """Node centres in points, computed by ``dot``; the same model gives the same positions."""
    plain = run_graphviz("dot", to_dot(model), "plain", what=_describe(model))
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
    where they are given (``neato -n2``'s engine), otherwise ``dot`` lays the model out. Only
    ``path`` is written, and only once the picture is whole.
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
    engine = "dot" if positions is None else "nop2"
    return write_whole(out, run_graphviz(engine, source, fmt, what=_describe(model)))


def _edge_labels(model: TransitionSystem) -> dict[tuple[int, int], list[int]]:
    """Sorted actions per ``(source, target)``, in sorted pair order (the matrix cells)."""
    labels: dict[tuple[int, int], list[int]] = {}
    for s, a, t in sorted(model.transitions(), key=lambda sat: (sat[0], sat[2], sat[1])):
        labels.setdefault((s, t), []).append(a)
    return labels
