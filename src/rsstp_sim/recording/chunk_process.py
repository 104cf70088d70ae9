"""A long run's chunks, built and compressed in a helper process beside the run.

Recording a step costs the Python of its message (the format, the record header, the place
in the chunk) and a share of the chunk's CRC and zstd: about as much as taking the step. In
one process all of it but zstd holds the GIL, so the run waits for it. For a long run the
recorder hands the chunk being built to a helper process (:class:`ChunkProcess`), sends it
the steps in blocks (:class:`~rsstp_sim.recording.step_messages.Block`: a plain step is four
integers), and gets the chunks back built, indexed and compressed
(:class:`~rsstp_sim.recording.chunks.PackedChunk`), which it writes where it would have
written its own (:meth:`~rsstp_sim.recording.chunks.ChunkedWriter.add_packed`): the same
bytes. The file, its lock, its write errors and what a failed run keeps stay with the
recorder; at the run's end the helper hands the chunk it was building back.

The helper is ``python -m rsstp_sim.recording.chunk_process`` on two pipes. It ignores
SIGINT and SIGTERM (Ctrl-C reaches the whole process group: the recorder ends the run, then
the helper), and it ends as soon as the recorder's end of its pipe closes, so a killed
recorder leaves no helper behind. A killed recorder loses the steps not yet back from the
helper (the blocks in the pipe and the helper's chunk: ``bench/kill_loss.py``); what it wrote
stays a readable prefix.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import pickle
import queue
import signal
import subprocess
import sys
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from multiprocessing.connection import Connection
from pathlib import Path

from rsstp_sim.errors import ChunkProcessFailed
from rsstp_sim.recording.chunks import (
    ChunkBuilder,
    OpenChunk,
    PackedChunk,
    SealedChunk,
    compressor,
    pack,
)
from rsstp_sim.recording.step_messages import Block, BlockMessages

__all__ = ["ChunkProcess"]

_PIPE_BYTES = 1 << 18
"""The pipe of blocks holds this much (some 15,000 plain steps) when the system allows it:
the run goes on while the helper catches up, and a killed recorder loses little."""


@dataclass(frozen=True, slots=True)
class _Failed:
    """What the helper says when its own code failed: the error, in one line."""

    error: str


_ENDED = object()  # the helper's pipe closed


class ChunkProcess:
    """The helper process building a run's chunks (see the module).

    Started ahead (its imports take a moment), it waits for :meth:`take_over` to give it the
    chunk being built; then :meth:`send` each block in order, and write the chunks it
    returns in order; :meth:`finish` gives the last chunks and the chunk left open.
    :meth:`close` (always) ends the helper.
    """

    def __init__(
        self, *, chunk_size: int, channels: tuple[int, int], compact: bool = False
    ) -> None:
        """Start the helper; raises ``OSError`` when no process can be started."""
        blocks_in, blocks_out = os.pipe()
        chunks_in, chunks_out = os.pipe()
        try:
            with contextlib.suppress(OSError, AttributeError):  # Linux only; a bigger buffer
                fcntl.fcntl(blocks_out, fcntl.F_SETPIPE_SZ, _PIPE_BYTES)
            self._process = subprocess.Popen(
                [sys.executable, "-m", __name__, str(blocks_in), str(chunks_out)],
                pass_fds=(blocks_in, chunks_out),
                env=_helper_environment(),
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        except BaseException:
            for fd in (blocks_out, chunks_in):
                os.close(fd)
            raise
        finally:
            for fd in (blocks_in, chunks_out):
                os.close(fd)
        self._blocks = Connection(blocks_out, readable=False)
        self._chunks = Connection(chunks_in, writable=False)
        self._back: queue.SimpleQueue[object] = queue.SimpleQueue()
        self._receiver = threading.Thread(
            target=self._receive, name="rsstp-chunk-process", daemon=True
        )
        self._receiver.start()
        self._setup = chunk_size, channels, compact

    def take_over(self, chunk: OpenChunk) -> None:
        """Give the helper the chunk being built: it goes on from there."""
        self._send((*self._setup, chunk))

    def _receive(self) -> None:
        """What the helper sends back, as it comes (so that it never waits for the run)."""
        try:
            while True:
                self._back.put(pickle.loads(self._chunks.recv_bytes()))
        except (EOFError, OSError):  # it ended
            pass
        finally:  # (whatever ended the thread: the run must not wait for more)
            self._back.put(_ENDED)

    def _send(self, item: object) -> None:
        try:
            self._blocks.send_bytes(pickle.dumps(item, pickle.HIGHEST_PROTOCOL))
        except OSError:  # its pipe closed: it ended; what it sent last says how
            self._take(until_open=True)  # (raises its failure, or its end)
            raise self._ended() from None

    def send(self, block: Block) -> list[PackedChunk]:
        """Hand ``block`` over; the chunks the helper finished since the last call."""
        self._send(block)
        return self._take(until_open=False)[0]

    def finish(self) -> tuple[list[PackedChunk], OpenChunk]:
        """The chunks still to come, and the chunk the helper leaves open."""
        self._send(None)
        chunks, chunk = self._take(until_open=True)
        assert chunk is not None  # _take returns only with it or raises
        return chunks, chunk

    def _take(self, *, until_open: bool) -> tuple[list[PackedChunk], OpenChunk | None]:
        chunks: list[PackedChunk] = []
        while True:
            try:
                item = self._back.get() if until_open else self._back.get_nowait()
            except queue.Empty:
                return chunks, None
            if isinstance(item, PackedChunk):
                chunks.append(item)
            elif isinstance(item, OpenChunk):
                return chunks, item
            elif isinstance(item, _Failed):
                raise ChunkProcessFailed(
                    f"the helper process that builds the chunks failed: {item.error}"
                )
            else:
                raise self._ended()

    def _ended(self) -> ChunkProcessFailed:
        try:
            code = self._process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            return ChunkProcessFailed("the helper process that builds the chunks stopped answering")
        how = f"signal {signal.Signals(-code).name}" if code < 0 else f"exit status {code}"
        return ChunkProcessFailed(
            f"the helper process that builds the chunks ended before the run did ({how})"
        )

    def close(self) -> None:
        """End the helper (at once, if :meth:`finish` did not) and its pipes; idempotent."""
        if self._blocks.closed:
            return
        self._blocks.close()  # the helper reads the end of its input and ends
        try:
            self._process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        self._receiver.join()
        self._chunks.close()


def _helper_environment() -> dict[str, str]:
    """This process's environment, with this package first on the helper's path: the helper
    runs the code this process runs, wherever it was imported from."""
    env = dict(os.environ)
    here = str(Path(__file__).resolve().parents[2])  # the folder that holds rsstp_sim
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [here, env.get("PYTHONPATH")]))
    return env


def _serve(blocks_fd: int, chunks_fd: int) -> int:
    """The helper: blocks in, chunks out, until the recorder says the run ended."""
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, signal.SIG_IGN)
    inbox = Connection(blocks_fd, writable=False)
    outbox = Connection(chunks_fd, readable=False)

    def send(item: object) -> None:
        outbox.send_bytes(pickle.dumps(item, pickle.HIGHEST_PROTOCOL))

    try:
        chunk_size, channels, compact, chunk = pickle.loads(inbox.recv_bytes())
        compress = compressor(compact=compact)

        def sealed(chunk: SealedChunk) -> None:
            send(pack(chunk, compress))

        builder = ChunkBuilder(chunk_size, sealed, chunk)
        builder.add_messages(BlockMessages(*channels).of(_blocks(inbox)))
        send(builder.open_chunk())
    except (EOFError, OSError):  # the recorder ended: nobody to tell
        return 1
    except BaseException as exc:  # our own code: one line for the recorder
        with contextlib.suppress(OSError):
            send(_Failed(f"{type(exc).__name__}: {exc}"))
        return 1
    return 0


def _blocks(inbox: Connection) -> Iterator[Block]:
    while (block := pickle.loads(inbox.recv_bytes())) is not None:
        yield block


if __name__ == "__main__":
    # The module under its own name (not __main__), so that what it pickles unpickles.
    from rsstp_sim.recording.chunk_process import _serve as serve

    sys.exit(serve(int(sys.argv[1]), int(sys.argv[2])))
