"""Recording speed and size: steps/s with and without the MCAP recorder (issue: recording).

    PYTHONPATH=src python bench/recording.py [--steps N] [--repeats R] [--profile]

Targets on ``three-joint`` with the ``random`` strategy and float feedback (as in
``bench/step_rate.py``): >= 50,000 recorded steps/s, a recording overhead <= 50 % of the
unrecorded step time (``recorded step time / unrecorded step time - 1``), and <= 120 bytes
per step on disk with the default chunk size.

Cold and warm: the world computes and caches every pose it meets. *Unrecorded* figures time
``Runner.run``: cold on a new runner, warm after ``reset()`` over the same walk (same seed).
*Recorded* figures time ``Recorder.run`` to a file in a temporary directory. The recorder
builds its own runner and world, and a world's cache cannot be handed to another one, so
the warm recorded figure walks the recorder's own world along the run's actions (``move``,
then ``reset``: the arm is back at the start pose step 0 was recorded at) before timing.
That fills the same pose cache the unrecorded warm figure enjoys; the recorder's own
per-pose JSON fragments are still built during the timed run (a real recording pays them
too). Every figure is the best of ``--repeats`` passes, each on fresh objects.

The second table gives, for every built-in scenario (its own feedback mode), the size of a
step message and how many steps fill a chunk of the default size (1 MiB of uncompressed
records): estimated as ``1 MiB / step message bytes``, and as ``1 MiB / message record
bytes`` (an MCAP message record adds 31 bytes to its JSON, and the chunk size counts
records), and measured from the full chunks of a 20,000-step random walk (a chunk's time
range is its step range; events share the chunks too). ``--profile`` adds a cProfile breakdown of
a warm recorded run and the same parts timed in isolation.

On the 2-core development machine (Python 3.11.7, mcap 1.6.0, msgspec 0.22.0), shared with
other jobs (load 3 to 10, so the figures moved by up to 2x between runs), best of 5 to 7:

    unrecorded (Runner)    cold 38,000-50,000/s   warm 380,000-560,000/s  (1.8-2.6 us/step)
    recorded (Recorder)    cold 28,000-42,000/s   warm  83,000-137,000/s  (7.3-12 us/step)
    overhead (warm)        225-430 %   target <= 50 %: missed
    recorded steps/s       >= 83,000   target >= 50,000: met
    on disk                74.2 bytes/step (three-joint, float feedback)  target <= 120: met

(Those figures and the breakdown below are from before 2026-11-26, when the recorder wrote
through mcap's ``Writer``; ``bench/record_vs_run.py`` measures the recorder since, and
``--profile`` times its parts: the step message, the chunked writer.)

Where a warm recorded step goes (``--profile``, the parts alone, us/step): the simulation
2.8, the step message bytes (``Recorder._step_bytes``, msgspec and joins) 2.0, mcap's
``Writer.add_message`` without compression 3.6-4.5, zstd 0.5-1.0. cProfile of the whole
run agrees: mcap writer code 53 %, recorder 16 %, simulation 25 %, zstd 2-3 %, msgspec 2 %,
file writes 0.2 %. The pure-Python MCAP writer's per-message bookkeeping (a ``Message``
object, statistics, the message index, eight ``struct.pack`` calls) alone costs about twice
a simulation step, so a 50 % overhead is out of reach while every step goes through
``Writer.add_message``.
"""

from __future__ import annotations

import argparse
import cProfile
import gc
import io
import os
import pstats
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from rsstp_format.schemas import STEP_NS
from rsstp_sim import (
    Pose,
    RandomStrategy,
    Runner,
    StepOutcome,
    builtin_scenarios,
    load_scenario,
)
from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.recording.chunks import ChunkedWriter
from rsstp_sim.recording.output import SideFileWriter
from rsstp_sim.recording.recorder import DEFAULT_CHUNK_SIZE, Recorder
from rsstp_sim.recording.step_messages import StepMessages
from step_rate import float_mode  # bench/ is the script folder

SEED = 1
TARGET_RECORDED = 50_000
TARGET_OVERHEAD = 0.50
TARGET_BYTES = 120
MESSAGE_RECORD_OVERHEAD = 1 + 8 + 2 + 4 + 8 + 8  # opcode, length, channel, sequence, 2 times


def walk_actions(scenario: Scenario, steps: int) -> list[int]:
    """The actions of the seeded random run (what the recorder's runner will play)."""
    runner = Runner(scenario, RandomStrategy(), seed=SEED)
    return [runner.step().action for _ in range(steps)]


def unrecorded(scenario: Scenario, steps: int) -> tuple[float, float]:
    """Steps/s of ``Runner.run``: cold (new runner), then warm (reset, same walk)."""
    runner = Runner(scenario, RandomStrategy(), seed=SEED)
    started = time.perf_counter()
    runner.run(steps)
    cold = steps / (time.perf_counter() - started)
    runner.reset()
    started = time.perf_counter()
    runner.run(steps)
    warm = steps / (time.perf_counter() - started)
    return cold, warm


def new_recorder(
    directory: Path, scenario: Scenario, *, warm_actions: list[int] | None
) -> Recorder:
    recorder = Recorder(directory / "run.mcap", scenario, RandomStrategy(), seed=SEED, force=True)
    if warm_actions is not None:
        world = recorder.runner.world
        for action in warm_actions:
            world.move(action)
        world.reset()
    return recorder


def recorded(
    directory: Path, scenario: Scenario, steps: int, actions: list[int]
) -> tuple[float, float, int]:
    """Steps/s of ``Recorder.run``: cold, then with the world's cache warmed; file bytes."""
    recorder = new_recorder(directory, scenario, warm_actions=None)
    started = time.perf_counter()
    recorder.run(steps)
    cold = steps / (time.perf_counter() - started)
    size = recorder.path.stat().st_size
    recorder = new_recorder(directory, scenario, warm_actions=actions)
    started = time.perf_counter()
    recorder.run(steps)
    warm = steps / (time.perf_counter() - started)
    if recorder.path.stat().st_size != size:
        raise SystemExit("the cold and the warm recording differ in size: not the same run")
    return cold, warm, size


def speed(steps: int, repeats: int) -> None:
    scenario = float_mode("three-joint")
    actions = walk_actions(scenario, steps)
    best = dict.fromkeys(("unrec_cold", "unrec_warm", "rec_cold", "rec_warm"), 0.0)
    size = 0
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):
            cold, warm = unrecorded(scenario, steps)
            best["unrec_cold"] = max(best["unrec_cold"], cold)
            best["unrec_warm"] = max(best["unrec_warm"], warm)
            cold, warm, size = recorded(Path(tmp), scenario, steps, actions)
            best["rec_cold"] = max(best["rec_cold"], cold)
            best["rec_warm"] = max(best["rec_warm"], warm)

    def overhead(cache: str) -> float:
        return best[f"unrec_{cache}"] / best[f"rec_{cache}"] - 1.0

    def us(rate: float) -> str:
        return f"{1e6 / rate:.2f} us/step"

    print(f"{scenario.origin}, random, seed {SEED}, {steps:,} steps, best of {repeats}")
    print(f"{'':<22} {'cold /s':>10} {'warm /s':>10}   warm step time")
    for label, key in (("unrecorded (Runner)", "unrec"), ("recorded (Recorder)", "rec")):
        cold, warm = best[f"{key}_cold"], best[f"{key}_warm"]
        print(f"{label:<22} {cold:>10,.0f} {warm:>10,.0f}   {us(warm)}")
    print(
        f"{'overhead':<22} {overhead('cold'):>10.0%} {overhead('warm'):>10.0%}"
        f"   target <= {TARGET_OVERHEAD:.0%} (warm)"
    )
    print(
        f"recorded steps/s (warm): {best['rec_warm']:,.0f}  target >= {TARGET_RECORDED:,}"
        f"  {'met' if best['rec_warm'] >= TARGET_RECORDED else 'MISSED'}"
    )
    print(
        f"recording overhead (warm): {overhead('warm'):.0%}  target <= {TARGET_OVERHEAD:.0%}"
        f"  {'met' if overhead('warm') <= TARGET_OVERHEAD else 'MISSED'}"
    )
    per_step = size / steps
    print(
        f"on disk: {size:,} bytes, {per_step:.1f} bytes/step (chunk {DEFAULT_CHUNK_SIZE:,} B, "
        f"zstd)  target <= {TARGET_BYTES}  {'met' if per_step <= TARGET_BYTES else 'MISSED'}"
    )


def chunk_table(steps: int = 20_000) -> None:
    """Steps per chunk for every built-in scenario, as a Markdown table for the README."""
    print()
    print(f"Steps per chunk at the default chunk size ({DEFAULT_CHUNK_SIZE:,} B), random walk")
    print(
        "| scenario | joints | obstacles | step message (B) | 1 MiB / message "
        "| 1 MiB / record | measured steps/chunk | on disk (B/step) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in builtin_scenarios():
            scenario = load_scenario(name)
            path = Path(tmp) / f"{name}.mcap"
            Recorder(path, scenario, RandomStrategy(), seed=SEED).run(steps)
            with path.open("rb") as stream:
                reader = make_reader(stream)
                summary = reader.get_summary()
                assert summary is not None
                sizes = [len(m.data) for _, _, m in reader.iter_messages(topics=["/rsstp/step"])]
            message = sum(sizes) / len(sizes)
            full = summary.chunk_indexes[:-1]  # the last chunk is partial
            spans = [(c.message_end_time - c.message_start_time) // STEP_NS + 1 for c in full]
            measured = f"{sum(spans) / len(spans):,.0f}" if spans else "(one chunk)"
            print(
                f"| {name} | {scenario.n_joints} | {len(scenario.obstacles)} | {message:.0f} "
                f"| {DEFAULT_CHUNK_SIZE / message:,.0f} "
                f"| {DEFAULT_CHUNK_SIZE / (message + MESSAGE_RECORD_OVERHEAD):,.0f} "
                f"| {measured} | {path.stat().st_size / steps:.1f} |"
            )


def isolated_parts(steps: int, repeats: int) -> None:
    """The parts of a recorded step, each timed alone over the same warm walk.

    The garbage collector is off while timing: the outcomes and messages kept here for the
    next part (a real recording keeps none) would otherwise make its passes dominate.
    """
    gc.collect()
    gc.disable()
    try:
        _isolated_parts(steps, repeats)
    finally:
        gc.enable()


def _best(repeats: int, run: Callable[[], None]) -> float:
    """The shortest of ``repeats`` timed calls, in seconds."""
    best = float("inf")
    for _ in range(repeats):
        started = time.perf_counter()
        run()
        best = min(best, time.perf_counter() - started)
    return best


def _add_all(data: list[bytes], compression: CompressionType) -> None:
    writer = Writer(io.BytesIO(), chunk_size=DEFAULT_CHUNK_SIZE, compression=compression)
    writer.start()
    channel = writer.register_channel("/rsstp/step", "json", 0)
    add = writer.add_message
    for t, message in enumerate(data):
        add(channel, t * STEP_NS, message, t * STEP_NS)
    writer.finish()


def _add_chunked(data: list[bytes], path: Path) -> None:
    output = SideFileWriter(io.FileIO(path, "w"))
    writer = ChunkedWriter(output, chunk_size=DEFAULT_CHUNK_SIZE)
    writer.start(profile="", library="bench")
    channel = writer.register_channel("/rsstp/step", "json", 0)
    add = writer.add_message
    for t, message in enumerate(data):
        add(channel, t * STEP_NS, message)
    writer.finish()
    output.close()


class _Replayed:
    """The world and the model as :meth:`StepMessages.stream` reads them, for steps taken
    before: the pose after each step, the model's version 0."""

    current: Pose
    version = 0


def _isolated_parts(steps: int, repeats: int) -> None:
    scenario = float_mode("three-joint")
    runner = Runner(scenario, RandomStrategy(), seed=SEED)
    runner.run(steps)  # warm the pose cache

    def simulate() -> None:
        runner.reset()
        step = runner.step
        for _ in range(steps):
            step()

    step_s = _best(repeats, simulate)
    runner.reset()
    outcomes = [(runner.step(), runner.world.current) for _ in range(steps)]
    data: list[bytes] = []

    def encode() -> None:
        at = _Replayed()

        def replayed() -> Iterator[StepOutcome]:
            for outcome, pose in outcomes:
                at.current = pose
                yield outcome

        stream = StepMessages().stream(replayed(), at, at, channel=1, waiting=(), then=lambda _: ())
        data[:] = [head + tail for _, _, head, tail in stream]

    encode_s = _best(repeats, encode)
    add_s = _best(repeats, lambda: _add_all(data, CompressionType.NONE))
    add_zstd_s = _best(repeats, lambda: _add_all(data, CompressionType.ZSTD))
    with tempfile.TemporaryDirectory() as tmp:
        chunked_s = _best(repeats, lambda: _add_chunked(data, Path(tmp) / "chunked.mcap"))

    print()
    print(f"The parts alone (warm, {steps:,} steps, best of {repeats}, us/step):")
    rows: list[tuple[str, float]] = [
        ("Runner.step (the simulation, unrecorded)", step_s),
        ("step message bytes (StepMessages.stream, joined)", encode_s),
        ("mcap Writer.add_message, no compression, to memory", add_s),
        ("zstd chunk compression (add_message zstd - none)", add_zstd_s - add_s),
        ("the recorder's ChunkedWriter, zstd on its thread, to a file", chunked_s),
    ]
    for label, seconds in rows:
        print(f"  {label:<52} {1e6 * seconds / steps:6.2f}")


GROUPS = (
    "zstd compression",
    "file writes (os)",
    "msgspec JSON encoding",
    "chunked writer (records, chunk builder)",
    "recorder (step bytes, loop, events)",
    "simulation (runner, world, memory, strategy)",
)


def _group(filename: str, name: str) -> str | None:
    """The part of a recorded step a profiled function belongs to (None: a builtin)."""
    if filename == "~":
        if "ZstdCompressor" in name:
            return GROUPS[0]
        if "_io.FileIO" in name:
            return GROUPS[1]
        if "msgspec" in name:
            return GROUPS[2]
        return None
    if f"{os.sep}mcap{os.sep}" in filename or filename.endswith(f"recording{os.sep}chunks.py"):
        return GROUPS[3]
    if f"{os.sep}recording{os.sep}" in filename:
        return GROUPS[4]
    if f"{os.sep}rsstp_sim{os.sep}" in filename:
        return GROUPS[5]
    return None


def profile(steps: int) -> None:
    """cProfile of a warm recorded run, grouped by where the time goes."""
    scenario = float_mode("three-joint")
    actions = walk_actions(scenario, steps)
    with tempfile.TemporaryDirectory() as tmp:
        recorder = new_recorder(Path(tmp), scenario, warm_actions=actions)
        profiler = cProfile.Profile()
        profiler.runcall(recorder.run, steps)
    stats = pstats.Stats(profiler)
    raw: dict[tuple[str, int, str], Any] = stats.stats  # type: ignore[attr-defined]
    total = sum(tottime for _, _, tottime, _, _ in raw.values())

    other = "other (Python builtins, numpy)"
    shares = dict.fromkeys([*GROUPS, other], 0.0)
    for (filename, _, name), (_, _, tottime, _, callers) in raw.items():
        group = _group(filename, name)
        if group is not None:
            shares[group] += tottime
            continue
        # A builtin (struct.pack, BytesIO.write, dict.get, ...): its time goes to its callers.
        for (caller_file, _, caller_name), timing in callers.items():
            shares[_group(caller_file, caller_name) or other] += timing[2]
    print()
    print(f"cProfile of a warm recorded run ({steps:,} steps; profiling inflates call-heavy code):")
    for group, seconds in shares.items():
        print(f"  {group:<46} {seconds / total:6.1%}  {1e6 * seconds / steps:6.2f} us/step")
    print()
    stats.sort_stats("tottime").print_stats(12)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--profile", action="store_true", help="add the time breakdown")
    args = parser.parse_args()
    speed(args.steps, args.repeats)
    chunk_table()
    if args.profile:
        isolated_parts(args.steps, args.repeats)
        profile(args.steps)


if __name__ == "__main__":
    main()
