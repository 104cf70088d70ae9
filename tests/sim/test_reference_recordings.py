"""The committed reference recordings are exactly what the code produces now.

A change that alters them must re-record them on purpose (commands in
``recordings/README.md``). Library versions written in a file's metadata are
taken from the reference, so a newer numpy or mcap alone does not fail this. A zstd
library other than the one that made them (the lowest-floors CI run installs an older one)
compresses the same records to other bytes: then every record is compared, chunks
decompressed, and only the offsets and sizes of the compressed bytes may differ.
"""

from __future__ import annotations

import shlex
import tomllib
from pathlib import Path
from typing import Any

import pytest
import zstandard
from mcap.reader import make_reader
from mcap.records import (
    AttachmentIndex,
    ChunkIndex,
    DataEnd,
    Footer,
    MetadataIndex,
    SummaryOffset,
)
from mcap.stream_reader import StreamReader

from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.recording.recorder import record

RECORDINGS = Path(__file__).resolve().parents[2] / "recordings"
_MANIFEST = tomllib.loads((RECORDINGS / "manifest.toml").read_text())
MANIFEST: list[dict[str, Any]] = _MANIFEST["recording"]
SAME_ZSTD = ".".join(map(str, zstandard.ZSTD_VERSION)) == _MANIFEST["zstd"]
"""Whether this zstd library is the one that compressed the references."""

_WHERE_COMPRESSED = (ChunkIndex, MetadataIndex, AttachmentIndex, SummaryOffset, Footer, DataEnd)
"""The records that hold offsets or checksums of the compressed bytes."""


def records(path: Path) -> list[object]:
    """The file's records with its chunks decompressed, those of :data:`_WHERE_COMPRESSED`
    left out."""
    with path.open("rb") as f:
        return [
            record
            for record in StreamReader(f, emit_chunks=False).records
            if not isinstance(record, _WHERE_COMPRESSED)
        ]


def command(entry: dict[str, Any]) -> str:
    params = "".join(
        f" --param {key}={shlex.quote(str(value).replace(' ', ''))}"
        for key, value in entry.get("params", {}).items()
    )
    return (
        f"rsstp-sim record {entry['scenario']} --strategy {entry['strategy']}{params} "
        f"--steps {entry['steps']} --seed {entry['seed']} -o recordings/{entry['file']} --force"
    )


@pytest.mark.parametrize("entry", MANIFEST, ids=[e["file"] for e in MANIFEST])
def test_reference_recording_is_reproduced_byte_for_byte(entry: dict[str, Any], tmp_path: Path):
    reference = RECORDINGS / entry["file"]
    with reference.open("rb") as f:
        metadata = next(m.metadata for m in make_reader(f).iter_metadata() if m.name == "rsstp")
    out = tmp_path / entry["file"]
    record(
        out,
        load_scenario(entry["scenario"]),
        make_strategy(entry["strategy"], entry.get("params")),
        steps=entry["steps"],
        seed=entry["seed"],
        versions=metadata,
    )
    same = (
        out.read_bytes() == reference.read_bytes()
        if SAME_ZSTD
        else records(out) == records(reference)
    )
    assert same, (
        f"{entry['file']} differs from what the code records now; if that is intended, "
        f"re-record it: {command(entry)}"
    )


@pytest.mark.parametrize("entry", MANIFEST, ids=[e["file"] for e in MANIFEST])
def test_reference_recording_is_small_and_documented(entry: dict[str, Any]):
    assert (RECORDINGS / entry["file"]).stat().st_size < 2_000_000
    assert command(entry) in (RECORDINGS / "README.md").read_text()
