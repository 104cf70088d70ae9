"""The thesis-style picture's layout: one Graphviz layout of every version at once.

Positions are in points, y up (Graphviz's frame); :func:`rsstp_replay.viewer.render_graph`
pins every state there, so a state has one place in the pictures of every step. (The viewer
draws the model on the world instead: :mod:`._viewer_model`.)
"""

from __future__ import annotations

import math
import shutil
import subprocess
import warnings
from collections.abc import Iterable, Sequence
from itertools import chain

import numpy as np

from rsstp_replay.errors import ViewerWarning
from rsstp_sim.graph import plain_positions, run_graphviz
from rsstp_sim.recording.records import ModelRecord
from rsstp_sim.transition_system import TransitionSystem, snapshot_form

__all__ = [
    "DOT_MAX_PAIRS",
    "DOT_TIMEOUT_S",
    "graph_positions",
    "union_model",
]


def union_model(
    versions: Sequence[ModelRecord], extra_states: Iterable[int] = ()
) -> TransitionSystem:
    """A transition system holding every state and transition of every version (and
    ``extra_states``): the one graph whose layout fixes every node's place."""
    states: set[int] = set(extra_states)
    actions: set[int] = set()
    for record in versions:
        states.update(record.states)
        actions.update(record.actions)
    columns = [
        np.fromiter(chain.from_iterable(getattr(r.transitions, name) for r in versions), np.int64)
        for name in ("source", "action", "target")
    ]
    # Every version's transitions at once, as one int64 key each: the distinct ones, sorted.
    base = int(max((c.max(initial=0) for c in columns), default=0)) + 1
    keys = np.unique((columns[0] * base + columns[1]) * base + columns[2])
    transitions = np.stack([keys // (base * base), keys // base % base, keys % base], axis=1)
    if not states:
        states.add(0)
    ordered = sorted(states)
    every_action = sorted(actions | set(transitions[:, 1].tolist()))
    return TransitionSystem.from_snapshot(
        snapshot_form(ordered, ordered[-1] + 1, ordered[0], every_action, transitions.tolist())
    )


def graph_positions(
    versions: Sequence[ModelRecord], extra_states: Iterable[int] = ()
) -> dict[int, tuple[float, float]]:
    """Every state's place (points, y up), from one layout of :func:`union_model`.

    The layout is Graphviz's: ``dot`` with :func:`rsstp_sim.graph.to_dot`'s graph attributes
    (left to right, the same node and rank separations) over one edge per state pair of the
    union, *without* the action labels (``dot`` places labels as nodes: on the union of a
    learning run, 90 states and 718 state pairs, 3.2 s with them, 0.2 s without). ``dot``'s
    crossing minimisation can take minutes on dense graphs, so past :data:`DOT_MAX_PAIRS` pairs,
    or when ``dot`` runs longer than :data:`DOT_TIMEOUT_S`, the force-directed ``sfdp`` lays it
    out instead (deterministic too). Without Graphviz the states go on a circle, with a
    :class:`ViewerWarning`.
    """
    union = union_model(versions, extra_states)
    pairs = sorted({(s, t) for s, _, t in union.transitions() if s != t})
    if shutil.which("dot") is None:
        warnings.warn(
            ViewerWarning("Graphviz 'dot' not found: the model's states are drawn on a circle"),
            stacklevel=2,
        )
        return _circle(union.states)
    source = _layout_source(union.states, pairs)
    if len(pairs) <= DOT_MAX_PAIRS:
        try:
            return _run_layout("dot", source, timeout=DOT_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            pass
    return _run_layout("sfdp", source, timeout=None)


DOT_MAX_PAIRS = 400
"""Above this many state pairs the union is laid out by ``sfdp`` rather than ``dot``."""
DOT_TIMEOUT_S = 10.0
"""How long ``dot`` may take before ``sfdp`` takes over."""


def _layout_source(states: Sequence[int], pairs: Sequence[tuple[int, int]]) -> str:
    lines = [
        "digraph union {",
        '  graph [rankdir="LR", nodesep="0.6", ranksep="0.9", overlap="false", sep="+12"];',
        '  node [shape="circle", width="0.5", fixedsize="true"];',
        *(f"  {s};" for s in states),
        *(f"  {s} -> {t};" for s, t in pairs),
        "}",
    ]
    return "\n".join(lines) + "\n"


def _run_layout(
    engine: str, source: str, *, timeout: float | None
) -> dict[int, tuple[float, float]]:
    """Node centres in points from Graphviz's ``plain`` output."""
    plain = run_graphviz(
        engine, source, ["-Tplain"], what="the layout of every model version", timeout=timeout
    )
    return plain_positions(plain.decode())


def _circle(states: Sequence[int]) -> dict[int, tuple[float, float]]:
    radius = max(60.0, 20.0 * len(states))
    return {
        s: (
            round(radius * math.cos(2 * math.pi * i / len(states)), 2),
            round(radius * math.sin(2 * math.pi * i / len(states)), 2),
        )
        for i, s in enumerate(states)
    }
