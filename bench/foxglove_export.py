"""``rsstp-replay export --foxglove`` end to end, as a user runs it.

    python bench/foxglove_export.py                  # 1,000,000 steps
    python bench/foxglove_export.py --steps 200000 --repeat 3
    python bench/foxglove_export.py --recording x1m.mcap   # a recording of your own

The command runs in a fresh process (``rsstp-replay`` beside this interpreter), cold: its wall
time includes starting Python and the imports. Peak memory is the child's maximum RSS
(:mod:`_cold`). The recording is ``rsstp-sim record three-joint --strategy random --seed 1
--steps N``, made once and kept as ``/tmp/rsstp-bench-three-joint-N.mcap`` (or the one
``--recording`` names). Printed: the seconds of every run, the peak, the scene file's size
(bytes per step, and against the recording), its messages per topic, and whether every run
wrote the same bytes. The machine's load average is printed too: these are wall-clock figures
and other work slows them.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import sys
import tempfile
from pathlib import Path

from mcap.reader import make_reader

from _cold import measure
from _recordings import random_three_joint

BIN = Path(sys.executable).parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--recording", type=Path, help="export this recording instead")
    args = parser.parse_args()
    mcap = args.recording or random_three_joint(args.steps)
    out = Path(tempfile.gettempdir()) / "rsstp-bench-scene.mcap"
    command = [str(BIN / "rsstp-replay"), "export", "--foxglove", str(mcap), "-o", str(out)]
    print(f"{mcap}: {mcap.stat().st_size / 1e6:.1f} MB; load {os.getloadavg()[0]:.1f}")
    seconds: list[float] = []
    peak = 0.0
    digests = set()
    for _ in range(args.repeat):
        taken, gib = measure([*command, "--force"])
        seconds.append(taken)
        peak = max(peak, gib)
        digests.add(hashlib.sha256(out.read_bytes()).hexdigest())
    with open(out, "rb") as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        made_from = {m.name: m.metadata for m in reader.iter_metadata()}["rsstp.scene"]
    steps = int(made_from["steps"]) + 1  # the reset too
    assert summary is not None and summary.statistics is not None
    counts = {
        summary.channels[channel].topic: count
        for channel, count in summary.statistics.channel_message_counts.items()
    }
    size = out.stat().st_size
    shown = ", ".join(f"{s:.2f}" for s in seconds)
    print(f"export --foxglove, cold, fresh process: {shown} s; peak {peak:.2f} GiB")
    print(
        f"scene of {steps:,} steps: {size / 1e6:.1f} MB ({size / steps:.1f} bytes/step, "
        f"{size / mcap.stat().st_size:.2f} x the recording); messages per topic: {counts}"
    )
    print(f"same bytes on every run: {'yes' if len(digests) == 1 else 'NO'}")
    print(f"load {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
