"""A shorter switch interval while a helper thread compresses or reads beside the main one.

Recording and reading hand each chunk to a second thread: its file reads and writes, zstd
and CRC calls release the GIL, so they run beside the main thread's Python. Between those
calls the helper needs the GIL back for a moment, and while the main thread holds it that
moment lasts up to the interpreter's switch interval (``sys.setswitchinterval``, 5 ms by
default). Three such waits a chunk are longer than the main thread takes to fill the next
one, so the main thread ends up waiting for its helper at each hand-off: a third of
``record``'s time at 1,000,000 steps, a tenth of ``table``'s (``bench/record_vs_run.py``,
``bench/replay_commands.py``).

:func:`sooner_switches` holds the interval at most :data:`SWITCH_INTERVAL` while a helper
works, and puts back the one before when the last helper is done (helpers may overlap, from
several threads). Only the timing changes: no thread runs Python code at the same time as
another either way.
"""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["SWITCH_INTERVAL", "sooner_switches"]

SWITCH_INTERVAL = 0.0005
"""Seconds: the longest switch interval while a helper thread works."""

_lock = threading.Lock()
_helpers = 0  # helpers working now
_before = 0.0  # the switch interval when the first of them started


@contextmanager
def sooner_switches() -> Iterator[None]:
    """While in the block, the switch interval is at most :data:`SWITCH_INTERVAL`."""
    global _helpers, _before
    with _lock:
        if _helpers == 0:
            _before = sys.getswitchinterval()
            sys.setswitchinterval(min(_before, SWITCH_INTERVAL))
        _helpers += 1
    try:
        yield
    finally:
        with _lock:
            _helpers -= 1
            if _helpers == 0:
                sys.setswitchinterval(_before)
