"""Benchmark: recordings to Rerun ``.rrd`` files, as ``rsstp-replay view FILE --save OUT`` does.

    python bench/viewer.py                        # the three cases of the issue's budgets
    python bench/viewer.py --case learner --repeat 5
    python bench/viewer.py --case frontier-1m --repeat 3
    python bench/viewer.py --page run.rrd [--repeat 3] [--screenshot docs/viewer.png]
    python bench/viewer.py --case map-1200 --repeat 1     # then --page on the .rrd it names
    python bench/viewer.py --mcap RUN.mcap --repeat 1    # a recording at hand (<= 4 GiB peak)

The cases (recordings made once under the temporary folder if missing):

- ``splitter``: ``rsstp-sim record thesis-roulette --strategy splitter --steps 3000 --seed 0``
  (1,695 model versions): <= 5 s, <= 500 MiB peak, .rrd <= 20 MB;
- ``learner``: ``recordings/two-joint-30-learner.mcap`` (12,000 steps, 433 versions): <= 5 s;
- ``frontier-1m``: the learner for 1,000,000 steps on :data:`FRONTIER_TOML` (two joints at 10
  degrees, one obstacle, 1,183 true classes; 612 model versions): <= 10 s, <= 1 GiB peak,
  .rrd <= 1.5 x the .mcap;
- ``random-1m``: ``rsstp-sim record three-joint --strategy random --steps 1000000 --seed 1``:
  <= 10 s, <= 1 GiB peak, .rrd <= 1.5 x the .mcap;
- ``map-1200``: the learner on ``bench/two-joint-10-obstacle.toml`` (two joints at 10 degrees,
  one obstacle, 1,217 true classes; it stops when done, at step 643,244, 6,836 versions):
  issue 32's model map and large model. <= 20 s, <= 1 GiB peak, .rrd <= the .mcap; then
  ``--page`` on its .rrd: the web viewer settled within 60 s;
- ``--mcap FILE``: a recording at hand, such as issue 32's 39,232-class learner run of
  ``three-joint`` (viewed within 4 GiB, as it is recorded and audited).

Each case is timed twice over: cold, end to end in a fresh process (``rsstp-replay view ...
--save``, Python's start and imports included; the peak RSS is that process's), and in this
process (``open_recording`` to the finished file, the parts printed). Wall-clock figures: the
load average is printed with them.

``--page`` serves an ``.rrd`` with ``rerun --serve-web`` on 127.0.0.1 and times how long
the page, in headless Chromium (Debian's ``chromium`` driven by ``playwright``, software
WebGL), takes to show everything (:func:`page`), and the CPU seconds the browser spent until
then (a figure a busy machine does not inflate as much as the wall clock); ``--screenshot``
saves its last look.
"""

from __future__ import annotations

import argparse
import io
import os
import resource
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from _recordings import recorded
from rsstp_replay.reader.recording import open_recording
from rsstp_replay.viewer import view
from rsstp_replay.viewer._serve import WebServer

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
TMP = Path(tempfile.gettempdir())
CASES: dict[str, dict[str, Any]] = {
    "splitter": {
        "record": ["thesis-roulette", "--strategy", "splitter", "--steps", "3000", "--seed", "0"],
        "seconds": 5.0,
        "peak_mib": 500.0,
        "rrd_mb": 20.0,
    },
    "learner": {"file": ROOT / "recordings" / "two-joint-30-learner.mcap", "seconds": 5.0},
    "frontier-1m": {
        "scenario": "frontier-two-joint-10",
        "record": ["--strategy", "learner", "--steps", "1000000"],
        "seconds": 10.0,
        "peak_mib": 1024.0,
        "rrd_ratio": 1.5,
    },
    "random-1m": {
        "record": ["three-joint", "--strategy", "random", "--steps", "1000000", "--seed", "1"],
        "seconds": 10.0,
        "peak_mib": 1024.0,
        "rrd_ratio": 1.5,
    },
    "map-1200": {
        "toml": ROOT / "bench" / "two-joint-10-obstacle.toml",
        "record": ["--strategy", "learner", "--steps", "1000000", "--seed", "0"],
        "seconds": 20.0,
        "peak_mib": 1024.0,
        "rrd_ratio": 1.0,
    },
}

_RUNNER = """
import resource, subprocess, sys, time
began = time.perf_counter()
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
print(done.returncode, time.perf_counter() - began,
      resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, done.stderr.strip()[-300:])
"""


FRONTIER_TOML = """name = "two-joint-10"
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
"""Two joints at 10 degrees, one obstacle: 1,183 true classes (issue 19's frontier world)."""


def recording_of(name: str) -> Path:
    case = CASES[name]
    if "file" in case:
        return Path(case["file"])
    if "toml" in case:
        return recorded(f"view-{name}", str(case["toml"]), *case["record"])
    if "scenario" in case:
        toml = TMP / f"rsstp-bench-{case['scenario']}.toml"
        toml.write_text(FRONTIER_TOML)
        return recorded(f"view-{name}", str(toml), *case["record"])
    return recorded(f"view-{name}", *case["record"])


def bench(name: str, repeat: int) -> None:
    case = CASES[name]
    mcap = recording_of(name)
    out = TMP / f"rsstp-bench-view-{name}.rrd"
    print(f"== {name}: {mcap} ({mcap.stat().st_size / 1e6:.1f} MB); load {os.getloadavg()[0]:.1f}")
    for run in range(repeat):
        done = subprocess.run(
            [
                sys.executable,
                "-c",
                _RUNNER,
                str(BIN / "rsstp-replay"),
                "view",
                str(mcap),
                "--save",
                str(out),
                "--force",
            ],
            capture_output=True,
            text=True,
            check=True,
        )
        code, seconds, peak_kib, err = done.stdout.split(" ", 3)
        if code != "0":
            sys.exit(f"view failed: {err}")
        size_mb = out.stat().st_size / 1e6
        peak_mib = int(peak_kib) / 1024
        checks = [("s", float(seconds), case["seconds"])] if "seconds" in case else []
        if "peak_mib" in case:
            checks.append(("MiB peak", peak_mib, case["peak_mib"]))
        if "rrd_mb" in case:
            checks.append(("MB .rrd", size_mb, case["rrd_mb"]))
        if "rrd_ratio" in case:
            ratio = out.stat().st_size / mcap.stat().st_size
            checks.append(("x the .mcap", ratio, case["rrd_ratio"]))
        shown = "; ".join(
            f"{value:.2f} {unit} (target {target:g}: {'met' if value <= target else 'NOT met'})"
            for unit, value, target in checks
        )
        print(
            f"  cold, fresh process, run {run + 1}: {float(seconds):.1f} s; {shown}; "
            f"{peak_mib:.0f} MiB peak, "
            f"{size_mb:.1f} MB .rrd"
        )
    began = time.perf_counter()
    with open_recording(mcap) as recording:
        result = view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
    total = time.perf_counter() - began
    s = result.summary
    print(
        f"  in-process (warm imports): {total:.2f} s: read {s.seconds_read:.2f} s, audits and "
        f"placing {s.seconds_prepare:.2f} s, Rerun {result.seconds_rerun:.2f} s; "
        f"{s.model_versions} model versions, {sum(s.rows.values()):,} rows; load "
        f"{os.getloadavg()[0]:.1f}; peak RSS so far "
        f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MiB"
    )


# ------------------------------------------------------------------------------ the page


def page(rrd: Path, *, repeat: int, limit_s: float, png: Path | None) -> None:
    """Serve ``rrd`` with ``rerun --serve-web`` on 127.0.0.1, open the page in headless
    Chromium (Debian's ``chromium`` driven by ``playwright``, software WebGL) and take a
    screenshot every 2 s until four in a row are alike (below the top bar, whose latency
    figure changes): the page then shows everything, the last step at the time cursor. The
    figure is when it first looked like that (a screenshot waits while the page's one thread
    is busy loading, so it is an upper bound). ``png``: save the last screenshot."""
    chromium = shutil.which("chromium")
    if chromium is None:
        sys.exit("bench/viewer.py: 'chromium' not found (Debian: apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        sys.exit("bench/viewer.py: needs playwright (pip install playwright)")
    print(f"== page: {rrd} ({rrd.stat().st_size / 1e6:.1f} MB); load {os.getloadavg()[0]:.1f}")
    for run in range(repeat):
        server = WebServer(rrd, bind="127.0.0.1", web_port=_free_port(), grpc_port=_free_port())
        try:
            with sync_playwright() as driver:
                browser = driver.chromium.launch(
                    executable_path=chromium, args=["--use-angle=swiftshader", "--no-sandbox"]
                )
                tab = browser.new_page(viewport={"width": 1600, "height": 1000})
                cpu_before = _browser_cpu_s()
                began = time.perf_counter()
                tab.goto(server.url)
                shots: list[tuple[float, float, bytes]] = []
                alike = 0
                while time.perf_counter() - began < limit_s and alike < 4:
                    shot = tab.screenshot(timeout=limit_s * 1000)
                    seconds = time.perf_counter() - began
                    alike = alike + 1 if shots and _body(shot) == _body(shots[-1][2]) else 0
                    shots.append((seconds, _browser_cpu_s() - cpu_before, shot))
                    tab.wait_for_timeout(2000)
                browser.close()
        finally:
            server.close()
        final = _body(shots[-1][2])
        first, cpu = next((s, c) for s, c, shot in shots if _body(shot) == final)
        state = "settled" if alike >= 4 else f"still changing after {limit_s:.0f} s"
        print(
            f"  run {run + 1}: final look first at {first:.1f} s after opening the page "
            f"({state}; target 60: {'met' if alike >= 4 and first <= 60 else 'NOT met'}); "
            f"the browser's CPU until then {cpu:.1f} s; load {os.getloadavg()[0]:.1f}"
        )
        if png is not None:
            png.write_bytes(shots[-1][2])
            print(f"  saved {png}")


def _browser_cpu_s() -> float:
    """CPU seconds (user and system) of this process's descendants now alive: the browser's
    processes (read from ``/proc``; 0 elsewhere)."""
    parents: dict[int, int] = {}
    cpu: dict[int, float] = {}
    tick = os.sysconf("SC_CLK_TCK")
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(entry.name)] = int(fields[1])
        cpu[int(entry.name)] = (int(fields[11]) + int(fields[12])) / tick
    me, total = os.getpid(), 0.0
    for pid in cpu:
        up = parents.get(pid, 0)
        while up not in (0, 1, me):
            up = parents.get(up, 0)
        if up == me and pid != me:
            total += cpu[pid]
    return total


def _body(png: bytes) -> bytes:
    """The screenshot's pixels below the top bar (40 px)."""
    from PIL import Image

    image = Image.open(io.BytesIO(png)).convert("RGB")
    return image.crop((0, 40, image.width, image.height)).tobytes()


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--case", choices=sorted(CASES), action="append")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--page", type=Path, default=None, metavar="RRD")
    parser.add_argument("--screenshot", type=Path, default=None, metavar="PNG")
    parser.add_argument("--limit", type=float, default=600.0, help="seconds to wait at most")
    parser.add_argument("--mcap", type=Path, default=None, help="view this recording instead")
    args = parser.parse_args()
    if args.page is not None:
        page(args.page, repeat=args.repeat, limit_s=args.limit, png=args.screenshot)
        return
    if args.mcap is not None:
        CASES[args.mcap.stem] = {"file": args.mcap, "peak_mib": 4096.0}
        args.case = [args.mcap.stem]
    for name in args.case or list(CASES):
        bench(name, args.repeat)


if __name__ == "__main__":
    main()
