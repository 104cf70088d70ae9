"""Where both command lines start, before anything heavy is imported.

The console scripts ``rsstp-sim`` and ``rsstp-replay`` (pyproject.toml) point here rather than
at the packages' ``cli.main``: importing a package loads numpy, pandas and the rest, and a
Ctrl-C in that time would end in a traceback. From here on, a Ctrl-C at any moment is one
line and exit 130.
"""

from __future__ import annotations

import importlib
import signal
import sys

__all__ = ["rsstp_replay", "rsstp_sim"]


def _start(prog: str, module: str) -> int:
    # While the packages load, Ctrl-C is only noted: a KeyboardInterrupt raised inside an
    # extension's import comes out as that import's ImportError (numpy's does), a traceback.
    pressed: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: pressed.append(signum))
    try:
        main = importlib.import_module(module).main
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        if pressed:
            raise KeyboardInterrupt
        code: int = main()
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
    return code


def rsstp_sim() -> int:
    """``rsstp-sim``: the simulator's command line (:func:`rsstp_cli.sim.main`)."""
    return _start("rsstp-sim", "rsstp_cli.sim")


def rsstp_replay() -> int:
    """``rsstp-replay``: the replay side's command line (:func:`rsstp_cli.replay.main`)."""
    return _start("rsstp-replay", "rsstp_cli.replay")
