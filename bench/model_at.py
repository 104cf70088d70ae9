"""The model at any step of a recording: ``Recording.model_at``, cold and warm.

    PYTHONPATH=src python bench/model_at.py RUN.mcap [--samples 50]

Opens the recording in this process, then times, in order: the first ``model_at`` (the
model versions read and their chain checked: what a user's first call pays), then
``--samples`` more at steps drawn evenly over the run (each a version rebuilt from the
recording's versions and the step's internal state). Prints the recording's size, its
model messages (keyframes and changes) and the times. Target (issue 32): any version within
50 ms.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from rsstp_replay import open_recording
from rsstp_replay.reader import version_heads


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path)
    parser.add_argument("--samples", type=int, default=50)
    args = parser.parse_args()
    began = time.perf_counter()
    with open_recording(args.recording) as recording:
        opened = time.perf_counter() - began
        started = time.perf_counter()
        recording.model_at(recording.n_steps)
        first = time.perf_counter() - started
        versions = version_heads(recording.model_versions())  # (not each version rebuilt)
        keyframes = sum(record.keyframe for record in versions)
        steps = np.linspace(0, recording.n_steps, args.samples).astype(np.int64).tolist()
        times = []
        for step in steps:
            started = time.perf_counter()
            model = recording.model_at(step)
            times.append(time.perf_counter() - started)
        print(
            f"{args.recording} ({args.recording.stat().st_size / 1e6:.1f} MB, "
            f"{recording.n_steps:,} steps): {len(versions):,} model versions, {keyframes:,} "
            f"keyframes; the last model {len(model):,} states"
        )
        print(f"  open {opened * 1e3:.0f} ms; first model_at (versions read) {first:.2f} s")
        ms = np.array(times) * 1e3
        print(
            f"  model_at at {len(times)} steps: median {np.median(ms):.1f} ms, "
            f"most {ms.max():.1f} ms (target 50 ms)"
        )


if __name__ == "__main__":
    main()
