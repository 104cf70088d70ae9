"""Bad input: real damaged files, through the API and through the command line.

Each case is a file made from a real recording (cut bytes, flipped bytes, records copied into
a new file with one thing changed) or a file that is not one of ours. The API must raise the
named error with a one-line message naming the file and the problem; ``rsstp-replay`` must
print one line on stderr, exit with 2 and never show a traceback.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import struct
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import pandas as pd
import pytest
from fakes import count_chunk_reads
from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from rsstp_format.schemas import SCHEMA_VERSION
from rsstp_replay import Recording, errors, open_recording
from rsstp_replay.export.table_files import write_table_parts
from rsstp_sim import AgentView, StrategyBase, load_scenario
from rsstp_sim.recording.recorder import record
from waiting import HANG_S

SRC = Path(__file__).resolve().parents[2] / "src"
RECORDINGS = SRC.parent / "recordings"
STEPS = 400
CHUNK_SIZE = 8 * 1024
CHUNK_DATA = 1 + 8 + 8 + 8 + 8 + 4 + 4 + len("zstd") + 8
"""Bytes from a chunk record's opcode to its compressed data."""

_NOW = f'"version": "{SCHEMA_VERSION}"'.encode()
"""How the schemas this package writes say their version."""


class Splitter(StrategyBase):
    """Random actions; splits and adds now and then, so the model messages form a chain."""

    name: ClassVar[str] = "test-splitter"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]

    def refine(self, agent: AgentView) -> None:
        if agent.step % 40 == 0 and len(agent.model) < 5:
            agent.model.split(agent.model.current)
        elif agent.step % 25 == 0:
            agent.model.add(agent.model.current, agent.model.states[0], agent.actions[0])


# ----------------------------------------------------------------------- making damage


def rewrite(
    source: Path,
    target: Path,
    *,
    schema: Callable[[str, bytes], bytes] = lambda name, data: data,
    message: Callable[[str, int, bytes], bytes | None] = lambda topic, log_time, data: data,
    attachment: Callable[[bytes], bytes] = lambda data: data,
    retime: Callable[[str, int], int] = lambda topic, log_time: log_time,
    metadata: Callable[[dict[str, str]], dict[str, str]] = lambda values: values,
) -> Path:
    """Copy a recording record by record into a new finished file, changing what is asked
    (``message`` returning None drops the message; ``retime`` gives a message's new log
    time)."""
    with open(source, "rb") as stream, open(target, "wb") as out:
        reader = make_reader(stream)
        summary = reader.get_summary()
        assert summary is not None
        writer = Writer(out, chunk_size=CHUNK_SIZE, compression=CompressionType.ZSTD)
        writer.start(profile="", library="test rewrite")
        schema_ids = {
            sid: writer.register_schema(s.name, s.encoding, schema(s.name, s.data))
            for sid, s in summary.schemas.items()
        }
        channel_ids = {
            cid: writer.register_channel(c.topic, c.message_encoding, schema_ids[c.schema_id])
            for cid, c in summary.channels.items()
        }
        for found_metadata in reader.iter_metadata():
            writer.add_metadata(found_metadata.name, metadata(dict(found_metadata.metadata)))
        for found in reader.iter_attachments():
            writer.add_attachment(
                found.log_time,
                found.create_time,
                found.name,
                found.media_type,
                attachment(found.data),
            )
        for _, channel, msg in reader.iter_messages(log_time_order=False):
            data = message(channel.topic, msg.log_time, msg.data)
            if data is not None:
                at = retime(channel.topic, msg.log_time)
                writer.add_message(channel_ids[channel.id], at, data, at)
        writer.finish()
    return target


def flip(source: Path, target: Path, offset: int) -> Path:
    data = bytearray(source.read_bytes())
    data[offset] ^= 0xFF
    target.write_bytes(bytes(data))
    return target


def chunk_offsets(path: Path) -> list[int]:
    with open(path, "rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    return sorted(index.chunk_start_offset for index in summary.chunk_indexes)


def in_compressed_data(path: Path, chunk: int) -> int:
    """A byte in the middle of the compressed data of the chunk at offset ``chunk``."""
    data = path.read_bytes()
    (length,) = struct.unpack_from("<Q", data, chunk + CHUNK_DATA - 8)
    return chunk + CHUNK_DATA + length // 2


def summary_start(path: Path) -> int:
    data = path.read_bytes()
    (start,) = struct.unpack_from("<Q", data, len(data) - 8 - 20)
    return int(start)


def foreign_mcap(target: Path) -> Path:
    with open(target, "wb") as out:
        writer = Writer(out)
        writer.start(profile="", library="another tool")
        schema = writer.register_schema("camera.Frame", "jsonschema", b'{"type": "object"}')
        channel = writer.register_channel("/camera", "json", schema)
        writer.add_message(channel, 0, b'{"pixels": []}', 0)
        writer.finish()
    return target


def edit_json(topic: str, step: int, change: Callable[[dict[str, Any]], None]) -> Any:
    """A ``message`` callback for :func:`rewrite` that edits one message of ``topic``."""

    def edit(found: str, log_time: int, data: bytes) -> bytes:
        if found != topic or log_time != step * 1_000_000:
            return data
        value = json.loads(data)
        change(value)
        return json.dumps(value, separators=(",", ":")).encode()

    return edit


# ---------------------------------------------------------------------------- the cases


@dataclass(frozen=True)
class Case:
    """A damaged file, what the API raises (and how it is reached), what the CLI runs."""

    error: type[errors.ReplayError]
    match: str
    reach: Callable[[Recording], object] | None = None
    """``None``: open_recording raises; else this raises on the opened recording."""
    command: tuple[str, ...] = ("info",)


CASES: dict[str, Case] = {
    "missing": Case(errors.NotARecording, r"missing\.mcap: no such file"),
    "directory": Case(errors.NotARecording, r"directory\.mcap: is a directory, not a recording"),
    "empty": Case(errors.NotARecording, r"empty\.mcap: the file is empty, not an MCAP recording"),
    "text": Case(errors.NotARecording, r"text\.mcap: not an MCAP file \(it does not start with"),
    "foreign": Case(
        errors.ForeignRecording,
        r"foreign\.mcap: an MCAP file, but not an rsstp recording: none of the topics "
        r"/rsstp/scenario, /rsstp/step, /rsstp/model, /rsstp/event \(its topics: /camera\)",
    ),
    "version1": Case(
        errors.UnsupportedVersion,
        r"version1\.mcap: channel /rsstp/step: schema rsstp\.Step version 1\.0 is not "
        r"supported \(this reader understands 2\.x and 3\.x; re-record the run with "
        r"rsstp-sim record: its scenario\.toml is attached\)",
    ),
    "in-magic": Case(
        errors.CorruptRecording, r"in-magic\.mcap: truncated: the file ends at byte 5"
    ),
    "in-header": Case(
        errors.CorruptRecording,
        r"in-header\.mcap: the file was not finished and holds no complete chunk "
        r"\(read \d+ of 40 bytes\): nothing to recover",
    ),
    "chunk-flip": Case(
        errors.CorruptRecording,
        r"chunk-flip\.mcap: the chunk at byte \d+ (fails its CRC check|does not decompress)",
        reach=Recording.steps,
        command=("table", "-o", "{tmp}/chunk-flip.parquet"),
    ),
    "first-chunk-flip": Case(
        errors.CorruptRecording,
        r"first-chunk-flip\.mcap: the chunk at byte \d+ (fails its CRC check|does not decompress)",
    ),
    "summary-flip": Case(
        errors.CorruptRecording,
        r"summary-flip\.mcap: the summary section \(bytes \d+ to \d+\) fails its CRC check: "
        r"expected 0x[0-9a-f]{8}, computed 0x[0-9a-f]{8}",
    ),
    "bad-step": Case(
        errors.CorruptRecording,
        r"bad-step\.mcap: the step message at step 17 \(chunk at byte \d+\) is invalid: "
        r"agent\.action: expected `int \| null`, got `float`",
        reach=Recording.memory,
        command=("compare", "1", "2"),
    ),
    "step-gap": Case(
        errors.CorruptRecording,
        r"step-gap\.mcap: step 50: expected step 50 in this place, found step 51",
        reach=Recording.steps,
        command=("table", "-o", "{tmp}/step-gap.csv"),
    ),
    "broken-chain": Case(
        errors.CorruptRecording,
        r"broken-chain\.mcap: model version \d+ \(step \d+\): its operations applied to "
        r"version \d+ do not give its snapshot \(transitions differ",
        reach=Recording.model_versions,
        command=("audit",),
    ),
    "other-scenario": Case(
        errors.CorruptRecording,
        r"other-scenario\.mcap: the /rsstp/scenario message's sha256 is [0-9a-f]{64}, but the "
        r"scenario\.toml attachment hashes to [0-9a-f]{64}",
    ),
    "step-out-of-range": Case(
        errors.StepOutOfRange,
        r"step-out-of-range\.mcap: (step|compare M =) 401 is out of range: the recording "
        r"has steps 0 to 400",
        reach=lambda recording: recording.model_at(STEPS + 1),
        command=("compare", "0", "401"),
    ),
}


@pytest.fixture(scope="module")
def original(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("original") / "run.mcap"
    record(
        path, load_scenario("three-joint"), Splitter(), steps=STEPS, seed=5, chunk_size=CHUNK_SIZE
    )
    return path


@pytest.fixture(scope="module")
def damaged(tmp_path_factory: pytest.TempPathFactory, original: Path) -> dict[str, Path]:
    """One file per case of :data:`CASES`, in one directory."""
    folder = tmp_path_factory.mktemp("damaged")
    files = {name: folder / f"{name}.mcap" for name in CASES}
    files["directory"].mkdir()
    files["empty"].write_bytes(b"")
    files["text"].write_text("step,action\n0,\n", encoding="utf-8")
    foreign_mcap(files["foreign"])

    def version1(name: str, data: bytes) -> bytes:
        return data.replace(_NOW, b'"version": "1.0"') if name == "rsstp.Step" else data

    rewrite(original, files["version1"], schema=version1)
    raw = original.read_bytes()
    files["in-magic"].write_bytes(raw[:5])
    files["in-header"].write_bytes(raw[:40])
    offsets = chunk_offsets(original)
    flip(original, files["chunk-flip"], in_compressed_data(original, offsets[len(offsets) // 2]))
    flip(original, files["first-chunk-flip"], in_compressed_data(original, offsets[0]))
    flip(original, files["summary-flip"], summary_start(original) + 40)

    def set_action(step: dict[str, Any]) -> None:
        step["agent"]["action"] = 1.5

    rewrite(original, files["bad-step"], message=edit_json("/rsstp/step", 17, set_action))

    def drop_step_50(topic: str, log_time: int, data: bytes) -> bytes | None:
        return None if topic == "/rsstp/step" and log_time == 50_000_000 else data

    rewrite(original, files["step-gap"], message=drop_step_50)
    with open_recording(original) as recording:
        changed = recording.model_versions()[2]

    def drop_transition(model: dict[str, Any]) -> None:
        """The change made a keyframe whose snapshot lacks one of the version's transitions."""
        model.pop("keyframe", None)
        model["states"] = list(changed.states)
        whole = changed.transitions
        columns = {"source": whole.source, "action": whole.action, "target": whole.target}
        model["transitions"] = {k: list(v)[1:] for k, v in columns.items()}
        model["deterministic"], model["nondeterministic_pairs"] = _determinism(model)

    rewrite(
        original,
        files["broken-chain"],
        message=edit_json("/rsstp/model", changed.step, drop_transition),
    )
    rewrite(original, files["other-scenario"], attachment=lambda data: data + b"\n# edited\n")
    files["step-out-of-range"].write_bytes(raw)
    return files


def _determinism(model: dict[str, Any]) -> tuple[bool, int]:
    pairs: dict[tuple[int, int], int] = {}
    transitions = model["transitions"]
    for pair in zip(transitions["source"], transitions["action"], strict=True):
        pairs[pair] = pairs.get(pair, 0) + 1
    count = sum(1 for n in pairs.values() if n > 1)
    return count == 0, count


# ---------------------------------------------------------------------------- the API


@pytest.mark.parametrize("name", list(CASES))
def test_api_raises_a_one_line_error(name: str, damaged: dict[str, Path]) -> None:
    case = CASES[name]
    with pytest.raises(case.error, match=case.match) as caught:
        if case.reach is None:
            open_recording(damaged[name])
        else:
            with open_recording(damaged[name]) as recording:
                case.reach(recording)
    assert "\n" not in str(caught.value)
    assert str(damaged[name]) in str(caught.value)


def test_a_later_minor_version_with_new_fields_is_read(original: Path, tmp_path: Path) -> None:
    def minor(name: str, data: bytes) -> bytes:
        return data.replace(_NOW, b'"version": "2.99"')

    def extra_fields(topic: str, log_time: int, data: bytes) -> bytes:
        value = json.loads(data)
        value["added_in_2_3"] = {"anything": [1, 2]}
        if topic == "/rsstp/step":
            value["agent"]["confidence"] = 0.5
            value["truth"]["velocity"] = [0.0, 0.0]
        return json.dumps(value, separators=(",", ":")).encode()

    newer = rewrite(original, tmp_path / "newer.mcap", schema=minor, message=extra_fields)
    with open_recording(newer) as recording, open_recording(original) as before:
        assert recording.schema_versions["rsstp.Step"] == "2.99"
        assert recording.memory() == before.memory()
        assert recording.steps().equals(before.steps())
        assert recording.events().equals(before.events())
        assert recording.model_at(STEPS) == before.model_at(STEPS)


def test_a_bit_flip_in_a_chunk_spares_the_chunks_before_it(damaged: dict[str, Path]) -> None:
    recording = open_recording(damaged["chunk-flip"])
    assert recording.model_at(0).version >= 0  # the first chunks read fine
    with pytest.raises(errors.CorruptRecording, match="chunk at byte"):
        recording.memory()


def test_an_event_of_an_unknown_kind_is_refused(original: Path, tmp_path: Path) -> None:
    with open_recording(original) as recording:
        step = int(recording.events()["step"].iloc[0])

    def explode(event: dict[str, Any]) -> None:
        event["kind"] = "explosion"

    bad = rewrite(
        original, tmp_path / "bad-event.mcap", message=edit_json("/rsstp/event", step, explode)
    )
    with open_recording(bad) as recording:
        with pytest.raises(
            errors.CorruptRecording,
            match=rf"bad-event\.mcap: the /rsstp/event message at step {step} \(chunk at byte "
            r"\d+\) is invalid: rsstp\.Event: kind: invalid enum value 'explosion'",
        ):
            recording.events()


def test_the_model_at_a_step_reads_that_steps_message_alone(original: Path, tmp_path: Path) -> None:
    """``model_at`` decodes only the message of the step asked for: a step whose message is
    invalid is named when asked for, and a step beside it in the same chunk still reads."""
    step = STEPS // 2

    def unhinge(message: dict[str, Any]) -> None:
        message["agent"]["internal_state"] = "here"

    bad = rewrite(
        original, tmp_path / "bad-step.mcap", message=edit_json("/rsstp/step", step, unhinge)
    )
    with open_recording(bad) as recording, open_recording(original) as before:
        assert recording.model_at(step + 1) == before.model_at(step + 1)
        with pytest.raises(
            errors.CorruptRecording,
            match=rf"bad-step\.mcap: the step message at step {step} \(chunk at byte \d+\) is "
            r"invalid: .*internal_state",
        ):
            recording.model_at(step)


# ------------------------------------------------------------------------ the command line


@pytest.fixture(scope="module")
def cli_runs(damaged: dict[str, Path]) -> dict[str, subprocess.CompletedProcess[str]]:
    """``python -m rsstp_cli.replay`` on every damaged file, all at once (they take a while)."""
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    folder = damaged["text"].parent
    processes = {}
    for name, case in CASES.items():
        command, *options = case.command
        argv = [command, str(damaged[name]), *(o.format(tmp=folder) for o in options)]
        processes[name] = subprocess.Popen(
            [sys.executable, "-m", "rsstp_cli.replay", *argv],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
    runs = {}
    for name, process in processes.items():
        stdout, stderr = process.communicate(timeout=HANG_S)
        runs[name] = subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)
    return runs


@pytest.mark.parametrize("name", list(CASES))
def test_cli_prints_one_line_and_exits_with_2(
    name: str, cli_runs: dict[str, subprocess.CompletedProcess[str]], damaged: dict[str, Path]
) -> None:
    run = cli_runs[name]
    assert "Traceback" not in run.stderr
    assert run.returncode == 2, run.stderr
    lines = run.stderr.splitlines()
    assert len(lines) == 1, run.stderr
    assert lines[0].startswith("rsstp-replay: error: ")
    assert str(damaged[name]) in lines[0]
    assert re.search(CASES[name].match, lines[0]), lines[0]


def test_a_table_streamed_from_a_recording_broken_at_its_end_is_not_kept(
    damaged: dict[str, Path], tmp_path: Path
) -> None:
    """The steps are checked as a whole once all are read: the parts written before the
    check found the gap are dropped, and the old table stays."""
    out = tmp_path / "steps.parquet"
    out.write_bytes(b"old")
    with open_recording(damaged["step-gap"]) as recording:
        with pytest.raises(errors.CorruptRecording, match=r"step 50: expected step 50"):
            write_table_parts(recording.step_parts(10), out)
    assert out.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["steps.parquet"]


def test_a_message_index_that_points_elsewhere_is_refused(original: Path, tmp_path: Path) -> None:
    """A finished file's steps are found through each chunk's message index; an index entry
    that does not point at a step message (here: moved by one byte) is one clear error."""
    from rsstp_replay.reader._container import open_container

    container = open_container(original)
    ref = container.chunks[1]
    with open_recording(original) as recording:
        step_channel = recording._file.channels["/rsstp/step"]
    assert ref.indexes is not None
    at = ref.indexes[step_channel]
    raw = bytearray(original.read_bytes())
    entry = at + 15 + 8  # the first entry's offset field (after opcode, length, channel, size)
    offset = int.from_bytes(raw[entry : entry + 8], "little")
    raw[entry : entry + 8] = (offset + 1).to_bytes(8, "little")
    bad = tmp_path / "moved-index.mcap"
    bad.write_bytes(bytes(raw))
    with open_recording(bad) as recording, pytest.raises(errors.CorruptRecording) as caught:
        recording.steps()
    assert re.fullmatch(
        rf"{re.escape(str(bad))}: the message index of the chunk at byte {ref.offset} does "
        rf"not point at messages of channel {step_channel}",
        str(caught.value),
    )


def test_info_never_calls_a_file_with_a_failing_chunk_finished(damaged: dict[str, Path]) -> None:
    """A finished file whose middle chunk fails its CRC: `info` reads every chunk, so it is
    one line and exit 2, not "finished"."""
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "info", str(damaged["chunk-flip"])],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert done.returncode == 2
    assert "finished" not in done.stdout
    assert re.fullmatch(
        r"rsstp-replay: error: .*chunk-flip\.mcap: the chunk at byte \d+ "
        r"(fails its CRC check|does not decompress).*\n",
        done.stderr,
    )


def test_model_messages_written_another_way_read_the_same(original: Path, tmp_path: Path) -> None:
    """Model messages spaced out and with their keys in reverse order are not the bytes the
    recorder writes, so none is read by its head alone: each is decoded whole and compared
    value by value, and the versions are the original's."""

    def respace(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/model":
            return data
        value = json.loads(data)
        return json.dumps(dict(reversed(list(value.items()))), indent=1).encode()

    spaced = rewrite(original, tmp_path / "spaced.mcap", message=respace)

    def versions(path: Path) -> list[tuple[object, ...]]:
        with open_recording(path) as recording:
            return [
                (v.version, v.step, tuple(v.states), v.current, v.triples(), v.operations)
                for v in recording.model_versions()
            ]

    assert len(versions(original)) >= 5  # the splitter's versions, each read whole
    assert versions(spaced) == versions(original)


def test_step_messages_written_another_way_read_the_same(original: Path, tmp_path: Path) -> None:
    """Step messages spaced out and with their keys in reverse order (nested objects too) are
    not the bytes the recorder writes: the steps table is still the original's, value for
    value."""

    def reverse(value: object) -> object:
        if isinstance(value, dict):
            return {key: reverse(value[key]) for key in reversed(list(value))}
        if isinstance(value, list):
            return [reverse(item) for item in value]
        return value

    def respace(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/step":
            return data
        return json.dumps(reverse(json.loads(data)), indent=1).encode()

    spaced = rewrite(original, tmp_path / "spaced.mcap", message=respace)
    with open_recording(original) as recording:
        expected = recording.steps()
    with open_recording(spaced) as recording:
        found = recording.steps()
    pd.testing.assert_frame_equal(found, expected)


# ------------------------------------------------------------------ the metadata checksum

CHECKSUM_KEY = "metadata_sha256"


def _documented_checksum(values: dict[str, str]) -> str:
    """schemas/README.md's rule, written out here: SHA-256 of the other keys as one JSON
    object, keys sorted, no spaces, UTF-8."""
    others = {key: value for key, value in values.items() if key != CHECKSUM_KEY}
    text = json.dumps(others, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _metadata_values(path: Path) -> dict[str, str]:
    with open(path, "rb") as stream:
        (found,) = make_reader(stream).iter_metadata()
    return dict(found.metadata)


@pytest.mark.parametrize("path", sorted(RECORDINGS.glob("*.mcap")), ids=lambda p: p.stem)
def test_every_reference_recording_carries_the_documented_checksum(path: Path) -> None:
    values = _metadata_values(path)
    assert list(values)[-1] == CHECKSUM_KEY
    assert values[CHECKSUM_KEY] == _documented_checksum(values)
    with open_recording(path) as recording:
        assert recording.metadata_verified


def _change_one_byte(raw: bytes, key: str, value: str, *, in_key: bool) -> bytes:
    """``raw`` with one byte of the metadata record's ``key`` (or of its value) changed, the
    record staying well-formed MCAP: a character becomes another of the same size."""
    encoded = struct.pack("<I", len(key)) + key.encode() + struct.pack("<I", len(value))
    at = raw.index(encoded + value.encode())
    assert raw.count(encoded + value.encode()) == 1
    at += 4 + (len(key) - 1 if in_key else len(key) + 4)
    changed = bytearray(raw)
    changed[at] = ord("0") if changed[at] != ord("0") else ord("1")
    return bytes(changed)


@pytest.mark.parametrize(
    ("key", "in_key", "match"),
    [
        ("seed", False, "fails its checksum"),
        ("package_version", False, "fails its checksum"),
        ("strategy_params", False, "fails its checksum"),
        ("scenario_sha256", False, "fails its checksum"),
        (CHECKSUM_KEY, False, "fails its checksum"),
        ("python", True, "fails its checksum"),
        (CHECKSUM_KEY, True, "lacks its checksum metadata_sha256"),
    ],
    ids=lambda v: v if isinstance(v, str) and " " not in v else None,
)
def test_a_metadata_record_changed_by_one_byte_is_refused(
    original: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    key: str,
    in_key: bool,
    match: str,
) -> None:
    """Every command that opens the file (check, audit, info) refuses it in one line; the
    summary's CRC does not cover the data section, so only the checksum can tell."""
    from rsstp_cli.replay import main

    values = _metadata_values(original)
    bad = tmp_path / "changed.mcap"
    bad.write_bytes(_change_one_byte(original.read_bytes(), key, values[key], in_key=in_key))
    with open(bad, "rb") as stream:  # still well-formed MCAP, the record changed
        (found,) = make_reader(stream).iter_metadata()
    assert dict(found.metadata) != values
    for command in ("check", "audit", "info"):
        assert main([command, str(bad)]) == 2
        out, err = capsys.readouterr()
        assert len(err.splitlines()) == 1, err
        assert err.startswith(f"rsstp-replay: error: {bad}: the 'rsstp' metadata record {match}")


def _older(values: dict[str, str]) -> dict[str, str]:
    return {key: value for key, value in values.items() if key != CHECKSUM_KEY}


def _to_version(version: str) -> Callable[[str, bytes], bytes]:
    def schema(name: str, data: bytes) -> bytes:
        return data.replace(_NOW, f'"version": "{version}"'.encode())

    return schema


def test_an_older_recording_without_a_checksum_is_read_unverified(
    original: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A 2.1 file was written before the checksum: it is read, and `check` and `info` say its
    metadata is unverified; a 2.2 file without its checksum is refused."""
    from rsstp_cli.replay import main

    old = rewrite(original, tmp_path / "old.mcap", schema=_to_version("2.1"), metadata=_older)
    with open_recording(old) as recording:
        assert not recording.metadata_verified
        assert recording.metadata == _older(_metadata_values(original))
    unverified = "metadata: unverified (a schema 2.1 recording, written before the metadata "
    for command in ("check", "info"):
        assert main([command, str(old)]) == 0
        out, err = capsys.readouterr()
        assert err == ""
        assert unverified in out
    assert main(["check", str(old), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["metadata_verified"] is False
    assert main(["check", str(original), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["metadata_verified"] is True

    stripped = rewrite(original, tmp_path / "stripped.mcap", metadata=_older)
    with pytest.raises(errors.CorruptRecording, match="lacks its checksum metadata_sha256"):
        open_recording(stripped)

    def wrong(values: dict[str, str]) -> dict[str, str]:
        return {**values, "seed": "7"}

    changed_old = rewrite(original, tmp_path / "old-changed.mcap", schema=_to_version("2.1"),
                          metadata=wrong)  # fmt: skip
    with pytest.raises(errors.CorruptRecording, match="fails its checksum"):
        open_recording(changed_old)  # a checksum present is verified, whatever the version


def test_a_recording_whose_numbers_another_geometry_made_opens_and_physics_names_the_step(
    original: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The reader returns what the file holds: a tip moved by 1e-9 (as a geometry fix would
    move it) opens, its steps table shows the file's number, and the physics check names the
    first step that differs."""
    from rsstp_cli.replay import main

    def move_the_tip(step: dict[str, Any]) -> None:
        step["truth"]["joint_positions"][-1]["x"] += 1e-9

    moved = rewrite(
        original, tmp_path / "moved.mcap", message=edit_json("/rsstp/step", 0, move_the_tip)
    )
    with open_recording(original) as recording:
        before = recording.steps()
    with open_recording(moved) as recording:
        after = recording.steps()
    n = sum(1 for c in before.columns if c.startswith("joint") and c.endswith("_x")) - 1
    tip = f"joint{n}_x"
    assert after.at[0, tip] == before.at[0, tip] + 1e-9  # the file's number, not a recomputed one
    capsys.readouterr()
    assert main(["check", str(moved), "--physics"]) == 1
    out = capsys.readouterr().out
    assert f"physics: broken at step 0, truth.joint_positions[{n}].x: recorded" in out


def test_the_audits_read_the_model_messages_with_the_steps_and_name_a_bad_step_first(
    original: Path, damaged: dict[str, Path], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The audits read the model messages in the pass that decodes the steps (each chunk
    read once): the versions are those read on their own, a broken chain is named as there,
    and a file with a broken chain and, later, a bad step names the step, as when the model
    messages were read after the steps."""
    from rsstp_replay.audits.loaded import load

    with open_recording(original) as alone:
        versions = alone.model_versions()
    read = count_chunk_reads(monkeypatch)
    with open_recording(original) as together:
        loaded = load(together)
        assert together.model_versions() is loaded.model_versions()
        assert list(loaded.model_versions()) == list(versions)  # every version whole
    assert sorted(read) == sorted(set(read)) == chunk_offsets(original)
    with open_recording(damaged["broken-chain"]) as recording:
        with pytest.raises(errors.CorruptRecording, match=CASES["broken-chain"].match):
            load(recording)

    def set_late_action(step: dict[str, Any]) -> None:
        step["agent"]["action"] = 1.5

    both = rewrite(
        damaged["broken-chain"],
        tmp_path / "both.mcap",
        message=edit_json("/rsstp/step", STEPS - 3, set_late_action),
    )
    with open_recording(both) as recording:
        with pytest.raises(errors.CorruptRecording, match=f"at step {STEPS - 3} "):
            load(recording)
