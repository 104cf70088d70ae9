"""Benchmark: recordings to Rerun ``.rrd`` files, as ``rsstp-replay view FILE --save OUT`` does.

    python bench/viewer.py                        # the three cases of the issue's budgets
    python bench/viewer.py --case learner --repeat 5
    python bench/viewer.py --screenshot docs/viewer.png --rrd run.rrd [--wait 40]

The cases (recordings made once under the temporary folder if missing):

- ``splitter``: ``rsstp-sim record thesis-roulette --strategy splitter --steps 3000 --seed 0``
  (1,695 model versions): <= 5 s, <= 500 MiB peak, .rrd <= 20 MB;
- ``learner``: ``recordings/two-joint-30-learner.mcap`` (12,000 steps, 433 versions): <= 5 s;
- ``random-1m``: ``rsstp-sim record three-joint --strategy random --steps 1000000 --seed 1``:
  <= 10 s, <= 1 GiB peak, .rrd <= 1.5 x the .mcap.

Each case is timed twice over: cold, end to end in a fresh process (``rsstp-replay view ...
--save``, Python's start and imports included; the peak RSS is that process's), and in this
process (``open_recording`` to the finished file, the parts printed). Wall-clock figures: the
load average is printed with them.

``--screenshot`` serves an ``.rrd`` with ``rerun --serve-web`` on 127.0.0.1, renders it in
headless Chromium (Debian's ``chromium``, software WebGL) over the DevTools protocol, waits
``--wait`` seconds for the viewer to load the file, and saves a PNG.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
import resource
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

from _recordings import recorded
from rsstp_replay._viewer_serve import WebServer
from rsstp_replay.recording import open_recording
from rsstp_replay.viewer import view

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
    "random-1m": {
        "record": ["three-joint", "--strategy", "random", "--steps", "1000000", "--seed", "1"],
        "seconds": 10.0,
        "peak_mib": 1024.0,
        "rrd_ratio": 1.5,
    },
}

_RUNNER = """
import resource, subprocess, sys, time
began = time.perf_counter()
done = subprocess.run(sys.argv[1:], capture_output=True, text=True)
print(done.returncode, time.perf_counter() - began,
      resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, done.stderr.strip()[-300:])
"""


def recording_of(name: str) -> Path:
    case = CASES[name]
    if "file" in case:
        return Path(case["file"])
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
        checks = [("s", float(seconds), case["seconds"])]
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
            f"  cold, fresh process, run {run + 1}: {shown}; {peak_mib:.0f} MiB peak, "
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


# ------------------------------------------------------------------------------ screenshot


def screenshot(png: Path, rrd: Path, *, wait_s: float) -> None:
    """Serve ``rrd`` to the web viewer on 127.0.0.1, load it in headless Chromium, save a PNG."""
    chromium = shutil.which("chromium")
    if chromium is None:
        sys.exit("bench/viewer.py: 'chromium' not found (Debian: apt-get install chromium)")
    with tempfile.TemporaryDirectory() as folder:
        server = WebServer(rrd, bind="127.0.0.1", web_port=_free_port(), grpc_port=_free_port())
        try:
            began = time.perf_counter()
            png.write_bytes(_capture(chromium, server.url, Path(folder) / "profile", wait_s=wait_s))
        finally:
            server.close()
    print(f"saved {png} ({time.perf_counter() - began:.0f} s after the page was opened)")


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def _wait_for_port(port: int, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on port {port}")


def _capture(chromium: str, url: str, profile: Path, *, wait_s: float) -> bytes:
    """Load ``url`` in headless Chromium, wait, and return a PNG of the page."""
    profile.mkdir()
    devtools_port = _free_port()
    browser = subprocess.Popen(
        [
            chromium,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={profile}",
            "--use-angle=swiftshader",
            f"--remote-debugging-port={devtools_port}",
            "--window-size=1600,1000",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        _wait_for_port(devtools_port)
        pages = json.load(urllib.request.urlopen(f"http://127.0.0.1:{devtools_port}/json/list"))
        page = next(p for p in pages if p["type"] == "page")
        devtools = _DevTools(page["webSocketDebuggerUrl"])
        devtools.call(
            "Emulation.setDeviceMetricsOverride",
            width=1600,
            height=1000,
            deviceScaleFactor=1,
            mobile=False,
        )
        devtools.call("Page.navigate", url=url)
        time.sleep(wait_s)  # the viewer's wasm loads, then renders with software WebGL
        shot = devtools.call("Page.captureScreenshot", format="png")
        return base64.b64decode(shot["result"]["data"])
    finally:
        os.killpg(browser.pid, signal.SIGTERM)
        browser.wait()


class _DevTools:
    """The smallest Chrome DevTools Protocol client: one websocket, text frames, no deps."""

    def __init__(self, url: str) -> None:
        host_port, path = url.removeprefix("ws://").split("/", 1)
        host, port = host_port.split(":")
        self._socket = socket.create_connection((host, int(port)))
        key = base64.b64encode(os.urandom(16)).decode()
        self._socket.sendall(
            f"GET /{path} HTTP/1.1\r\nHost: {host_port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
            "Sec-WebSocket-Version: 13\r\n\r\n".encode()
        )
        self._buffer = b""
        while b"\r\n\r\n" not in self._buffer:
            self._buffer += self._socket.recv(4096)
        head, self._buffer = self._buffer.split(b"\r\n\r\n", 1)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise ConnectionError(f"DevTools refused the websocket: {head[:80]!r}")
        self._id = 0

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self._id += 1
        self._send(json.dumps({"id": self._id, "method": method, "params": params}).encode())
        while True:
            message: dict[str, Any] = json.loads(self._receive())
            if message.get("id") == self._id:
                return message

    def _send(self, data: bytes) -> None:
        mask = os.urandom(4)
        size = len(data)
        if size < 126:
            head = struct.pack(">BB", 0x81, 0x80 | size)
        elif size < 1 << 16:
            head = struct.pack(">BBH", 0x81, 0x80 | 126, size)
        else:
            head = struct.pack(">BBQ", 0x81, 0x80 | 127, size)
        self._socket.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def _read(self, size: int) -> bytes:
        while len(self._buffer) < size:
            chunk = self._socket.recv(1 << 20)
            if not chunk:
                raise ConnectionError("DevTools closed the websocket")
            self._buffer += chunk
        data, self._buffer = self._buffer[:size], self._buffer[size:]
        return data

    def _receive(self) -> bytes:
        payload = b""
        while True:
            first, second = self._read(2)
            size = second & 0x7F
            if size == 126:
                size = struct.unpack(">H", self._read(2))[0]
            elif size == 127:
                size = struct.unpack(">Q", self._read(8))[0]
            payload += self._read(size)
            if first & 0x80:
                return payload


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--case", choices=sorted(CASES), action="append")
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--screenshot", type=Path, default=None, metavar="PNG")
    parser.add_argument("--rrd", type=Path, default=None, help="the .rrd to screenshot")
    parser.add_argument("--wait", type=float, default=30.0, help="seconds before the screenshot")
    args = parser.parse_args()
    if args.screenshot is not None:
        if args.rrd is None:
            parser.error("--screenshot needs --rrd")
        screenshot(args.screenshot, args.rrd, wait_s=args.wait)
        return
    for name in args.case or list(CASES):
        bench(name, args.repeat)


if __name__ == "__main__":
    main()
