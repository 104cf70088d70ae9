"""Where a view can go on this machine: a display for a native viewer, free ports for the web.

The web viewer is served by the ``rerun`` program that comes with rerun-sdk (beside this
interpreter), on the ``.rrd`` file the view wrote: ``rerun --serve-web --bind ADDR`` binds
both of its servers (the page and the data) to one address, 127.0.0.1 unless asked otherwise.
(The SDK's own ``serve_web_viewer`` listens on every interface and cannot be told otherwise.)
Ports are checked before anything is read or logged, so a port in use is one line.
"""

from __future__ import annotations

import errno
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse
from pathlib import Path

from rsstp_replay.errors import ReplayError

__all__ = ["DEFAULT_BIND", "WebServer", "check_port", "has_display", "rerun_program"]

DEFAULT_BIND = "127.0.0.1"


def has_display() -> bool:
    """Whether a native viewer window can open: on Linux (and other X11/Wayland systems) a
    ``DISPLAY`` or ``WAYLAND_DISPLAY``; macOS and Windows always have one."""
    if sys.platform in ("darwin", "win32"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def check_port(address: str, port: int, *, option: str) -> None:
    """Raise :class:`ReplayError` (one line naming the port and ``option``) unless ``port`` can
    be bound on ``address``."""
    family = socket.AF_INET6 if ":" in address else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        try:
            probe.bind((address, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                raise ReplayError(
                    f"port {port} on {address} is in use: choose another with {option} N"
                ) from None
            raise ReplayError(
                f"cannot listen on {address} port {port}: {exc.strerror or exc}"
            ) from None


def rerun_program() -> str:
    """The ``rerun`` program of this environment (beside the interpreter, else on PATH)."""
    found = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")
    if found is None:
        raise ReplayError("the 'rerun' program of rerun-sdk was not found beside Python or on PATH")
    return found


class WebServer:
    """``rerun --serve-web`` on an ``.rrd`` file, bound to ``bind``, as a child process."""

    def __init__(self, rrd: Path, *, bind: str, web_port: int, grpc_port: int) -> None:
        self.bind, self.web_port, self.grpc_port = bind, web_port, grpc_port
        self._errors = tempfile.TemporaryFile()  # noqa: SIM115 - closed in close()
        self._process = subprocess.Popen(
            [
                rerun_program(),
                "--serve-web",
                "--bind",
                bind,
                "--web-viewer-port",
                str(web_port),
                "--port",
                str(grpc_port),
                str(rrd),
            ],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=self._errors,
            start_new_session=True,
        )
        self._wait_until_listening()

    @property
    def url(self) -> str:
        host = "127.0.0.1" if self.bind in ("0.0.0.0", "::") else self.bind  # noqa: S104
        data = f"rerun+http://{host}:{self.grpc_port}/proxy"
        return f"http://{host}:{self.web_port}/?url={urllib.parse.quote(data, safe='')}"

    def _wait_until_listening(self, timeout_s: float = 30.0) -> None:
        host = "127.0.0.1" if self.bind in ("0.0.0.0", "::") else self.bind  # noqa: S104
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self._process.poll() is not None:
                self._errors.seek(0)
                error = self._errors.read().decode(errors="replace")
                lines = [line for line in error.splitlines() if line.strip()]
                raise ReplayError(
                    "the rerun web server stopped at once"
                    + (f": {lines[-1].strip()[:200]}" if lines else "")
                )
            with socket.socket() as probe:
                probe.settimeout(0.5)
                if probe.connect_ex((host, self.web_port)) == 0:
                    return
            time.sleep(0.1)
        self.close()
        raise ReplayError(f"the rerun web server did not listen on port {self.web_port} in time")

    def wait(self) -> None:
        """Until the server ends, or Ctrl-C."""
        try:
            self._process.wait()
        except KeyboardInterrupt:
            pass
        finally:
            self.close()

    def close(self) -> None:
        if self._process.poll() is None:
            os.killpg(self._process.pid, signal.SIGTERM)
            try:
                self._process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(self._process.pid, signal.SIGKILL)
                self._process.wait()
        self._errors.close()
