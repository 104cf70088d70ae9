"""Only regular files: what this project reads, and what it ever replaces.

A named pipe given as a scenario or a recording would block a reader forever, and a device
given as an output would be truncated or deleted on failure. Every path a command opens is
checked here first; :func:`irregular` never blocks (``stat`` does not open the file).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

__all__ = ["irregular"]


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
