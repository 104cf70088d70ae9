"""Only regular files, written whole: what this project reads, and how it replaces a file.

A named pipe given as a scenario or a recording would block a reader forever, and a device
given as an output would be truncated or deleted on failure. Every path a command opens is
checked here first; :func:`irregular` never blocks (``stat`` does not open the file).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from rsstp_sim.errors import OutputError, UsageError

__all__ = [
    "check_output",
    "check_output_folder",
    "irregular",
    "side_file",
    "write_whole",
    "written_whole",
]


def irregular(path: str | os.PathLike[str]) -> str | None:
    """What ``path`` is when it exists and is neither a regular file nor a directory (``"a
    named pipe"``, ``"a character device"``...), else None (callers say what they say of a
    directory or a missing path)."""
    try:
        mode = os.stat(Path(path)).st_mode
    except (OSError, ValueError):
        return None
    if stat.S_ISREG(mode) or stat.S_ISDIR(mode):
        return None
    if stat.S_ISFIFO(mode):
        return "a named pipe"
    if stat.S_ISCHR(mode):
        return "a character device"
    if stat.S_ISBLK(mode):
        return "a block device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def check_output(out: Path, *, force: bool) -> None:
    """One line (:class:`~rsstp_sim.errors.UsageError`) for an output path a command must not
    or cannot write, said before any work: a directory or a device, a file that exists
    without ``force``, a folder that is missing or not writable."""
    if out.is_dir():
        raise UsageError(f"{out}: is a directory, not an output file")
    kind = irregular(out)
    if kind is not None:
        raise UsageError(f"{out}: {kind}: only a regular file is ever written or replaced")
    if out.exists() and not force:
        raise UsageError(f"{out}: already exists (use --force to overwrite)")
    check_output_folder(out)


def check_output_folder(out: Path) -> None:
    """One line when the folder ``out`` would be written in is missing or not writable."""
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        found = "is not a directory" if parent.exists() else "does not exist"
        raise UsageError(f"{out}: the output directory {parent} {found}")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise UsageError(f"{out}: the output directory {parent} is not writable")


def side_file(path: str | os.PathLike[str]) -> Path:
    """Where a file of ``path`` is written until it is whole: ``<name>.partial`` beside it."""
    out = Path(path)
    return out.with_name(f"{out.name}.partial")


@contextmanager
def written_whole(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Give the side file to write ``path`` through; once the block ends, rename it into
    place. A reader never sees a part, and a failed write (a full disk) removes the side file
    and leaves what was at ``path`` as it was: :class:`~rsstp_sim.errors.OutputError` says
    what failed, in one line."""
    out = Path(path)
    kind = irregular(out)
    if kind is not None:
        raise OutputError(f"{out}: {kind}: only a regular file is ever written or replaced")
    side = side_file(out)
    try:
        yield side
        os.replace(side, out)
    except OSError as exc:
        side.unlink(missing_ok=True)
        raise OutputError(f"{out}: cannot write: {exc.strerror or exc}") from None


def write_whole(path: str | os.PathLike[str], data: bytes) -> Path:
    """Write ``data`` to ``path`` whole (see :func:`written_whole`)."""
    with written_whole(path) as side:
        side.write_bytes(data)
    return Path(path)
