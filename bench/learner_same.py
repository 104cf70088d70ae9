"""The learner step for step as before: save its runs, then check a changed learner against them.

    PYTHONPATH=src python bench/learner_same.py --save DIR     # the runs of this source, to DIR
    PYTHONPATH=src python bench/learner_same.py --check DIR    # the same runs again, compared
    PYTHONPATH=src python bench/learner_same.py --check DIR --only two-joint-30

For a change meant to make the ``learner`` faster and nothing else: save with the source before
the change (``git archive main src | tar -x -C OLD``, then ``PYTHONPATH=OLD/src``), check with
the source after. Each case is one run of the ``learner`` (boolean or float feedback; arm and
rover worlds, built in and generated: bench/worlds.py's first worlds of 4,500..5,500 and
14,000..16,000 classes) for its budget of steps (200,000 or more, or until the learner is done)
through the :class:`~rsstp_sim.runner.Runner`. Saved per case: every step's action, internal
state, sensation and feedback (``CASE.npz``), and a SHA-256 of those, of every event (notes,
phases, the stop) and of every model operation with its step, and of the run's generator state
at the end (``digests.json``). The check runs each case again and compares: the first step
whose action, state, sensation or feedback differs, else which digest differs. Exits 1 on any
difference.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rsstp_sim.runner import Event, Runner  # noqa: E402
from rsstp_sim.scenario import AnyScenario, load_scenario, parse_scenario  # noqa: E402
from rsstp_sim.strategies import make_strategy  # noqa: E402
from rsstp_sim.transition_system import Operation  # noqa: E402
from worlds import generate  # noqa: E402

BUILTIN = Path(__file__).resolve().parents[1] / "src" / "rsstp_sim" / "scenarios"


@dataclass(frozen=True)
class Case:
    name: str
    world: str  # a built-in scenario's name, or "generated-LOW-HIGH"
    float_feedback: bool
    steps: int
    seed: int = 0


CASES = (
    Case("two-joint-30", "two-joint-30", False, 200_000),
    Case("two-joint-30-seed-3", "two-joint-30", False, 200_000, seed=3),
    Case("two-joint-30-float", "two-joint-30", True, 200_000),
    Case("three-joint", "three-joint", False, 200_000),
    Case("three-joint-float", "three-joint", True, 200_000),
    Case("rover-room", "rover-room", False, 200_000),
    Case("rover-room-float", "rover-room", True, 200_000),
    Case("rover-two-rooms", "rover-two-rooms", False, 200_000),
    Case("rover-one-way-float", "rover-one-way", True, 200_000),
    Case("generated-4797", "generated-4500-5500", False, 300_000),
    Case("generated-4797-float", "generated-4500-5500", True, 2_000_000),
    Case("generated-15117", "generated-14000-16000", False, 200_000),
    Case("generated-15117-float", "generated-14000-16000", True, 300_000),
)


@cache
def _source(world: str) -> str:
    if world.startswith("generated-"):
        low, high = (int(v) for v in world.split("-")[1:])
        return generate(1, 0, min_n=low, max_n=high).source
    return (BUILTIN / f"{world}.toml").read_text(encoding="utf-8")


def scenario_of(case: Case) -> AnyScenario:
    if not case.float_feedback and not case.world.startswith("generated-"):
        return load_scenario(case.world)
    text = _source(case.world)
    if case.float_feedback:
        text = text.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    return parse_scenario(text, origin=case.name)


def run(case: Case) -> tuple[dict[str, np.ndarray], dict[str, str], int, float]:
    """The case's run: its per-step arrays, its digests, its steps and its seconds."""
    events = hashlib.sha256()
    operations = hashlib.sha256()

    def on_event(event: Event) -> None:
        events.update(repr((event.step, event.kind, event.text, event.data)).encode())

    def on_model_change(step: int, ops: Sequence[Operation]) -> None:
        operations.update(repr((step, list(ops))).encode())

    strategy = make_strategy("learner")
    runner = Runner(
        scenario_of(case),
        strategy,
        seed=case.seed,
        on_event=on_event,
        on_model_change=on_model_change,
    )
    started = time.perf_counter()
    runner.run(case.steps)
    seconds = time.perf_counter() - started
    memory = runner.memory
    arrays = {
        "actions": np.asarray(memory.actions),
        "states": np.asarray(memory.internal_states),
        "sensations": np.asarray(memory.sensations),
        "feedback": np.asarray(memory.feedback),
    }
    steps = hashlib.sha256()
    for key in sorted(arrays):
        steps.update(np.ascontiguousarray(arrays[key]).tobytes())
    generator = json.dumps(runner.rng.bit_generator.state, sort_keys=True, default=str)
    digests = {
        "steps": steps.hexdigest(),
        "events": events.hexdigest(),
        "operations": operations.hexdigest(),
        "generator": hashlib.sha256(generator.encode()).hexdigest(),
        "stopped": repr(runner.stopped),
    }
    return arrays, digests, runner.step_index, seconds


def first_difference(saved: dict[str, np.ndarray], now: dict[str, np.ndarray]) -> str | None:
    """Where two runs' per-step arrays first differ (entry 0 is the start), or None."""
    for key in sorted(saved):
        a, b = saved[key], now[key]
        common = min(len(a), len(b))
        same = a[:common] == b[:common]
        if a.dtype.kind == "f":  # (NaN where there is no feedback)
            same |= np.isnan(a[:common]) & np.isnan(b[:common])
        wrong = np.flatnonzero(~same)
        if len(wrong):
            return f"{key} first differ at step {int(wrong[0]):,}"
        if len(a) != len(b):
            return f"{key}: {len(a):,} entries saved, {len(b):,} now"
    return None


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    group = parser.add_mutually_exclusive_group(required=True)
    group.add_argument("--save", type=Path, metavar="DIR")
    group.add_argument("--check", type=Path, metavar="DIR")
    parser.add_argument("--only", nargs="*", default=None, help="case names (default: all)")
    args = parser.parse_args()
    folder: Path = args.save or args.check
    folder.mkdir(parents=True, exist_ok=True)
    index = folder / "digests.json"
    saved = json.loads(index.read_text()) if index.exists() else {}
    failed = 0
    for case in CASES:
        if args.only is not None and case.name not in args.only:
            continue
        arrays, digests, steps, seconds = run(case)
        line = f"{case.name:24s} {steps:>10,} steps {seconds:7.1f} s"
        if args.save:
            np.savez_compressed(folder / f"{case.name}.npz", **arrays)
            saved[case.name] = digests
            index.write_text(json.dumps(saved, indent=1, sort_keys=True))
            print(f"{line}  saved", flush=True)
            continue
        if case.name not in saved:
            print(f"{line}  not saved in {folder}", flush=True)
            failed += 1
            continue
        with np.load(folder / f"{case.name}.npz") as data:
            where = first_difference(dict(data), arrays)
        differ = [key for key in sorted(digests) if digests[key] != saved[case.name][key]]
        if where is None and not differ:
            print(f"{line}  same", flush=True)
        else:
            failed += 1
            print(f"{line}  DIFFERENT: {where or ''} {', '.join(differ)}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
