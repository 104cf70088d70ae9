"""A command timed cold, as a user runs it: wall seconds and peak memory of a fresh process
(the child's maximum RSS, read by a fresh runner process so that no earlier child counts)."""

from __future__ import annotations

import subprocess
import sys

_RUNNER = """
import resource, subprocess, sys, time
began = time.perf_counter()
done = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
seconds = time.perf_counter() - began
peak_kib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
print(done.returncode, seconds, peak_kib, done.stderr.decode().strip().replace(chr(10), " | "))
"""


def measure(command: list[str]) -> tuple[float, float]:
    """Wall seconds and peak RSS (GiB) of ``command`` in a fresh process."""
    done = subprocess.run(
        [sys.executable, "-c", _RUNNER, *command], capture_output=True, text=True, check=True
    )
    code, seconds, peak_kib, stderr = done.stdout.split(" ", 3)
    if int(code) not in (0, 1):  # audit exits 1 on a finding it was asked to gate on
        sys.exit(f"{' '.join(command)} failed ({code}): {stderr}")
    return float(seconds), int(peak_kib) / 2**20
