"""Where a recording's bytes go: a locked side file, written through, renamed when finished.

The recording is written to a side file, ``<name>.partial`` beside the output, and renamed
onto the output only when finished (by the recorder): an existing recording (``force``)
survives until the new one is whole, and nothing half written ever has the output's name.
The side file holds an exclusive lock while it is written, so a second recorder on the same
output is refused. It is written without a user-space buffer, so every chunk the writer
completes is on disk at once; after a SIGKILL, a full disk or a file-size limit, the side
file stays and a sequential reader recovers all its complete chunks (a later recorder
refuses to replace it without ``force``). Only regular files are ever written or replaced.
"""

from __future__ import annotations

import fcntl
import io
import os
from collections.abc import Callable
from pathlib import Path

from rsstp_sim.errors import RecordingError
from rsstp_sim.files import irregular, side_file

__all__ = ["WriteThrough", "open_side_file"]


class WriteThrough:
    """A write-through file for the MCAP writer: each completed chunk reaches the OS at once.

    (The writer would wrap a raw file in a ``BufferedWriter``, which could keep
    the tail of a chunk in memory when the process is killed.) ``safe_steps`` is the last
    step whose messages are all in complete chunks, as of the last write (the writer writes
    only when a chunk is complete): what a reader recovers from the file as it stands.
    """

    def __init__(self, raw: io.FileIO, steps_done: Callable[[], int]) -> None:
        self._raw = raw
        self._steps_done = steps_done
        self.safe_steps = 0
        self.error: OSError | None = None  # the write error, told apart from other OSErrors

    def write(self, data: bytes | bytearray | memoryview) -> int:
        view = memoryview(data)
        while view:
            try:
                written = self._raw.write(view)
            except OSError as exc:
                self.error = exc
                raise
            if written is None:  # pragma: no cover - only for non-blocking files
                continue
            view = view[written:]
        if data:  # the step being written may have messages after this chunk: not counted
            self.safe_steps = max(0, self._steps_done() - 1)
        return len(data)

    def tell(self) -> int:
        return self._raw.tell()

    def flush(self) -> None:
        return None

    def close(self) -> None:
        self._raw.close()


def open_side_file(path: Path, *, force: bool) -> io.FileIO:
    """Open the side file of ``path`` for writing, locked; refuse what must not be replaced."""
    parent = path.parent if str(path.parent) else Path(".")
    if path.is_dir():
        raise RecordingError(f"{path}: is a directory, not an output file")
    partial = side_file(path)
    for checked in (path, partial):
        kind = irregular(checked)
        if kind is not None:
            raise RecordingError(
                f"{checked}: {kind}: only a regular file is ever written or replaced"
            )
    if not parent.is_dir():
        found = "is not a directory" if parent.exists() else "does not exist"
        raise RecordingError(f"{path}: the output directory {parent} {found}")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise RecordingError(f"{path}: the output directory {parent} is not writable")
    if path.exists() and not force:
        raise RecordingError(
            f"{path}: already exists (use --force, or force=True in Python, to overwrite)"
        )
    try:
        fd = os.open(partial, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError as exc:
        raise RecordingError(f"{path}: cannot open for writing: {exc.strerror or exc}") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise RecordingError(
                f"{path}: another recording is being written there (its side file "
                f"{partial.name} is locked)"
            ) from None
        if os.fstat(fd).st_size and not force:
            raise RecordingError(
                f"{partial}: left by an interrupted recording; read it with rsstp-replay, "
                "move it away, or use --force (force=True in Python) to replace it"
            )
        os.ftruncate(fd, 0)
        return io.FileIO(fd, "w", closefd=True)
    except BaseException:
        os.close(fd)
        raise
