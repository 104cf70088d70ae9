"""Where both command lines start, before anything heavy is imported.

The console scripts ``rsstp-sim`` and ``rsstp-replay`` (pyproject.toml) point here rather than
at the packages' ``cli.main``: importing a package loads numpy, pandas and the rest, and a
Ctrl-C in that time would end in a traceback. From here on, a Ctrl-C at any moment is one
line and exit 130.
"""

from __future__ import annotations

import importlib
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

__all__ = ["ctrl_c_held", "rsstp_replay", "rsstp_sim"]

THP_DEFRAG = Path("/sys/kernel/mm/transparent_hugepage/defrag")
"""The kernel's setting of when a page fault may compact memory for a transparent huge page."""


def huge_page_advice(defrag: str | None, environ: dict[str, str]) -> str | None:
    """The ``NUMPY_MADVISE_HUGEPAGE`` a command runs with: ``"0"`` where the user has not set
    it and the kernel's THP ``defrag`` setting (the file's text; None: no such file) makes a
    fault stall, else None (numpy's default stays).

    numpy asks for transparent huge pages for each array of 4 MB and more (``madvise``).
    Under ``defrag`` ``madvise`` (the kernel's default) or ``defer+madvise``, a fault in such
    an array when no huge page is free compacts memory on the spot (numpy issue 31590). The
    commands fill hundreds of megabytes of fresh arrays (a 1,000,000-step table is 31 columns
    of 8 MB): ``table`` of 1,000,000 steps took 3.06-3.29 s with the advice and 2.71-2.85 s
    without it on a 2-core machine under ``madvise`` (``bench/replay_commands.py``).
    """
    if "NUMPY_MADVISE_HUGEPAGE" in environ or defrag is None:
        return None
    chosen = defrag[defrag.find("[") + 1 : defrag.find("]")]
    return "0" if chosen in ("madvise", "defer+madvise") else None


def _read_defrag() -> str | None:
    try:
        return THP_DEFRAG.read_text()
    except OSError:  # not Linux, or no transparent huge pages
        return None


def _start(prog: str, module: str) -> int:
    advice = huge_page_advice(_read_defrag(), dict(os.environ))
    if advice is not None and "numpy" not in sys.modules:  # read when numpy is imported
        os.environ["NUMPY_MADVISE_HUGEPAGE"] = advice
    try:
        # A KeyboardInterrupt raised inside an extension's import comes out as that import's
        # ImportError (numpy's does), a traceback: while the packages load, Ctrl-C waits.
        with ctrl_c_held():
            main = importlib.import_module(module).main
        code: int = main()
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    return code


@contextmanager
def ctrl_c_held() -> Iterator[None]:
    """Ctrl-C inside the block is held until the block ends, then raised as
    :class:`KeyboardInterrupt`: for work that an interrupt would leave half done (an
    extension's import; a progress bar's construction, whose half-built object fails again
    in its finaliser). Outside the main thread, or where SIGINT is ignored, nothing changes."""
    if threading.current_thread() is not threading.main_thread() or (
        signal.getsignal(signal.SIGINT) is signal.SIG_IGN
    ):
        yield
        return
    pressed: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if pressed:
        raise KeyboardInterrupt


def rsstp_sim() -> int:
    """``rsstp-sim``: the simulator's command line (:func:`rsstp_cli.sim.main`)."""
    return _start("rsstp-sim", "rsstp_cli.sim")


def rsstp_replay() -> int:
    """``rsstp-replay``: the replay side's command line (:func:`rsstp_cli.replay.main`)."""
    return _start("rsstp-replay", "rsstp_cli.replay")
