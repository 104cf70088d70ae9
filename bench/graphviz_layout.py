"""Benchmark: Graphviz in process (``pygraphviz``'s wheel) against the Graphviz programs.

    PYTHONPATH=src python bench/graphviz_layout.py
    PYTHONPATH=src python bench/graphviz_layout.py --cap 60 --repeats 3 --model 119

Two learned models, each the last model of a learner's run (recorded once under the temporary
folder if missing):

- ``119``: ``rsstp-sim record two-joint-30 --strategy learner --steps 12000 --seed 0`` (119
  states; the union of its versions has 763 state pairs);
- ``1183``: the learner, seed 0, on :data:`TWO_LINKS_10` (two links at 10-degree steps, one
  obstacle: 1,183 true classes), until it is done (about 250,000 steps).

Three drawings of each, the ones the command lines make:

- ``union``: the places of every state, one layout of the union of all versions without labels
  (``rsstp-replay graph``, :func:`rsstp_replay.viewer.graph_positions`): past 400 state pairs
  ``sfdp`` (both models), in process with today's settings, the program with the settings it
  had (``overlap=false``: prism, where Debian's Graphviz has it);
- ``pinned``: the model drawn as SVG at those places (``nop2``, the program ``neato -n2``);
- ``labelled``: the model laid out by ``dot`` with its action labels (``rsstp-sim graph``,
  :func:`rsstp_sim.graph.layout`).

And ``dot400``: unions of 400 state pairs (:data:`~rsstp_replay.viewer._layout.DOT_MAX_PAIRS`,
the most ``dot`` lays out) laid out by ``dot`` within
:data:`~rsstp_replay.viewer._layout.DOT_LIMITS` (``limits``, both sides) and without them
(``none``: the program as it ran before issue 30, with a 10 s timeout): the union of the first
versions of the ``119`` run, and random pairs over 150 states (seed 0).

Each is timed cold and warm. In process, cold is a fresh Python that imports
:mod:`rsstp_sim.graph` and draws once (Python's start and the imports included), warm the
fastest of ``--repeats`` drawings after a first small one in the same process (one if a drawing
takes over 10 s). The programs (``dot``, ``sfdp``, ``neato`` on ``PATH``; left out with a note
when absent) start afresh every time: cold is the first run, warm the fastest of the next
``--repeats``. Wall seconds, with CPU seconds beside them (the figure on a loaded machine; the
load average is printed). A drawing still running after ``--cap`` seconds is stopped and shown
as ``> cap``; its warm run is then left out.
"""

from __future__ import annotations

import argparse
import os
import random
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from _recordings import recorded
from rsstp_replay import open_recording
from rsstp_replay.viewer._layout import (
    DOT_LIMITS,
    DOT_MAX_PAIRS,
    SFDP_SETTINGS,
    _layout_source,
    graph_positions,
    union_model,
)
from rsstp_sim.graph import to_dot

TWO_LINKS_10 = """name = "two-links-10"
[arm]
lengths = [2.0, 1.0]
initial_deg = [0, 0]
step_deg = 10
[[obstacles]]
center = [0.0, 2.5]
radius = 0.5
[feedback]
target_deg = [0, 0]
"""
"""Two links (2, 1) at 10-degree steps, one obstacle at (0, 2.5): 1,183 true classes."""

_OLD_UNION_SETTINGS = 'overlap="false"'
"""The union's graph settings while ``sfdp`` ran as a program (before issue 30)."""

_IN_PROCESS = """
import sys, time
from rsstp_sim.graph import run_graphviz

engine, output, path, mode, repeats = sys.argv[1:6]
source = open(path, encoding="utf-8").read()
if mode == "cold":
    run_graphviz(engine, source, output, what="the benchmark")
    print(time.process_time(), 0.0)
else:
    run_graphviz("dot", "digraph { a -> b [label=x] }", "svg", what="a warm-up")
    best = None
    for _ in range(int(repeats)):
        began, cpu = time.perf_counter(), time.process_time()
        run_graphviz(engine, source, output, what="the benchmark")
        seconds = time.perf_counter() - began
        if best is None or seconds < best[1]:
            best = (time.process_time() - cpu, seconds)
        if seconds > 10:
            break
    print(*best)
"""


@dataclass(frozen=True)
class Drawing:
    """One Graphviz job: a DOT file, and how each side draws it."""

    name: str
    source: Path
    engine: str
    output: str
    program: list[str]
    program_source: Path


@dataclass(frozen=True)
class Timing:
    wall: float | None  # None: stopped at the cap
    cpu: float

    def text(self, cap: float) -> str:
        if self.wall is None:
            return f"> {cap:.0f} s"
        return f"{self.wall:6.2f} s ({self.cpu:5.2f})"


def model_recording(name: str) -> Path:
    """The recording whose last model is the ``name`` model (recorded once)."""
    if name == "119":
        return recorded(
            "two-joint-30-learner-12000",
            "two-joint-30", "--strategy", "learner", "--steps", "12000", "--seed", "0",
        )  # fmt: skip
    scenario = Path(tempfile.gettempdir()) / "rsstp-bench-two-links-10.toml"
    scenario.write_text(TWO_LINKS_10, encoding="utf-8")
    return recorded(
        "two-links-10-learner",
        str(scenario), "--strategy", "learner", "--steps", "6000000", "--seed", "0",
    )  # fmt: skip


def drawings(name: str, folder: Path) -> tuple[str, list[Drawing]]:
    """What the model ``name`` is, and its three drawings (their DOT files under ``folder``)."""
    with open_recording(model_recording(name)) as recording:
        versions = recording.model_versions()
        model = recording.model_at(recording.n_steps)
    union = union_model(versions)
    pairs = sorted({(s, t) for s, _, t in union.transitions() if s != t})
    if len(pairs) <= DOT_MAX_PAIRS:
        raise SystemExit(f"the {name} model's union has {len(pairs)} pairs: dot, not sfdp")
    places = graph_positions(versions)
    files = {
        "union": _layout_source(union.states, pairs, SFDP_SETTINGS),
        "union-old": _layout_source(union.states, pairs, _OLD_UNION_SETTINGS),
        "pinned": to_dot(model, positions={s: places[s] for s in model.states}),
        "labelled": to_dot(model),
    }
    for key, text in files.items():
        (folder / f"{name}-{key}.gv").write_text(text, encoding="utf-8")

    def path(key: str) -> Path:
        return folder / f"{name}-{key}.gv"

    what = (
        f"{name} ({len(model):,} states, {len(model.transitions()):,} transitions; "
        f"union {len(union):,} states, {len(pairs):,} pairs)"
    )
    return f"model {what}", [
        Drawing("union", path("union"), "sfdp", "plain", ["sfdp", "-Tplain"], path("union-old")),
        Drawing("pinned", path("pinned"), "nop2", "svg", ["neato", "-n2", "-Tsvg"], path("pinned")),
        Drawing("labelled", path("labelled"), "dot", "plain", ["dot", "-Tplain"], path("labelled")),
    ]


def dot_drawings(folder: Path) -> list[tuple[str, list[Drawing]]]:
    """The ``dot400`` cases: each union of 400 state pairs, within the limits and without."""
    with open_recording(model_recording("119")) as recording:
        versions = recording.model_versions()

    def pairs_of(count: int) -> tuple[list[int], list[tuple[int, int]]]:
        union = union_model(versions[:count])
        return list(union.states), sorted({(s, t) for s, _, t in union.transitions() if s != t})

    low, high = 1, len(versions)  # the fewest versions whose union has DOT_MAX_PAIRS pairs
    while low < high:
        middle = (low + high) // 2
        if len(pairs_of(middle)[1]) < DOT_MAX_PAIRS:
            low = middle + 1
        else:
            high = middle
    every = [(s, t) for s in range(150) for t in range(150) if s != t]
    graphs = {
        "learner": pairs_of(low),
        "random": (list(range(150)), sorted(random.Random(0).sample(every, DOT_MAX_PAIRS))),
    }
    cases = []
    for name, (states, pairs) in graphs.items():
        limited = folder / f"dot400-{name}-limits.gv"
        limited.write_text(_layout_source(states, pairs, DOT_LIMITS), encoding="utf-8")
        unlimited = folder / f"dot400-{name}-none.gv"
        unlimited.write_text(_layout_source(states, pairs, _OLD_UNION_SETTINGS), encoding="utf-8")
        jobs = [
            Drawing("limits", limited, "dot", "plain", ["dot", "-Tplain"], limited),
            Drawing("none", unlimited, "dot", "plain", ["dot", "-Tplain"], unlimited),
        ]
        cases.append((f"dot400 {name} (union {len(states)} states, {len(pairs)} pairs)", jobs))
    return cases


def in_process(drawing: Drawing, mode: str, repeats: int, cap: float) -> Timing:
    """A fresh Python drawing it: cold (timed from outside, start and imports included) or
    warm (timed inside, after a first small drawing)."""
    command = [
        sys.executable, "-c", _IN_PROCESS,
        drawing.engine, drawing.output, str(drawing.source), mode, str(repeats),
    ]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    began = time.perf_counter()
    try:
        done = subprocess.run(
            command, capture_output=True, text=True, timeout=cap * (1 if mode == "cold" else 2),
            env=env, check=True,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        return Timing(None, 0.0)
    seconds = time.perf_counter() - began
    cpu, inside = (float(x) for x in done.stdout.split())
    return Timing(seconds if mode == "cold" else inside, cpu)


def by_program(drawing: Drawing, runs: int, cap: float) -> Timing:
    """The fastest of ``runs`` runs of the Graphviz program (each a fresh process)."""
    best: Timing | None = None
    for _ in range(runs):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        began = time.perf_counter()
        try:
            subprocess.run(
                [*drawing.program, str(drawing.program_source)],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=cap, check=True,
            )  # fmt: skip
        except subprocess.TimeoutExpired:
            return Timing(None, 0.0)
        seconds = time.perf_counter() - began
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        if best is None or best.wall is None or seconds < best.wall:
            best = Timing(seconds, cpu)
        if seconds > 10:
            break
    assert best is not None
    return best


def main(argv: Sequence[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", choices=["119", "1183", "dot400"], action="append")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--cap", type=float, default=120.0, help="seconds a drawing may take")
    args = parser.parse_args(argv)
    programs = {name: shutil.which(name) for name in ("dot", "sfdp", "neato")}
    missing = sorted(name for name, found in programs.items() if found is None)
    import pygraphviz

    print(
        f"pygraphviz {pygraphviz.__version__} (Graphviz {pygraphviz.__graphviz_version__}); "
        f"programs: {', '.join(f'{n} {p}' for n, p in programs.items() if p) or 'none'}; "
        f"load average {os.getloadavg()[0]:.1f}"
    )
    if missing:
        print(f"no {', '.join(missing)} on PATH: the program's columns say 'not found'")
    head = (
        f"{'drawing':9s} {'engine':6s} | {'in process cold':>17s} {'warm':>17s} | "
        f"{'program cold':>17s} {'warm':>17s}"
    )
    with tempfile.TemporaryDirectory() as scratch:
        cases = []
        for name in args.model or ["119", "1183", "dot400"]:
            if name == "dot400":
                cases += dot_drawings(Path(scratch))
            else:
                cases.append(drawings(name, Path(scratch)))
        for what, jobs in cases:
            print(f"\n{what}; wall seconds (CPU seconds)")
            print(head)
            print("-" * len(head))
            for job in jobs:
                cells = []
                cold = in_process(job, "cold", args.repeats, args.cap)
                warm = (
                    in_process(job, "warm", args.repeats, args.cap)
                    if cold.wall is not None
                    else None
                )
                cells += [cold.text(args.cap), warm.text(args.cap) if warm else "not run"]
                if programs[job.program[0]] is None:
                    cells += ["not found", ""]
                else:
                    first = by_program(job, 1, args.cap)
                    again = by_program(job, args.repeats, args.cap) if first.wall else None
                    cells += [first.text(args.cap), again.text(args.cap) if again else "not run"]
                print(
                    f"{job.name:9s} {job.engine:6s} | {cells[0]:>17s} {cells[1]:>17s} | "
                    f"{cells[2]:>17s} {cells[3]:>17s}",
                    flush=True,
                )
    print(f"\nload average {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main(sys.argv[1:])
