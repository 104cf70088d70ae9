"""Recordings the benchmarks measure: made once with ``rsstp-sim record`` and kept in the
temporary folder (a half-written one never counts: it is renamed into place when done)."""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

BIN = Path(sys.executable).parent


def recorded(name: str, *arguments: str) -> Path:
    """``/tmp/rsstp-bench-{name}.mcap``: ``rsstp-sim record ARGUMENTS``, recorded if missing."""
    path = Path(tempfile.gettempdir()) / f"rsstp-bench-{name}.mcap"
    if not path.exists():
        partial = path.with_suffix(".partial.mcap")
        print(f"recording {path} (once): rsstp-sim record {' '.join(arguments)}", flush=True)
        subprocess.run(
            [str(BIN / "rsstp-sim"), "record", *arguments, "-o", str(partial), "--force"],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        partial.rename(path)
    return path


def random_three_joint(steps: int) -> Path:
    """``steps`` random steps of ``three-joint``, seed 1 (the speed issue's run)."""
    return recorded(
        f"three-joint-{steps}",
        "three-joint", "--strategy", "random", "--seed", "1", "--steps", str(steps),
    )  # fmt: skip
