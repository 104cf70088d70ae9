"""Graphviz in this process, from the libraries inside ``pygraphviz``'s wheel: one call lays a
DOT source out and writes it in one output format.

No Graphviz program is run and none is needed on ``PATH``: ``pygraphviz`` (a dependency of the
package) carries Graphviz's libraries with the ``dot``, ``neato``, ``sfdp`` layouts and the
``nop2`` engine (``neato -n2``: the positions given in points, as they are), and SVG, PNG, PDF
and ``plain`` output.

Graphviz's C library writes its warnings and errors straight to file descriptor 2, and the wheel
has some it prints on every call: fontconfig's complaint about a system font configuration newer
than the fontconfig it carries, and ``remove_overlap: Graphviz not built with triangulation
library``, which its ``sfdp`` (built without GTS) prints on every layout whatever the
``overlap`` setting, and which does no harm with one that needs no triangulation. So a
call takes file descriptor 2 into an unlinked temporary file while it runs: what a call that
succeeds wrote there is dropped, and a call that fails raises one :class:`GraphvizFailed` line
with the first error Graphviz gave. Calls take a lock: Graphviz's library is not thread-safe,
and file descriptor 2 is the whole process's.

Each call starts from the C library's ``rand()`` state of a process's start (``srand(1)``):
``sfdp`` draws from ``rand()`` and never seeds it, so without this a layout would depend on what
drew before in the process (the 1,183-state union of a learner's run came out differently on the
first and the second ``sfdp`` call of a process, and after any other ``rand()`` caller).

A call holds the interpreter until Graphviz returns (the library keeps the GIL): no timeout
can stop it and Ctrl-C is taken when it returns, so every layout this package asks for is
bounded by the size of its input and by Graphviz's own work limits, never by a clock (see
:func:`rsstp_replay.viewer.graph_positions`). A fatal error inside the library (it ends the
process on a failed allocation) ends the process with its message lost in the temporary file.
"""

from __future__ import annotations

import ctypes
import functools
import os
import sys
import tempfile
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO, Any

from rsstp_sim.errors import GraphvizFailed, OutputError

__all__ = ["run_graphviz"]

_LOCK = threading.Lock()
_KEPT_BYTES = 1 << 16
"""How much of what Graphviz writes to file descriptor 2 during one call is read back."""


def run_graphviz(engine: str, source: str, output_format: str, *, what: str) -> bytes:
    """``source`` laid out by ``engine`` and written as ``output_format``, in this process.

    A failure (a source Graphviz cannot read, an engine or format it does not know, a layout or
    a rendering that fails) is one :class:`GraphvizFailed` line naming ``what``, with the first
    error Graphviz wrote; nothing Graphviz writes reaches the terminal. ``pygraphviz`` hands the
    source over in a temporary file: one that cannot be written (a full disk, a file-size limit)
    is :class:`~rsstp_sim.errors.OutputError`.
    """
    with _LOCK, _captured_stderr() as messages:
        problem, data = _draw(engine, source, output_format, what=what)
    if problem is not None:
        detail = _first_error(messages) or problem
        raise GraphvizFailed(
            f"Graphviz ({engine}) failed drawing {what}: {detail}; write .dot instead to keep the "
            "graph"
        )
    return data


def _draw(engine: str, source: str, output_format: str, *, what: str) -> tuple[str | None, bytes]:
    """``(None, the output)``, or ``(what went wrong, b"")``: pygraphviz's parser, then
    Graphviz's own calls (``gvLayout``, ``gvRenderData``) on the graph it read."""
    import pygraphviz
    from pygraphviz import graphviz as gv

    try:
        graph = pygraphviz.AGraph(string=source)
    except OSError as exc:
        raise OutputError(
            f"cannot hand the DOT source of {what} to Graphviz: a temporary file could not be "
            f"written ({exc.strerror or exc})"
        ) from None
    except (ValueError, TypeError) as exc:  # pygraphviz.DotError is a ValueError
        return f"cannot read the DOT source ({exc})", b""
    context: Any = gv.gvContextWithBuiltins()
    try:
        _reseed_c_rand()
        status = gv.gvLayout(context, graph.handle, engine.encode())
        if status != 0:
            return f"the {engine} layout failed (status {status})", b""
        try:
            # [0, the bytes] when it went through, a bare status when it did not
            rendered = gv.gvRenderData(context, graph.handle, output_format.encode())
        finally:
            gv.gvFreeLayout(context, graph.handle)
        if not isinstance(rendered, list | tuple) or rendered[0] != 0:
            status = rendered[0] if isinstance(rendered, list | tuple) else rendered
            return f"writing {output_format} failed (status {status})", b""
        return None, bytes(rendered[1])
    finally:
        gv.gvFreeContext(context)
        graph.close()


def _reseed_c_rand() -> None:
    """``srand(1)``: the C library's ``rand()`` as at a process's start (not on a platform whose
    C library ctypes cannot reach)."""
    libc = _c_library()
    if libc is not None:
        libc.srand(1)


@functools.cache
def _c_library() -> ctypes.CDLL | None:
    try:
        libc = ctypes.CDLL(None)
        libc.srand.argtypes = [ctypes.c_uint]
    except (OSError, AttributeError, TypeError):
        return None
    return libc


def _first_error(messages: list[str]) -> str | None:
    """The first line of Graphviz's that says ``Error``, else its first line that is not
    fontconfig's (200 characters at most)."""
    ours = [line for line in messages if not line.startswith("Fontconfig ")]
    errors = [line for line in ours if line.lower().startswith("error")]
    chosen = errors or ours
    return chosen[0][:200] if chosen else None


@contextmanager
def _captured_stderr() -> Iterator[list[str]]:
    """What is written to file descriptor 2 while the block runs, as its non-empty lines (given
    when the block ends); nothing of it reaches the terminal."""
    messages: list[str] = []
    try:
        saved = os.dup(2)
    except OSError:  # no file descriptor 2: nothing to keep off it
        yield messages
        return
    try:
        with _sink() as sink:
            if sys.stderr is not None:
                sys.stderr.flush()  # what Python wrote before stays before
            os.dup2(sink.fileno(), 2)
            try:
                yield messages
            finally:
                os.dup2(saved, 2)
                sink.seek(0)
                text = sink.read(_KEPT_BYTES).decode(errors="replace")
                messages.extend(line.strip() for line in text.splitlines() if line.strip())
    finally:
        os.close(saved)


@contextmanager
def _sink() -> Iterator[IO[bytes]]:
    """An unlinked temporary file, or the null device when none can be made (the messages are
    then lost, not shown)."""
    try:
        stream: IO[bytes] = tempfile.TemporaryFile()
    except OSError:
        stream = open(os.devnull, "w+b")
    with stream:
        yield stream
