"""What both command-line programs share: one-line errors and their exit codes, progress.

Bad input is one line on stderr and exit code 2, never a traceback; an output that could
not be written whole (a full disk, a file-size limit) is one line and exit code 1; a reader
that goes away (``| head``) ends the program quietly; Ctrl-C is exit code 130. A warning,
ours or a library's, is one line in the errors' form (``PROG: warning: ...``), never Python's
warning format with its source file and line.
A long command shows a progress bar (tqdm) on stderr when stderr is a terminal,
and nothing when it is piped or redirected, or with ``--quiet``.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from collections.abc import Callable, Sequence
from typing import Any, NoReturn

from rsstp_cli.start import ctrl_c_held
from rsstp_sim.errors import OutputError, RsstpError, UsageError

__all__ = [
    "Parser",
    "Progress",
    "UsageError",
    "add_no_cache",
    "progress",
    "run_command",
    "warning_line",
]


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are :class:`UsageError` (one line, exit code 2)."""

    def error(self, message: str) -> NoReturn:
        raise UsageError(message)


class Progress:
    """A progress bar on stderr, or nothing. ``to(done)`` moves it to ``done`` units; ``stage``
    names what it is doing. Use it as a context manager: it closes (a finished bar stays)."""

    def __init__(self, total: int, what: str, unit: str, *, shown: bool) -> None:
        self._bar: Any = None
        if shown:
            from tqdm import tqdm

            try:
                with ctrl_c_held():  # a bar interrupted half-built fails in its finaliser
                    self._bar = tqdm(
                        total=total, desc=what, unit=unit, unit_scale=True, file=sys.stderr,
                        leave=False,
                    )  # fmt: skip
            except KeyboardInterrupt:  # cleared now, before the command's last line
                self.__exit__()
                raise

    def to(self, done: int) -> None:
        if self._bar is not None:
            self._bar.update(done - self._bar.n)

    def stage(self, text: str) -> None:
        if self._bar is not None:
            self._bar.set_description_str(text)

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *_: object) -> None:
        if self._bar is not None:
            self._bar.close()


def add_no_cache(parser: argparse.ArgumentParser) -> None:
    """``--no-cache``: compute the ground truth without reading or writing the truth cache
    (:mod:`rsstp_sim.truth.cache`)."""
    parser.add_argument(
        "--no-cache",
        action="store_true",
        help="compute the ground truth afresh, without the truth cache on disk",
    )


def progress(total: int, what: str, *, unit: str = "step", quiet: bool = False) -> Progress:
    """A bar of ``total`` units when stderr is a terminal and not ``quiet``; else nothing."""
    return Progress(total, what, unit, shown=not quiet and sys.stderr.isatty())


def warning_line(prog: str, message: Warning | str) -> str:
    """A warning as the command line prints it: one line, ``PROG: warning: TEXT``."""
    return f"{prog}: warning: {' '.join(str(message).split())}"


def run_command(prog: str, parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> int:
    """Parse ``argv`` and run the chosen sub-command (``args.func``); return the exit code.

    While it runs, every warning shown (which ones: the warning filters in force) is one
    :func:`warning_line` on stderr."""

    def show(message: Warning | str, *_: object, **__: object) -> None:
        print(warning_line(prog, message), file=sys.stderr)

    with warnings.catch_warnings():
        warnings.showwarning = show
        return _run_parsed(prog, parser, argv)


def _run_parsed(prog: str, parser: argparse.ArgumentParser, argv: Sequence[str] | None) -> int:
    try:
        args = parser.parse_args(argv)
        func: Callable[[argparse.Namespace], int] = args.func
        return func(args)
    except OutputError as exc:  # the disk failed, not the input
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 1
    except RsstpError as exc:
        print(f"{prog}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # The reader went away (e.g. `| head`): stop quietly, as other Unix tools do.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 141
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return 130
