"""The internal model for the viewer: the transition graph at every model version, with node
positions that never move, and the current internal state at every step.

Positions come from one layout of the union of every version (:mod:`._viewer_layout`).

Action labels: a Rerun graph edge carries no label, so each ``(s, t)`` state pair with at least
one transition gets a small *label node* ``"s>t"`` whose text is the sorted actions (``"0,1"``,
as a cell of the thesis's matrix), and the edge is drawn in two halves, ``s -> "s>t" -> t``.
The label node sits beside the midpoint of the straight segment ``s t``, on the right of the
direction ``s -> t`` (so ``s -> t`` and ``t -> s`` get their own nodes on either side); for a
self-loop ``s -> s`` it sits above ``s`` and the two halves form a loop.

Every version is logged whole (Rerun shows the latest row at or before the time cursor), so
the data grows with the sum of the versions' sizes: a run of the splitter strategy with 1,695
versions of up to 6,659 transitions makes 4.9 million nodes and 9.4 million edges. The columns
are therefore built with numpy over all versions at once (:func:`graph_columns`);
:func:`graph_frame` is the plain per-version definition they must agree with.
"""

from __future__ import annotations

import itertools
import math
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import rerun as rr

from rsstp_replay._viewer_chunks import TIMELINE, send_rows
from rsstp_replay._viewer_layout import ViewerWarning
from rsstp_sim.recording.records import ModelRecord

__all__ = [
    "GRAPH",
    "STATE",
    "GraphColumns",
    "GraphFrame",
    "graph_columns",
    "graph_frame",
    "label_node",
    "log_current_state",
    "log_model",
]

GRAPH = "model/graph"
STATE = "model/state"

_STATE_COLOR = (40, 110, 200)
_LABEL_COLOR = (120, 120, 120)
_CURRENT_COLOR = (235, 100, 0)
_LOOP_RISE = 42.0
"""How far above its state a self-loop's label node sits (points)."""
_INSTANCES_PER_CHUNK = 200_000
"""About how many nodes (or edges) one chunk of ``model/graph`` holds."""

_Ints = npt.NDArray[np.int64]
_Strings = npt.NDArray[np.str_]
_Floats = npt.NDArray[np.float64]
Positions = dict[int, tuple[float, float]]


def label_node(s: int, t: int) -> str:
    """The id of the label node of the state pair ``(s, t)``."""
    return f"{s}>{t}"


def _label_position(
    source: tuple[float, float], target: tuple[float, float]
) -> tuple[float, float]:
    """Where the label node of ``source -> target`` goes, in the viewer's frame (y down)."""
    (x0, y0), (x1, y1) = source, target
    dx, dy = x1 - x0, y1 - y0
    length = math.hypot(dx, dy)
    if length == 0.0:
        return x0, y0 - _LOOP_RISE
    offset = min(30.0, max(12.0, 0.15 * length))
    # The right-hand side of the direction, y pointing down: (-dy, dx) / length.
    return (x0 + x1) / 2 - dy / length * offset, (y0 + y1) / 2 + dx / length * offset


@dataclass(frozen=True, slots=True)
class GraphFrame:
    """One model version as the viewer draws it: nodes (states, then label nodes in the order
    of their pairs) and edges (two per label node)."""

    node_ids: list[str]
    positions: list[tuple[float, float]]
    labels: list[str]
    edges: list[tuple[str, str]]


def graph_frame(
    states: Sequence[int], transitions: Iterable[Sequence[int]], positions: Positions
) -> GraphFrame:
    """The nodes and edges of one version; ``positions`` are the viewer's (y down)."""
    cells: dict[tuple[int, int], list[int]] = {}
    for s, a, t in sorted(transitions, key=lambda sat: (sat[0], sat[2], sat[1])):
        cells.setdefault((s, t), []).append(a)
    frame = GraphFrame(
        node_ids=[str(s) for s in states],
        positions=[positions[s] for s in states],
        labels=[str(s) for s in states],
        edges=[],
    )
    for (s, t), actions in cells.items():
        middle = label_node(s, t)
        frame.node_ids.append(middle)
        frame.positions.append(_label_position(positions[s], positions[t]))
        frame.labels.append(",".join(map(str, actions)))
        frame.edges.extend([(str(s), middle), (middle, str(t))])
    return frame


@dataclass(frozen=True, slots=True)
class GraphColumns:
    """Every version's :class:`GraphFrame`, concatenated: version ``v`` owns
    ``node_counts[v]`` consecutive nodes and ``edge_counts[v]`` consecutive edges."""

    node_ids: _Strings
    positions: _Floats
    labels: _Strings
    is_state: npt.NDArray[np.bool_]
    node_counts: _Ints
    edges: _Strings
    edge_counts: _Ints


def graph_columns(versions: Sequence[ModelRecord], positions: Positions) -> GraphColumns:
    """The frames of all ``versions`` at once, with numpy (see the module docstring)."""
    n = len(versions)
    state_counts = np.array([len(record.states) for record in versions], np.int64)
    state_ids = np.fromiter(
        itertools.chain.from_iterable(record.states for record in versions),
        np.int64,
        count=int(state_counts.sum()),
    )
    state_version = np.repeat(np.arange(n), state_counts)
    triples = np.fromiter(
        itertools.chain.from_iterable(
            itertools.chain.from_iterable(record.transitions) for record in versions
        ),
        np.int64,
        count=3 * sum(len(record.transitions) for record in versions),
    ).reshape(-1, 3)
    triple_version = np.repeat(np.arange(n), [len(record.transitions) for record in versions])
    s, a, t = triples[:, 0], triples[:, 1], triples[:, 2]
    if len(a) and (int(a.min()) < 0 or int(a.max()) >= 62):
        raise ValueError(f"actions {int(a.min())}..{int(a.max())}: the viewer handles 0 to 61")
    # One cell per (version, s, t), its actions as a bit mask; sorted on one integer key.
    base = int(max(state_ids.max(initial=0), triples.max(initial=0))) + 1
    if n * base * base >= 2**62:
        raise ValueError(f"{n} versions of states up to {base - 1}: too many for the viewer")
    pair_key = s * base + t
    order = np.argsort(triple_version * (base * base) + pair_key, kind="stable")
    key, a, triple_version = pair_key[order], a[order], triple_version[order]
    starts = np.flatnonzero(np.r_[True, (np.diff(triple_version) != 0) | (np.diff(key) != 0)])
    masks = np.bitwise_or.reduceat(np.left_shift(np.int64(1), a), starts) if len(a) else a
    cell_key, cell_version = key[starts], triple_version[starts]
    pairs, pair_of_cell = np.unique(cell_key, return_inverse=True)
    cell_s, cell_t = cell_key // base, cell_key % base
    pair_ids = np.array(
        [label_node(int(p), int(q)) for p, q in zip(pairs // base, pairs % base, strict=True)],
        dtype=np.str_,
    )
    pair_places = np.array(
        [
            _label_position(positions[int(p)], positions[int(q)])
            for p, q in zip(pairs // base, pairs % base, strict=True)
        ],
        np.float64,
    ).reshape(-1, 2)
    mask_values, mask_of_cell = np.unique(masks, return_inverse=True)
    mask_labels = np.array([_mask_label(int(m)) for m in mask_values], dtype=np.str_)

    states, state_of_node = np.unique(state_ids, return_inverse=True)
    state_names = _names(states)
    state_places = np.array([positions[int(q)] for q in states], np.float64).reshape(-1, 2)
    # Gather strings once, by integer codes into small vocabularies (states, then pairs or
    # action sets): numpy string arrays are slow to concatenate and reorder.
    kinds = np.r_[np.zeros(len(state_ids), np.int64), np.ones(len(cell_key), np.int64)]
    node_order = np.lexsort((kinds, np.r_[state_version, cell_version]))
    id_codes = np.r_[state_of_node, len(states) + pair_of_cell][node_order]
    label_codes = np.r_[state_of_node, len(states) + mask_of_cell][node_order]
    ids = np.concatenate([state_names, pair_ids])
    edge_codes = np.empty((2 * len(cell_key), 2), np.int64)
    edge_codes[0::2, 0] = np.searchsorted(states, cell_s)
    edge_codes[0::2, 1] = len(states) + pair_of_cell
    edge_codes[1::2, 0] = len(states) + pair_of_cell
    edge_codes[1::2, 1] = np.searchsorted(states, cell_t)
    cells_per_version = np.bincount(cell_version, minlength=n).astype(np.int64)
    return GraphColumns(
        node_ids=ids[id_codes],
        positions=np.concatenate([state_places, pair_places])[id_codes],
        labels=np.concatenate([state_names, mask_labels])[label_codes],
        is_state=kinds[node_order] == 0,
        node_counts=state_counts + cells_per_version,
        edges=ids[edge_codes],
        edge_counts=2 * cells_per_version,
    )


def _names(values: _Ints) -> _Strings:
    """The decimal names of ``values``, in a string array no wider than needed."""
    return np.array([str(value) for value in values.tolist()], dtype=np.str_)


def _mask_label(mask: int) -> str:
    return ",".join(str(a) for a in range(mask.bit_length()) if mask >> a & 1)


def log_model(
    stream: rr.RecordingStream,
    versions: Sequence[ModelRecord],
    steps: Sequence[int],
    positions: Positions,
) -> int:
    """The graph of each version in ``versions`` at the matching step of ``steps`` (one row
    each); ``positions`` are the viewer's. Returns the rows logged."""
    columns = graph_columns(versions, positions)
    times = np.asarray(steps, np.int64)
    colors = np.where(columns.is_state[:, None], _STATE_COLOR, _LABEL_COLOR).astype(np.uint8)
    stream.log(GRAPH, rr.GraphEdges.from_fields(graph_type="directed"), static=True)
    node_ends = np.cumsum(columns.node_counts)
    edge_ends = np.cumsum(columns.edge_counts)
    shown_edges = False  # an empty group of edges must still hide the edges before it
    for first, last in _row_groups(np.maximum(columns.node_counts, columns.edge_counts)):
        index = [rr.TimeColumn(TIMELINE, sequence=times[first:last])]
        nodes = slice(int(node_ends[first] - columns.node_counts[first]), int(node_ends[last - 1]))
        stream.send_columns(
            GRAPH,
            indexes=index,
            columns=rr.GraphNodes.columns(
                node_ids=columns.node_ids[nodes],
                positions=columns.positions[nodes],
                labels=columns.labels[nodes],
                colors=colors[nodes],
            ).partition(columns.node_counts[first:last]),
        )
        edges = slice(int(edge_ends[first] - columns.edge_counts[first]), int(edge_ends[last - 1]))
        if edges.stop > edges.start or shown_edges:
            shown_edges = True
            stream.send_columns(
                GRAPH,
                indexes=index,
                columns=rr.GraphEdges.columns(edges=columns.edges[edges]).partition(
                    columns.edge_counts[first:last]
                ),
            )
    return len(versions)


def _row_groups(sizes: _Ints) -> list[tuple[int, int]]:
    """Consecutive rows ``[first, last)`` holding about :data:`_INSTANCES_PER_CHUNK`
    instances each (at least one row)."""
    groups: list[tuple[int, int]] = []
    first, total = 0, 0
    for row, size in enumerate(sizes.tolist()):
        if row > first and total + size > _INSTANCES_PER_CHUNK:
            groups.append((first, row))
            first, total = row, 0
        total += size
    if len(sizes):
        groups.append((first, len(sizes)))
    return groups


def log_current_state(
    stream: rr.RecordingStream,
    times: _Ints,
    internal_states: _Ints,
    positions: Positions,
) -> int:
    """The current internal state at every step: one node drawn over the state's node (same
    id, same place, in orange). Returns the rows logged."""
    states, inverse = np.unique(internal_states, return_inverse=True)
    missing = [int(s) for s in states if int(s) not in positions]
    if missing:
        warnings.warn(
            ViewerWarning(
                f"internal states {missing[:10]} belong to no model version: drawn at the origin"
            ),
            stacklevel=2,
        )
    places = np.array([positions.get(int(s), (0.0, 0.0)) for s in states], np.float64)
    names = states.astype(np.str_)
    color = np.array(_CURRENT_COLOR, np.uint8)
    return send_rows(
        stream,
        STATE,
        times,
        lambda rows: rr.GraphNodes.columns(
            node_ids=names[inverse[rows]],
            positions=places[inverse[rows]],
            labels=names[inverse[rows]],
            colors=np.tile(color, (len(inverse[rows]), 1)),
        ),
    )
