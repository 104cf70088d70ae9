"""Benchmark: a recording to a Rerun ``.rrd`` file, as ``rsstp-replay view FILE --save OUT`` does.

    python bench/viewer.py                       # 100,000 steps of three-joint, random, seed 1
    python bench/viewer.py --steps 10000 --repeat 5
    python bench/viewer.py --screenshot docs/viewer.png

The recording is made first if ``--mcap`` does not exist (``rsstp-sim record three-joint
--strategy random --steps N --seed 1``). Each run prints the parts (reading the MCAP, audits and
graph layout, Rerun: building and sending the columns and writing the file) and the total from
``open_recording`` to the finished file; the target is 3 s for 100,000 steps.

``--screenshot`` renders the web viewer on a saved ``.rrd`` in headless Chromium (software
WebGL) and saves a PNG. Its recording is a short three-joint run of the tests' ``RandomRefiner``
(random splits, merges, adds and deletes), so that the model has something to show.
"""

from __future__ import annotations

import argparse
import base64
import json
import os
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

from rsstp_replay.recording import open_recording
from rsstp_replay.viewer import view
from rsstp_sim.recording import record
from rsstp_sim.scenario import load_scenario
from rsstp_sim.strategies import RandomStrategy

TARGET_S = 3.0
ROOT = Path(__file__).resolve().parents[1]


def bench(mcap: Path, steps: int, repeat: int) -> None:
    if not mcap.exists():
        began = time.perf_counter()
        record(mcap, load_scenario("three-joint"), RandomStrategy(), steps=steps, seed=1)
        print(f"recorded {steps} steps to {mcap} in {time.perf_counter() - began:.1f} s")
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "bench.rrd"
        for run in range(repeat):
            began = time.perf_counter()
            with open_recording(mcap) as recording:
                result = view(
                    recording, save=out, spawn=False, serve_web=False, start=None, end=None
                )
            total = time.perf_counter() - began
            s = result.summary
            print(
                f"run {run + 1}: {s.last_step + 1} steps, {s.model_versions} model versions: "
                f"read {s.seconds_read:.2f} s, audits and layout {s.seconds_prepare:.2f} s, "
                f"Rerun {result.seconds_rerun:.2f} s; total {total:.2f} s "
                f"(target {TARGET_S:.0f} s: {'met' if total <= TARGET_S else 'NOT met'}); "
                f"{out.stat().st_size / 1e6:.1f} MB"
            )


# ------------------------------------------------------------------------------ screenshot


def screenshot(png: Path, *, wait_s: float) -> None:
    for program in ("rerun", "chromium"):
        if shutil.which(program) is None:
            sys.exit(f"bench/viewer.py: {program!r} not found (Debian: apt-get install chromium)")
    sys.path.insert(0, str(ROOT / "tests" / "replay"))
    from fakes import RandomRefiner  # the tests' refining strategy

    with tempfile.TemporaryDirectory() as folder:
        mcap, rrd = Path(folder) / "demo.mcap", Path(folder) / "demo.rrd"
        strategy = RandomRefiner(split=0.03, max_states=4)
        record(mcap, load_scenario("three-joint"), strategy, steps=300, seed=3)
        with open_recording(mcap) as recording:
            view(recording, save=rrd, spawn=False, serve_web=False, start=0, end=270)
        server = subprocess.Popen(
            ["rerun", "--serve-web", "--web-viewer-port", "9090", "--port", "9877", str(rrd)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        try:
            _wait_for_port(9090)
            url = "http://127.0.0.1:9090/?url=" + urllib.request.quote(
                "rerun+http://localhost:9877/proxy", safe=""
            )
            png.write_bytes(_capture(url, Path(folder) / "profile", wait_s=wait_s))
        finally:
            os.killpg(server.pid, signal.SIGTERM)
            server.wait()
    print(f"saved {png}")


def _wait_for_port(port: int, timeout_s: float = 20.0) -> None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        with socket.socket() as probe:
            if probe.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on port {port}")


def _capture(url: str, profile: Path, *, wait_s: float) -> bytes:
    """Load ``url`` in headless Chromium, wait, and return a PNG of the page."""
    profile.mkdir()
    browser = subprocess.Popen(
        [
            "chromium",
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={profile}",
            "--remote-debugging-port=9222",
            "--window-size=1600,1000",
            "about:blank",
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        _wait_for_port(9222)
        pages = json.load(urllib.request.urlopen("http://127.0.0.1:9222/json/list"))
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
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--mcap", type=Path, default=None, help="default: /tmp/rsstp-bench-N.mcap")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--screenshot", type=Path, default=None, metavar="PNG")
    parser.add_argument("--wait", type=float, default=25.0, help="seconds before the screenshot")
    args = parser.parse_args()
    if args.screenshot is not None:
        screenshot(args.screenshot, wait_s=args.wait)
        return
    mcap = args.mcap or Path(tempfile.gettempdir()) / f"rsstp-bench-{args.steps}.mcap"
    bench(mcap, args.steps, args.repeat)


if __name__ == "__main__":
    main()
