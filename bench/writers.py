"""Which MCAP writer should the recorder use? The candidates, on the recorder's real messages.

    python bench/writers.py [--steps 200000]      # needs: pip install foxglove-sdk

The messages are those of a real recording (``rsstp-sim record three-joint --strategy random
--seed 1``, its ``/rsstp/step`` messages and the others, in file order), written again by:

- ``rsstp chunked``: the recorder's own writer (``rsstp_sim.recording.chunks``, the ``mcap``
  ``Writer``'s bytes from encoded messages, each chunk's CRC, zstd and write on a second
  thread), one ``add_message`` per message, as the recorder does since 2026-11-26;
- ``mcap``: the Python ``mcap`` library's ``Writer.add_message``, one call per message, as the
  recorder did before;
- ``foxglove-sdk``: the Rust writer of the ``foxglove-sdk`` package (``foxglove.open_mcap``
  with its own context, one ``Channel.log`` per message, multithreaded compression off),
  writing through a Python file object so that every finished chunk reaches the OS as the
  recorder needs for crash safety.

For each: microseconds per message (best of ``--repeat``), file size, whether two runs give
the same bytes (a recording must be reproducible), how many writes reach the file object per
chunk, and whether the ``mcap`` reader reads every message back unchanged.
"""

from __future__ import annotations

import argparse
import hashlib
import io
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from _recordings import random_three_joint
from rsstp_sim.recording.chunks import ChunkedWriter
from rsstp_sim.recording.output import SideFileWriter

BIN = Path(sys.executable).parent
CHUNK = 1024 * 1024
Message = tuple[str, int, bytes]  # topic, log time (ns), data


class CountingFile:
    """A write-through file (no user-space buffer, as the recorder writes), counting writes."""

    def __init__(self, path: Path) -> None:
        self._raw = io.FileIO(path, "w")
        self.writes = 0

    def write(self, data: bytes | bytearray | memoryview) -> int:
        self.writes += 1
        view = memoryview(data)
        while view:
            view = view[self._raw.write(view) or 0 :]
        return len(data)

    def tell(self) -> int:
        return self._raw.tell()

    def seek(self, offset: int, whence: int = 0) -> int:  # the foxglove writer seeks
        return self._raw.seek(offset, whence)

    def flush(self) -> None:
        return None

    def close(self) -> None:
        self._raw.close()


class CountingSideFile(SideFileWriter):
    """The recorder's side file writer, counting the writes."""

    def __init__(self, path: Path) -> None:
        super().__init__(io.FileIO(path, "w"))
        self.writes = 0

    def _write(self, data: bytes, mark: int) -> None:
        self.writes += 1
        super()._write(data, mark)


def messages_of(steps: int) -> tuple[list[Message], dict[str, tuple[str, bytes]]]:
    path = random_three_joint(steps)
    found: list[Message] = []
    schemas: dict[str, tuple[str, bytes]] = {}
    with open(path, "rb") as stream:
        for schema, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            schemas[channel.topic] = (schema.name, schema.data)
            found.append((channel.topic, message.log_time, message.data))
    return found, schemas


def _channels(
    writer: ChunkedWriter | Writer, schemas: dict[str, tuple[str, bytes]]
) -> dict[str, int]:
    """Each topic's channel, with its schema, registered in the recording's order."""
    return {
        topic: writer.register_channel(
            topic, "json", writer.register_schema(name, "jsonschema", data)
        )
        for topic, (name, data) in schemas.items()
    }


def write_chunked(
    path: Path, messages: list[Message], schemas: dict[str, tuple[str, bytes]]
) -> int:
    out = CountingSideFile(path)
    writer = ChunkedWriter(out, chunk_size=CHUNK)
    writer.start(profile="", library="bench")
    channels = _channels(writer, schemas)
    add = writer.add_message
    for topic, log_time, data in messages:
        add(channels[topic], log_time, data)
    writer.finish()
    out.close()
    return out.writes


def write_mcap(path: Path, messages: list[Message], schemas: dict[str, tuple[str, bytes]]) -> int:
    out = CountingFile(path)
    writer = Writer(out, chunk_size=CHUNK, compression=CompressionType.ZSTD)  # type: ignore[arg-type]
    writer.start(profile="", library="bench")
    channels = _channels(writer, schemas)
    add = writer.add_message
    for topic, log_time, data in messages:
        add(channels[topic], log_time, data, log_time)
    writer.finish()
    out.close()
    return out.writes


def write_foxglove(
    path: Path, messages: list[Message], schemas: dict[str, tuple[str, bytes]]
) -> int:
    import foxglove
    from foxglove import mcap as fmcap

    out = CountingFile(path)
    context = foxglove.Context()
    writer = foxglove.open_mcap(
        out,
        context=context,
        writer_options=fmcap.MCAPWriteOptions(chunk_size=CHUNK, compression_threads=0),
    )
    channels = {
        topic: foxglove.Channel(
            topic,
            schema=foxglove.Schema(name=name, encoding="jsonschema", data=data),
            message_encoding="json",
            context=context,
        )
        for topic, (name, data) in schemas.items()
    }
    logs = {topic: channel.log for topic, channel in channels.items()}
    for topic, log_time, data in messages:
        logs[topic](data, log_time=log_time)
    writer.close()
    out.close()
    return out.writes


def read_back(path: Path) -> list[Message]:
    with open(path, "rb") as stream:
        return [
            (channel.topic, message.log_time, message.data)
            for _, channel, message in make_reader(stream).iter_messages(log_time_order=False)
        ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", type=int, default=200_000)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    messages, schemas = messages_of(args.steps)
    print(f"{len(messages):,} messages ({args.steps:,} steps of three-joint, random)")
    writers: dict[str, Callable[[Path, list[Message], dict[str, tuple[str, bytes]]], int]] = {
        "rsstp chunked": write_chunked,
        "mcap": write_mcap,
        "foxglove-sdk": write_foxglove,
    }
    with tempfile.TemporaryDirectory() as folder:
        for name, write in writers.items():
            try:
                digests, times = set(), []
                for run in range(args.repeat):
                    path = Path(folder) / f"{name}-{run}.mcap"
                    began = time.perf_counter()
                    writes = write(path, messages, schemas)
                    times.append(time.perf_counter() - began)
                    digests.add(hashlib.sha256(path.read_bytes()).hexdigest())
            except ImportError as exc:
                print(f"{name:<13} not installed ({exc})")
                continue
            chunks = max(1, sum(len(data) for _, _, data in messages) // CHUNK)
            same = read_back(path) == messages
            print(
                f"{name:<13} {min(times) / len(messages) * 1e6:5.2f} us/message, "
                f"{path.stat().st_size / (args.steps + 1):5.1f} bytes/step, "
                f"{'same bytes every run' if len(digests) == 1 else 'DIFFERENT bytes per run'}, "
                f"~{writes / chunks:.0f} writes per chunk, "
                f"read back {'unchanged' if same else 'CHANGED'}"
            )


if __name__ == "__main__":
    main()
