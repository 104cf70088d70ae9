"""foxglove-sdk's MCAP writer, made to fail the way this project's writers fail.

The SDK's writer does not raise when a write fails: each later ``log`` call puts a warning on
the ``foxglove`` logger (one per message, so millions of lines after a full disk) and only
``close`` raises, with a message that has lost the cause. Here the file is written through a
Python file object that keeps the first :class:`OSError`; :meth:`SceneWriter.check` raises it
(as soon as the caller asks, once per step), and the SDK's warnings stay off stderr while the
file is written. The caller (:func:`rsstp_sim.files.written_whole`) turns the ``OSError`` into
one line and removes the side file.
"""

from __future__ import annotations

import errno
import io
import logging
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import foxglove
from foxglove.mcap import MCAPWriteOptions, MCAPWriter

__all__ = ["SceneWriter", "open_scene"]

_SDK_LOGGER = "foxglove"


class SceneWriter:
    """An open MCAP file: ``context`` (a Context of its own, for the channels), ``writer``
    (the SDK's ``MCAPWriter``) and :meth:`check`."""

    def __init__(self, file: _KeepsError, context: foxglove.Context, writer: MCAPWriter) -> None:
        self._file = file
        self.context = context
        self.writer = writer

    def check(self) -> None:
        """Raise the first write error, if there was one."""
        if self._file.error is not None:
            raise self._file.error


@contextmanager
def open_scene(path: Path) -> Iterator[SceneWriter]:
    """Write a new MCAP file at ``path`` (replacing what is there) and finish it when the block
    ends. A failed write raises its :class:`OSError`, from the block's next :meth:`check` or
    at the end; any other failure of the SDK's writer is an :class:`OSError` too. When the
    block or the writer fails (or Ctrl-C stops it), the unfinished file is removed."""
    try:
        with _written(path) as scene:
            yield scene
    except BaseException:
        path.unlink(missing_ok=True)
        raise


@contextmanager
def _written(path: Path) -> Iterator[SceneWriter]:
    # Zstd in the writer's own thread: the output of multithreaded zstd depends on the machine.
    options = MCAPWriteOptions(compression_threads=0)
    context = foxglove.Context()  # not the global one: nothing else logs into this file
    with io.FileIO(path, "w") as raw, _sdk_warnings_kept() as warnings:
        file = _KeepsError(raw)
        try:  # it writes the file's header at once: a full disk fails here
            writer = foxglove.open_mcap(file, context=context, writer_options=options)
        except RuntimeError as exc:
            raise file.error or OSError(f"the MCAP writer failed: {exc}") from None
        scene = SceneWriter(file, context, writer)
        try:
            yield scene
        except RuntimeError:  # an SDK call of the block, failing on a write of ours
            if file.error is not None:
                raise file.error from None
            raise
        finally:
            try:
                writer.close()
            except RuntimeError as exc:  # the SDK's own error; the cause is in file.error
                if file.error is None:
                    raise OSError(f"the MCAP writer failed: {exc}") from None
        scene.check()
        if warnings:
            raise OSError(f"the MCAP writer failed: {warnings[0]}")


class _KeepsError:
    """An unbuffered file (every write goes to the OS at once) keeping its first write error:
    what the SDK's writer needs of a file (``write``, ``seek``, ``flush``)."""

    def __init__(self, raw: io.FileIO) -> None:
        self._raw = raw
        self.error: OSError | None = None

    def write(self, data: bytes | bytearray) -> int:
        """Write all of ``data`` (a write cut short by a full disk is retried, and fails)."""
        view = memoryview(data)
        try:
            while view:
                written = self._raw.write(view)
                if not written:  # a regular file always takes some bytes or fails
                    raise OSError(errno.EIO, "the file took none of the bytes written")
                view = view[written:]
        except OSError as exc:
            if self.error is None:
                self.error = exc
            raise
        return len(data)

    def seek(self, offset: int, whence: int = 0) -> int:
        return self._raw.seek(offset, whence)

    def flush(self) -> None:
        pass  # nothing is buffered


@contextmanager
def _sdk_warnings_kept() -> Iterator[list[str]]:
    """The SDK's log records while the block runs, kept in a list instead of printed."""
    kept: list[str] = []

    class Keep(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            kept.append(record.getMessage())

    logger = logging.getLogger(_SDK_LOGGER)
    handler, propagate = Keep(logging.WARNING), logger.propagate
    logger.addHandler(handler)
    logger.propagate = False
    try:
        yield kept
    finally:
        logger.removeHandler(handler)
        logger.propagate = propagate
