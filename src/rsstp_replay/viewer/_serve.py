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
import threading
import time
import urllib.parse
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from rsstp_replay.errors import ReplayError

__all__ = [
    "DEFAULT_BIND",
    "STOP_SIGNALS",
    "CtrlC",
    "WebServer",
    "check_port",
    "ctrl_c_remembered",
    "has_display",
    "rerun_command",
    "rerun_program",
]

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


@dataclass(slots=True)
class CtrlC:
    """Whether Ctrl-C was pressed within :func:`ctrl_c_remembered` (a plain flag: a signal
    handler must not take a lock its own thread may hold)."""

    pressed: bool = False


STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""What stops a view as Ctrl-C does: a terminal closed (SIGHUP) and ``kill`` (SIGTERM) too, so
the servers and the temporary folder go with the command."""


@contextmanager
def ctrl_c_remembered(*, interrupt: bool = True) -> Iterator[CtrlC]:
    """Within: Ctrl-C (SIGINT, or SIGTERM or SIGHUP: :data:`STOP_SIGNALS`) sets the flag
    yielded and, with ``interrupt``, also raises :class:`KeyboardInterrupt`; a wait that polls
    the flag stops even when the exception was lost.

    Python ignores an exception raised inside a finaliser (``__del__``), and a
    ``KeyboardInterrupt`` lands in one whenever the signal arrives while the garbage collector
    runs one (rerun's ``RecordingStream.__del__`` is a likely one here); a server waiting on
    the exception alone would then serve on after Ctrl-C. Outside the main thread (where
    signal handlers cannot be set) the flag is only set by whoever holds it.
    """
    pressed = CtrlC()

    def handler(signum: int, frame: object) -> None:
        pressed.pressed = True
        if interrupt:
            raise KeyboardInterrupt

    if threading.current_thread() is not threading.main_thread():
        yield pressed
        return
    unraisable = sys.unraisablehook

    def quiet(found: sys.UnraisableHookArgs) -> None:
        # A Ctrl-C lost in a finaliser: the flag has it; Python would print it as a traceback.
        if not (pressed.pressed and isinstance(found.exc_value, KeyboardInterrupt)):
            unraisable(found)

    previous = {sig: signal.signal(sig, handler) for sig in STOP_SIGNALS}
    sys.unraisablehook = quiet
    try:
        yield pressed
    finally:
        sys.unraisablehook = unraisable
        for sig, before in previous.items():
            signal.signal(sig, before)


def rerun_program() -> str:
    """The ``rerun`` program of this environment (beside the interpreter, else on PATH)."""
    found = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")
    if found is None:
        raise ReplayError("the 'rerun' program of rerun-sdk was not found beside Python or on PATH")
    return found


def rerun_command() -> str:
    """How to run :func:`rerun_program` from this shell: ``rerun`` when that is what ``PATH``
    finds, else its full path (a venv that is not activated)."""
    program = rerun_program()
    on_path = shutil.which("rerun")
    if on_path is not None and Path(on_path).resolve() == Path(program).resolve():
        return "rerun"
    return program


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
            start_new_session=True,  # Ctrl-C reaches this process alone, which stops the server
        )
        try:
            self._wait_until_listening()
        except BaseException:  # Ctrl-C while it starts too: no server left behind
            self.close()
            raise

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
        raise ReplayError(f"the rerun web server did not listen on port {self.web_port} in time")

    def wait(self, stop: CtrlC | None = None) -> None:
        """Until the server ends, or Ctrl-C, or ``stop`` is pressed (polled every 0.2 s);
        then close."""
        try:
            with ctrl_c_remembered(interrupt=False) as pressed:
                while self._process.poll() is None and not pressed.pressed:
                    if stop is not None and stop.pressed:
                        break
                    time.sleep(0.2)
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
