"""The thesis-style picture's layout: one Graphviz layout of every version at once.

Positions are in points, y up (Graphviz's frame); :func:`rsstp_replay.viewer.render_graph`
pins every state there, so a state has one place in the pictures of every step. (The viewer
draws the model on the world instead: :mod:`._viewer_model`.)

Graphviz lays the union out in this process (:func:`rsstp_sim.graph.run_graphviz`, from
``pygraphviz``'s wheel) and holds the interpreter until it is done: no timeout can stop it, so
the layout is bounded by its input and by Graphviz's own work limits, never by a clock. (A clock
would also make the picture depend on how busy the machine is: the same recording laid out by
``dot`` on one machine and by ``sfdp`` on another.) Measured (``bench/graphviz_layout.py``,
warm, 2 shared cores): ``dot`` with Graphviz's default limits took 2.0 s on a learner's union of
400 state pairs and 25 s on 400 random pairs over 150 states (21 s over 70), so the pair count
alone (:data:`DOT_MAX_PAIRS`) does not bound it; within :data:`DOT_LIMITS` the same graphs take
0.3 s, 1.1 s and 1.9 s. ``sfdp`` with :data:`SFDP_SETTINGS` takes 0.06 s on the 119 states and
763 pairs of a learner's union, 3.1 s on the 1,183 states and 8,699 pairs of another.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from itertools import chain

import numpy as np

from rsstp_format.records import ModelRecord
from rsstp_sim.arrays import distinct
from rsstp_sim.graph import plain_positions, run_graphviz
from rsstp_sim.transition_system import TransitionSystem, snapshot_form

__all__ = [
    "DOT_LIMITS",
    "DOT_MAX_PAIRS",
    "SFDP_SETTINGS",
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
    keys = distinct((columns[0] * base + columns[1]) * base + columns[2])
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
    learning run, 90 states and 718 state pairs, 3.2 s with them, 0.2 s without) and without
    routing the edges (only the nodes' places are kept), within :data:`DOT_LIMITS`. Past
    :data:`DOT_MAX_PAIRS` pairs the force-directed ``sfdp`` lays it out instead, its overlaps
    removed as :data:`SFDP_SETTINGS` says (``pygraphviz``'s Graphviz has no triangulation
    library for ``prism``, and its ``voronoi`` took 58 s on 1,183 states). Both are
    deterministic: the same versions give the same places, whatever ran before in the process.
    A Graphviz failure is :class:`~rsstp_sim.errors.GraphvizFailed`.
    """
    union = union_model(versions, extra_states)
    pairs = sorted({(s, t) for s, _, t in union.transitions() if s != t})
    if len(pairs) <= DOT_MAX_PAIRS:
        engine, settings = "dot", DOT_LIMITS
    else:
        engine, settings = "sfdp", SFDP_SETTINGS
    plain = run_graphviz(
        engine,
        _layout_source(union.states, pairs, settings),
        "plain",
        what="the layout of every model version",
    )
    return plain_positions(plain.decode())


DOT_MAX_PAIRS = 400
"""Above this many state pairs the union is laid out by ``sfdp`` rather than ``dot``."""
DOT_LIMITS = 'splines="none", nslimit="2", nslimit1="2", mclimit="0.5"'
"""Graphviz's own bounds on ``dot``'s work, deterministic unlike a timeout: its network simplex
passes (ranks and places) at most twice the nodes' count of iterations, its crossing
minimisation half its default passes, and no edges routed (only the nodes' places are kept)."""
SFDP_SETTINGS = 'overlap="portho"'
"""``sfdp``'s overlap removal: pseudo-orthogonal constraints, which need no triangulation
library and are deterministic (``vpsc``, the most compact, is not: the same union came out in
two ways in fresh processes)."""


def _layout_source(states: Sequence[int], pairs: Sequence[tuple[int, int]], settings: str) -> str:
    lines = [
        "digraph union {",
        f'  graph [rankdir="LR", nodesep="0.6", ranksep="0.9", sep="+12", {settings}];',
        '  node [shape="circle", width="0.5", fixedsize="true"];',
        *(f"  {s};" for s in states),
        *(f"  {s} -> {t};" for s, t in pairs),
        "}",
    ]
    return "\n".join(lines) + "\n"
