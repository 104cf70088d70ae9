"""Waiting in tests: for an event, never for a length of time.

No test depends on how fast the machine is. A test that needs a command to have reached a
point waits until it can see it (a file grown, a line shown, a process gone) with
:func:`wait_until`; the one time limit anywhere is :data:`HANG_S`, a guard against a deadlock
that would otherwise hang the suite, far beyond what any command here takes on a busy machine.
"""

from __future__ import annotations

import subprocess
import time
from collections.abc import Callable

import pytest

HANG_S = 600.0
"""The time after which a command or a wait is taken to hang (a deadlock, a lost signal): the
``timeout`` of every command a test runs, and of every :func:`wait_until`. Not a speed: the
longest command of the suite takes about a minute on a quiet machine."""


def wait_until(
    reached: Callable[[], bool],
    what: str,
    *,
    process: subprocess.Popen[str] | subprocess.Popen[bytes] | None = None,
) -> None:
    """Poll until ``reached()``; fail naming ``what`` when ``process`` ended first (its
    output, if piped, in the message), or after :data:`HANG_S`."""
    deadline = time.monotonic() + HANG_S
    while not reached():
        if process is not None and process.poll() is not None:
            output = process.communicate() if process.stdout or process.stderr else ""
            pytest.fail(f"{what}: the process ended first ({process.returncode}) {output}")
        if time.monotonic() > deadline:
            pytest.fail(f"{what}: not after {HANG_S:.0f} s (a hang)")
        time.sleep(0.01)  # a poll's pace, not a wait for anything
