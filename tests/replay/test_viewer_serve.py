"""Serving the web viewer: Ctrl-C stops it, even a Ctrl-C that Python loses in a finaliser."""

from __future__ import annotations

import gc
import os
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

from rsstp_replay.reader.recording import open_recording
from rsstp_replay.viewer import view
from rsstp_replay.viewer._serve import WebServer, ctrl_c_remembered
from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[2]
REFERENCE = ROOT / "recordings" / "thesis-roulette-script.mcap"


class _InterruptedFinaliser:
    """Its finaliser receives the Ctrl-C: Python prints the KeyboardInterrupt and drops it."""

    def __del__(self) -> None:
        os.kill(os.getpid(), signal.SIGINT)
        _bytecodes()  # the handler runs here, and its KeyboardInterrupt ends the loop


class _FailingFinaliser:
    def __del__(self) -> None:
        raise ValueError("a finaliser's own error")


def _bytecodes() -> None:
    """A loop for a pending signal's Python handler to run in: CPython runs it at the loop's
    first jump back (between bytecodes), long before the loop could end; it ends the loop when
    it raises, so that no time is spent when it does."""
    for _ in range(1_000_000):
        pass


def test_a_ctrl_c_lost_in_a_finaliser_is_still_remembered_and_not_printed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Python hands an exception raised in a finaliser to sys.unraisablehook, which prints it
    # as a traceback: not the Ctrl-C the flag keeps; any other error still goes there.
    reported: list[BaseException | None] = []
    monkeypatch.setattr(sys, "unraisablehook", lambda found: reported.append(found.exc_value))
    with ctrl_c_remembered() as ctrl_c:
        _FailingFinaliser()
        _InterruptedFinaliser()  # collected at once: the KeyboardInterrupt is lost in __del__
        gc.collect()
        assert ctrl_c.pressed
    assert [type(error) for error in reported] == [ValueError]
    _FailingFinaliser()  # (after it, the test's hook is back)
    assert len(reported) == 2


def test_ctrl_c_without_interrupt_only_sets_the_flag() -> None:
    with ctrl_c_remembered(interrupt=False) as ctrl_c:
        os.kill(os.getpid(), signal.SIGINT)
        _bytecodes()  # the handler runs here; no KeyboardInterrupt
    assert ctrl_c.pressed
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def _free_port() -> int:
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


def test_a_real_server_stops_on_ctrl_c_during_its_wait(tmp_path: Path) -> None:
    rrd = tmp_path / "run.rrd"
    with open_recording(REFERENCE) as recording:
        view(recording, save=rrd, spawn=False, serve_web=False, start=None, end=None)
    server = WebServer(rrd, bind="127.0.0.1", web_port=_free_port(), grpc_port=_free_port())
    process = server._process
    before = signal.getsignal(signal.SIGINT)
    returned = threading.Event()
    stuck: list[bool] = []

    def press_ctrl_c_during_the_wait() -> None:
        while signal.getsignal(signal.SIGINT) is before:  # until the wait sets its handler
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)
        if not returned.wait(HANG_S):  # a hang guard: the server would serve on forever
            stuck.append(True)
            process.kill()

    presser = threading.Thread(target=press_ctrl_c_during_the_wait)
    presser.start()
    server.wait()
    returned.set()
    presser.join()
    assert not stuck, "Ctrl-C did not end the wait"
    assert process.poll() is not None  # the rerun server is gone
