"""The steps a SIGKILL of a recording loses, with and without the helper process.

    python bench/kill_loss.py                      # killed after 200,000 and 600,000 steps
    python bench/kill_loss.py --at 1000000 --repeat 3

A fresh process records ``three-joint --strategy random --seed 1`` (its chunks built in the
process, or by the helper process) and kills itself with SIGKILL from the progress callback
once it has taken ``--at`` steps (rounded up to the callback's 4,096); then
``rsstp-replay``'s reader counts the steps of the side file's complete chunks. Reported:
the steps taken, the steps kept, and the steps lost.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

from rsstp_replay import open_recording

_KILLED = """
import os, signal, sys
from rsstp_sim import RandomStrategy, load_scenario
from rsstp_sim.recording.recorder import Recorder

path, at, helper = sys.argv[1], int(sys.argv[2]), sys.argv[3] == "helper"
recorder = Recorder(path, load_scenario("three-joint"), RandomStrategy(), seed=1)


def progress(done: int) -> None:
    if done >= at:
        print(done, flush=True)
        os.kill(os.getpid(), signal.SIGKILL)


recorder.run(10**8, progress=progress, helper=helper)
"""


def lost(at: int, how: str) -> tuple[int, int]:
    """The steps taken when the recording was killed, and the steps its side file keeps."""
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "killed.mcap"
        done = subprocess.run(
            [sys.executable, "-c", _KILLED, str(out), str(at), how],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != -9:
            sys.exit(f"the recording was not killed ({done.returncode}): {done.stderr}")
        taken = int(done.stdout)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # (not finished: what is being measured)
            with open_recording(out.with_name(f"{out.name}.partial")) as recording:
                return taken, recording.n_steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--at", type=int, nargs="+", default=[200_000, 600_000])
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    for how in ("alone", "helper"):
        for at in args.at:
            for _ in range(args.repeat):
                taken, kept = lost(at, how)
                print(f"{how:<6} killed after {taken:>9,} steps: kept {kept:>9,}, "
                      f"lost {taken - kept:,}")  # fmt: skip


if __name__ == "__main__":
    main()
