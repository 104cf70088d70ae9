"""Time reading a recording: ``open_recording``, ``steps()``, ``memory()``, ``events()``.

    PYTHONPATH=src python bench/replay.py [STEPS]   (default: 1000000)

The recording is ``rsstp-sim record three-joint --strategy random --seed 1 --steps STEPS``,
made once (about 40 s for a million steps) and cached as
``/tmp/rsstp-replay-bench-STEPS.mcap``. Each measurement runs in a fresh Python process, so its
peak RSS (``resource.getrusage(RUSAGE_SELF).ru_maxrss``) is that of the imports plus the
measured call alone; ``imports`` is the RSS before the call. The machine's load average
(``os.getloadavg()``) is printed before and after: the figures are wall-clock seconds, and
other work on the machine slows them.

Targets for a million steps: ``steps()`` within 10 s and 1.5 GB peak RSS.

On the 2-core development machine (Python 3.11.7, msgspec 0.22, pandas 3, mcap 1.6), a million
steps (72.5 MB, 528 chunks of 1 MiB), while other jobs kept the load average at 13::

    open_recording      0.01 s   peak RSS    114 MB (imports  113 MB)
    steps()             6.32 s   peak RSS    317 MB (imports  113 MB)
    memory()            3.23 s   peak RSS    191 MB (imports  113 MB)
    events()            2.16 s   peak RSS    197 MB (imports  112 MB)
    model_at(last)      0.01 s   peak RSS    115 MB (imports  113 MB)

and at a load average of about 1: ``steps()`` 3.2 s, ``memory()`` 1.2 s, ``events()`` 0.9 s.
Of ``steps()``, about a third is msgspec parsing the JSON, a third copying fields into the
columns, the rest reading, decompressing, CRC-checking and slicing the chunks.
"""

from __future__ import annotations

import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

STEPS_TARGET_S = 10.0
RSS_TARGET_MB = 1536.0
MEASURES = ("open_recording", "steps()", "memory()", "events()", "model_at(last)")


def recording_path(steps: int) -> Path:
    """The cached recording of ``steps`` steps, made (in a subprocess) when missing or stale."""
    path = Path(f"/tmp/rsstp-replay-bench-{steps}.mcap")
    if path.exists():
        check = subprocess.run(
            [sys.executable, __file__, "--measure", "open_recording", str(path)],
            capture_output=True,
            text=True,
        )
        if check.returncode == 0:
            return path
        print(f"the cached {path} does not open ({check.stderr.strip()}): recording again")
    print(f"recording {steps:,} steps to {path} (cached for later runs)...", flush=True)
    started = time.perf_counter()
    command = [sys.executable, "-m", "rsstp_cli.sim", "record", "three-joint", "--strategy"]
    command += ["random", "--seed", "1", "--steps", str(steps), "-o", str(path), "--force"]
    subprocess.run(command, check=True)
    print(f"recorded in {time.perf_counter() - started:.1f} s")
    return path


def measure(what: str, path: str) -> dict[str, float]:
    """Run one measurement in this process; RSS in MB."""
    from rsstp_replay import open_recording

    before = _rss_mb()
    started = time.perf_counter()
    recording = open_recording(path)
    if what == "steps()":
        started = time.perf_counter()
        result: object = recording.steps()
    elif what == "memory()":
        started = time.perf_counter()
        result = recording.memory()
    elif what == "events()":
        started = time.perf_counter()
        result = recording.events()
    elif what == "model_at(last)":
        started = time.perf_counter()
        result = recording.model_at(recording.n_steps)
    else:
        result = recording
    seconds = time.perf_counter() - started
    size = len(result) if hasattr(result, "__len__") else 0  # type: ignore[arg-type]
    return {"seconds": seconds, "peak_mb": _rss_mb(), "imports_mb": before, "rows": size}


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # KiB on Linux


def main(argv: list[str]) -> int:
    if argv[:1] == ["--measure"]:
        print(json.dumps(measure(argv[1], argv[2])))
        return 0
    steps = int(argv[0]) if argv else 1_000_000
    path = recording_path(steps)
    size_mb = path.stat().st_size / 1e6
    load = os.getloadavg()
    print(f"{path}: {steps:,} steps, {size_mb:.1f} MB; {os.cpu_count()} CPUs")
    print(f"load average before: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    results = {}
    for what in MEASURES:
        run = subprocess.run(
            [sys.executable, __file__, "--measure", what, str(path)],
            capture_output=True,
            text=True,
            check=True,
        )
        result = json.loads(run.stdout)
        results[what] = result
        print(
            f"{what:<16} {result['seconds']:7.2f} s   peak RSS {result['peak_mb']:6.0f} MB "
            f"(imports {result['imports_mb']:4.0f} MB)",
            flush=True,
        )
    load = os.getloadavg()
    print(f"load average after: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    steps_result = results["steps()"]
    ok = steps_result["seconds"] <= STEPS_TARGET_S and steps_result["peak_mb"] <= RSS_TARGET_MB
    print(
        f"steps() target (<= {STEPS_TARGET_S:g} s, <= {RSS_TARGET_MB:g} MB peak RSS): "
        f"{'met' if ok else 'MISSED'}"
    )
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
