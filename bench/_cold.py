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
usage = resource.getrusage(resource.RUSAGE_CHILDREN)
cpu = usage.ru_utime + usage.ru_stime
stderr = done.stderr.decode().strip().replace(chr(10), " | ")
print(done.returncode, seconds, cpu, usage.ru_maxrss, stderr)
"""


def measure(command: list[str]) -> tuple[float, float]:
    """Wall seconds and peak RSS (GiB) of ``command`` in a fresh process."""
    seconds, _, peak_gib = measure_cpu(command)
    return seconds, peak_gib


def measure_cpu(command: list[str]) -> tuple[float, float, float]:
    """Wall seconds, CPU seconds (user and system: the figure on a loaded machine) and peak
    RSS (GiB) of ``command`` in a fresh process."""
    done = subprocess.run(
        [sys.executable, "-c", _RUNNER, *command], capture_output=True, text=True, check=True
    )
    code, seconds, cpu, peak_kib, stderr = done.stdout.split(" ", 4)
    if int(code) not in (0, 1):  # audit exits 1 on a finding it was asked to gate on
        sys.exit(f"{' '.join(command)} failed ({code}): {stderr}")
    return float(seconds), float(cpu), int(peak_kib) / 2**20
