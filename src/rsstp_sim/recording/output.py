"""Where a recording's bytes go: a locked side file, written through, renamed when finished.

The recording is written to a side file, ``<name>.partial`` beside the output, and renamed
onto the output only when finished (by the recorder): an existing recording (``force``)
survives until the new one is whole, and nothing half written ever has the output's name.
The side file holds an exclusive lock while it is written, so a second recorder on the same
output is refused. It is written without a user-space buffer, each chunk as soon as it is
compressed, on a second thread (:class:`SideFileWriter`); after a SIGKILL, a full disk or a
file-size limit, the side file stays and a sequential reader recovers all its complete
chunks (a later recorder refuses to replace it without ``force``). Only regular files are
ever written or replaced.
"""

from __future__ import annotations

import fcntl
import io
import os
import queue
import threading
from collections.abc import Callable
from contextlib import ExitStack
from pathlib import Path

from rsstp_format.schemas import STEP_NS
from rsstp_sim.errors import RecordingError
from rsstp_sim.files import irregular, side_file
from rsstp_sim.switching import sooner_switches

__all__ = ["SideFileWriter", "open_side_file"]


class SideFileWriter:
    """Writes a recording's bytes to its side file, in order, without a user-space buffer.

    Most records are written at once (:meth:`write`). A chunk is handed over as what builds
    its bytes (:meth:`write_later`: CRC, zstd), which a second thread runs and writes while
    the run goes on: zstd and file writes release the GIL. At most one chunk is in flight,
    so the next hand-off waits for it; a SIGKILL loses at most the chunk in flight and the
    one being built, and every chunk on disk is whole, written with one ``write`` (its
    message indexes with it).

    While the thread runs, the switch interval is short (:mod:`rsstp_sim.switching`), so the
    thread gets the GIL back soon after each of its calls.

    A write error is raised by the next call (the next chunk's hand-off, at most a chunk
    later) and kept in ``error``; nothing is written after it. ``safe_steps`` is the last
    step whose messages are all in chunks on disk: the step before the latest step with a
    message in the last chunk written (a chunk ends inside a step, whose other messages
    follow in the next; a message's log time is its step's, ``step * STEP_NS``).
    """

    def __init__(self, raw: io.FileIO) -> None:
        self._raw = raw
        self._position = raw.tell()
        self.safe_steps = 0
        self.error: BaseException | None = None  # the write error, told apart from others
        self._free = threading.Semaphore(1)  # taken while a chunk is in flight
        self._jobs: queue.SimpleQueue[tuple[Callable[[int], bytes], int] | None] = (
            queue.SimpleQueue()
        )
        self._thread: threading.Thread | None = None
        self._switching = ExitStack()  # while the thread runs

    def write(self, data: bytes) -> None:
        self._wait()
        self._write(data, self.safe_steps)

    def write_later(self, build: Callable[[int], bytes], end_time: int) -> None:
        mark = max(0, end_time // STEP_NS - 1)
        self._free.acquire()  # the chunk before is written
        if self.error is not None:
            self._free.release()
            raise self.error
        if self._thread is None:
            self._thread = threading.Thread(target=self._work, name="rsstp-chunks", daemon=True)
            self._switching.enter_context(sooner_switches())
            self._thread.start()
        self._jobs.put((build, mark))

    def tell(self) -> int:
        self._wait()
        return self._position

    def _wait(self) -> None:
        """Until the chunk in flight is written; raise its error, if any."""
        with self._free:
            pass
        if self.error is not None:
            raise self.error

    def _work(self) -> None:
        while (job := self._jobs.get()) is not None:
            build, mark = job
            try:
                if self.error is None:
                    self._write(build(self._position), mark)
            except BaseException as exc:  # handed to the recording thread
                self.error = exc
            finally:
                self._free.release()

    def _write(self, data: bytes, mark: int) -> None:
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
            self._position += written
        if data:
            self.safe_steps = mark

    def close(self) -> None:
        """Stop the thread (after the chunk in flight) and close the file."""
        if self._thread is not None:
            self._jobs.put(None)
            self._thread.join()
            self._thread = None
            self._switching.close()
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
