"""``rsstp-sim record`` in a real subprocess: bad input, the happy path, and crash safety.

Crash safety: a long recording with small chunks is stopped once the file has grown past a
few chunks. SIGINT and SIGTERM end the run after the current step with a finished file (exit
code 128 + signal); after SIGKILL the file has no summary, and a sequential reader recovers
the steps of every complete chunk, in order, without gaps.
"""

from __future__ import annotations

import io
import json
import os
import re
import signal
import struct
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import pytest
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Channel, Chunk, DataEnd, Footer, Message
from mcap.stream_reader import StreamReader, breakup_chunk

from rsstp_format import records, schemas
from rsstp_sim import RandomStrategy, load_scenario
from rsstp_sim.recording.recorder import record
from waiting import HANG_S, wait_until

SRC = Path(__file__).resolve().parents[2] / "src"
CHUNK_SIZE = 65536
MCAP_MAGIC = b"\x89MCAP0\r\n"


def cli_env(**extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    env.update(extra)
    return env


def rsstp_record(*args: str | Path, **env: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "record", *map(str, args)],
        env=cli_env(**env),
        capture_output=True,
        text=True,
        timeout=HANG_S,
        check=False,
    )


def assert_one_line_error(done: subprocess.CompletedProcess[str], pattern: str) -> None:
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1, done.stderr
    assert lines[0].startswith("rsstp-sim: error: ")
    assert re.search(pattern, lines[0]), lines[0]


def step_counts(path: Path) -> dict[str, int]:
    with path.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    return {c.topic: counts.get(c.id, 0) for c in summary.channels.values()}


# -------------------------------------------------------------------- bad input


def test_existing_output_without_force(tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    out.write_bytes(b"keep me")
    done = rsstp_record("three-joint", "--steps", "10", "-o", out)
    assert_one_line_error(done, re.escape(f"{out}: already exists") + r".*--force")
    assert out.read_bytes() == b"keep me"


def test_existing_output_with_force(tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    out.write_bytes(b"keep me")
    done = rsstp_record("three-joint", "--steps", "10", "-o", out, "--force")
    assert done.returncode == 0, done.stderr
    assert step_counts(out)["/rsstp/step"] == 11


def test_unwritable_output_directory(unwritable_directory: Path) -> None:
    done = rsstp_record("three-joint", "--steps", "10", "-o", unwritable_directory / "out.mcap")
    assert_one_line_error(done, rf"{re.escape(str(unwritable_directory))} is not writable")
    assert not (unwritable_directory / "out.mcap").exists()


BAD_ARGUMENTS: dict[str, tuple[list[str], str, str]] = {
    # case: (arguments before -o, output path in the case's directory, the error's pattern)
    "missing-directory": (
        ["three-joint"],
        "missing/out.mcap",
        r"output directory .*missing does not exist",
    ),
    "parent-is-a-file": (
        ["three-joint"],
        "a-file/out.mcap",
        r"output directory .*a-file is not a directory",
    ),
    "output-is-a-directory": (["three-joint", "--force"], ".", r": is a directory"),
    "chunk-size-too-small": (
        ["three-joint", "--chunk-size", "100"],
        "out.mcap",
        r"argument --chunk-size: expected at least 1024 bytes, got '100'",
    ),
    "negative-steps": (
        ["three-joint", "--steps", "-3"],
        "out.mcap",
        r"argument --steps: expected an integer >= 0, got '-3'",
    ),
    "unknown-scenario": (
        ["no-such-scenario"],
        "out.mcap",
        r"no-such-scenario: no such scenario file, and not a built-in scenario",
    ),
    "unknown-strategy": (
        ["three-joint", "--strategy", "telepathy"],
        "out.mcap",
        r"unknown strategy 'telepathy'",
    ),
    "script-action-not-in-scenario": (
        ["three-joint", "--strategy", "script", "--param", "actions=[77]"],
        "out.mcap",
        r"script: actions \[77\] are not among the scenario's actions",
    ),
}


@pytest.fixture(scope="module")
def bad_runs(
    tmp_path_factory: pytest.TempPathFactory,
) -> dict[str, tuple[Path, subprocess.CompletedProcess[str]]]:
    """Every case of :data:`BAD_ARGUMENTS`, run at once (each in its own directory)."""
    started = {}
    for case, (args, where, _) in BAD_ARGUMENTS.items():
        directory = tmp_path_factory.mktemp(case)
        (directory / "a-file").write_text("a file")
        output = str(directory / where)
        command = [sys.executable, "-m", "rsstp_cli.sim", "record", *args, "-o", output]
        proc = subprocess.Popen(
            command, env=cli_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        started[case] = (directory, proc)
    runs = {}
    for case, (directory, proc) in started.items():
        try:
            stdout, stderr = proc.communicate(timeout=HANG_S)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.communicate()
        runs[case] = (
            directory,
            subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr),
        )
    return runs


@pytest.mark.parametrize("case", BAD_ARGUMENTS)
def test_bad_arguments_one_line_and_no_file(
    bad_runs: dict[str, tuple[Path, subprocess.CompletedProcess[str]]], case: str
) -> None:
    directory, done = bad_runs[case]
    assert_one_line_error(done, BAD_ARGUMENTS[case][2])
    assert [p.name for p in directory.iterdir()] == ["a-file"]
    assert (directory / "a-file").read_text() == "a file"


# ------------------------------------------------------------------- happy path


def test_record_prints_a_summary_line_and_no_progress(tmp_path: Path) -> None:
    out = tmp_path / "out.mcap"
    done = rsstp_record("two-joint-30", "--steps", "5000", "--seed", "3", "-o", out)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""  # stderr is a pipe, not a TTY: no progress
    counts = step_counts(out)
    assert counts["/rsstp/step"] == 5001
    expected = ", ".join(f"{topic} {count:,}" for topic, count in counts.items())
    assert done.stdout == f"recorded 5,000 steps to {out} ({expected})\n"


def test_same_bytes_across_processes_and_hash_seeds(tmp_path: Path) -> None:
    paths = [tmp_path / f"run{i}.mcap" for i in range(2)]
    for path, hash_seed in zip(paths, ("1", "2"), strict=True):
        done = rsstp_record(
            "three-joint", "--steps", "1000", "--seed", "5", "-o", path, PYTHONHASHSEED=hash_seed
        )
        assert done.returncode == 0, done.stderr
    in_process = tmp_path / "in-process.mcap"
    record(in_process, load_scenario("three-joint"), RandomStrategy(), steps=1000, seed=5)
    assert paths[0].read_bytes() == paths[1].read_bytes() == in_process.read_bytes()


def test_compact_writes_the_compact_file_of_the_same_run(tmp_path: Path) -> None:
    out = tmp_path / "small.mcap"
    done = rsstp_record("three-joint", "--steps", "1000", "--seed", "5", "-o", out, "--compact")
    assert done.returncode == 0, done.stderr
    in_process = tmp_path / "in-process.mcap"
    scenario = load_scenario("three-joint")
    record(in_process, scenario, RandomStrategy(), steps=1000, seed=5, compact=True)
    assert out.read_bytes() == in_process.read_bytes()
    default = tmp_path / "default.mcap"
    record(default, scenario, RandomStrategy(), steps=1000, seed=5)
    assert out.stat().st_size < default.stat().st_size


# ----------------------------------------------------------------- crash safety


def start_long_recording(out: Path, *, session: bool = False) -> subprocess.Popen[str]:
    """A recording of 2,000,000 steps (its chunks built by a helper process); ``session``:
    in a process group of its own, as a command started from a terminal is."""
    return subprocess.Popen(
        [sys.executable, "-m", "rsstp_cli.sim", "record", "three-joint", "--strategy", "random"]
        + ["--steps", "2000000", "--seed", "1", "-o", str(out), "--chunk-size", str(CHUNK_SIZE)],
        env=cli_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=session,
    )


def helpers_of(pid: int) -> list[int]:
    """The helper processes (chunk_process) that process ``pid`` started."""
    found = []
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            command = Path(f"/proc/{entry}/cmdline").read_bytes()
        except OSError:  # ended meanwhile
            continue
        if int(stat.rpartition(")")[2].split()[1]) == pid and b"chunk_process" in command:
            found.append(int(entry))
    return found


def wait_until_gone(pids: list[int]) -> None:
    """Until the helpers ``pids`` end (they do as their recorder's pipe closes; a hang guard
    fails a helper that outlives its recorder)."""

    def gone() -> bool:
        return not any(Path(f"/proc/{pid}").exists() for pid in pids)

    wait_until(gone, f"helper processes {pids} outlived their recorder")


def side(out: Path) -> Path:
    """Where a recording of ``out`` is written until it is finished."""
    return out.with_name(f"{out.name}.partial")


def wait_for_chunks(proc: subprocess.Popen[str], out: Path, *, min_bytes: int) -> None:
    """Poll until the side file of ``out`` is bigger than ``min_bytes`` (several complete
    chunks)."""

    def grown() -> bool:
        return side(out).exists() and side(out).stat().st_size > min_bytes

    wait_until(grown, f"{out} growing past {min_bytes} bytes", process=proc)


def stop_recording(
    out: Path, sig: signal.Signals, *, group: bool = False
) -> subprocess.CompletedProcess[str]:
    """Stop a long recording with ``sig``, sent to its process alone or (``group``) to its
    process group, as Ctrl-C in a terminal sends SIGINT: its helper gets it too."""
    proc = start_long_recording(out, session=group)
    try:
        wait_for_chunks(proc, out, min_bytes=3 * CHUNK_SIZE)
        helpers = helpers_of(proc.pid)
        assert len(helpers) == 1
        if group:
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=HANG_S)
        wait_until_gone(helpers)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    return subprocess.CompletedProcess(proc.args, proc.returncode, stdout, stderr)


def step_numbers(messages: Sequence[tuple[str, bytes]]) -> list[int]:
    steps = []
    for topic, data in messages:
        if topic == "/rsstp/step":
            schemas.validate("rsstp.Step", json.loads(data))
            steps.append(records.decode("rsstp.Step", data).step)  # type: ignore[union-attr]
    return steps


@pytest.mark.parametrize(
    ("sig", "group"),
    [
        pytest.param(signal.SIGINT, True, id="SIGINT-group"),  # Ctrl-C at a terminal
        pytest.param(signal.SIGINT, False, id="SIGINT-process", marks=pytest.mark.slow),
        pytest.param(signal.SIGTERM, False, id="SIGTERM-process", marks=pytest.mark.slow),
        pytest.param(signal.SIGTERM, True, id="SIGTERM-group", marks=pytest.mark.slow),
    ],
)
def test_sigint_and_sigterm_finish_the_file(
    tmp_path: Path, sig: signal.Signals, group: bool
) -> None:
    out = tmp_path / "long.mcap"
    done = stop_recording(out, sig, group=group)
    assert done.returncode == 128 + sig.value
    assert "Traceback" not in done.stderr
    assert done.stdout == ""
    match = re.fullmatch(
        rf"rsstp-sim: interrupted by {sig.name}: kept ([\d,]+) steps? in {re.escape(str(out))} "
        r"\(file finished\)\n",
        done.stderr,
    )
    assert match, done.stderr
    kept = int(match[1].replace(",", ""))
    assert kept > 0
    assert step_counts(out)["/rsstp/step"] == kept + 1
    with out.open("rb") as stream:
        messages = [
            (channel.topic, m.data)
            for _, channel, m in make_reader(stream).iter_messages(log_time_order=False)
        ]
    assert step_numbers(messages) == list(range(kept + 1))


def read_sequentially(data: bytes) -> tuple[list[tuple[str, bytes]], list[int], int, bool]:
    """Read a (possibly truncated) MCAP file record by record, as a non-seeking reader does.

    Returns the messages (topic, data) of the complete chunks, the number of step messages
    in each complete chunk, the offset just after the last complete record, and whether a
    footer was found.
    """
    stream = io.BytesIO(data)
    reader = StreamReader(stream, skip_magic=False, emit_chunks=True, validate_crcs=True)
    topics: dict[int, str] = {}
    messages: list[tuple[str, bytes]] = []
    steps_per_chunk: list[int] = []
    end = 0
    footer = False
    try:
        for rec in reader.records:
            if isinstance(rec, Chunk):
                inner = breakup_chunk(rec, validate_crc=True)
                for item in inner:
                    if isinstance(item, Channel):
                        topics[item.id] = item.topic
                chunk_messages = [
                    (topics[m.channel_id], m.data) for m in inner if isinstance(m, Message)
                ]
                messages += chunk_messages
                steps_per_chunk.append(sum(t == "/rsstp/step" for t, _ in chunk_messages))
            footer = footer or isinstance(rec, Footer | DataEnd)
            end = stream.tell()
    except (McapError, struct.error):  # the truncated tail
        pass
    return messages, steps_per_chunk, end, footer


@pytest.mark.slow
def test_sigkill_keeps_every_complete_chunk(tmp_path: Path) -> None:
    out = tmp_path / "killed.mcap"
    proc = start_long_recording(out)
    try:
        wait_for_chunks(proc, out, min_bytes=4 * CHUNK_SIZE)
        helpers = helpers_of(proc.pid)
        assert len(helpers) == 1
        # Stopped first, so that the kill cannot land inside a write() (which would leave a
        # partial record): the file is then exactly what the process had handed to the OS.
        proc.send_signal(signal.SIGSTOP)
        _, status = os.waitpid(proc.pid, os.WUNTRACED)
        assert os.WIFSTOPPED(status)
        proc.kill()
        proc.communicate(timeout=HANG_S)
        wait_until_gone(helpers)  # its pipe closed: the helper ended too
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert proc.returncode == -signal.SIGKILL
    assert not out.exists()  # nothing unfinished ever has the output's name
    data = side(out).read_bytes()

    # Not finished: no footer, no summary for a seeking reader.
    assert not data.endswith(MCAP_MAGIC)
    with side(out).open("rb") as stream, pytest.raises((McapError, struct.error)):
        make_reader(stream).get_summary()

    messages, steps_per_chunk, end, footer = read_sequentially(data)
    assert not footer
    assert len(steps_per_chunk) >= 3  # waited for a few chunks
    steps = step_numbers(messages)  # every one schema-valid
    assert steps == list(range(len(steps)))  # 0..K in order, no gaps
    assert len(steps) == sum(steps_per_chunk)  # all steps of all complete chunks
    for topic, payload in messages:
        schemas.validate(schemas.TOPICS[topic], json.loads(payload))
    # Each chunk reaches the OS whole, with its message indexes, in one write: the file ends
    # on a record boundary. (That no completed chunk waits in a user-space buffer is checked
    # in-process by test_recorder.py::test_completed_chunks_are_on_disk_during_the_run.)
    assert end == len(data), f"{len(data) - end} bytes of a partial record at the end"


# -- nothing lost, nothing corrupt ----------------------------------------------------------


@pytest.mark.slow
def test_force_keeps_the_old_recording_until_the_new_one_is_whole(tmp_path: Path) -> None:
    out = tmp_path / "run.mcap"
    assert rsstp_record("thesis-roulette", "--steps", "20", "-o", out).returncode == 0
    old = out.read_bytes()
    proc = subprocess.Popen(
        [sys.executable, "-m", "rsstp_cli.sim", "record", "three-joint", "--steps", "2000000",
         "-o", str(out), "--chunk-size", str(CHUNK_SIZE), "--force"],
        env=cli_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        wait_for_chunks(proc, out, min_bytes=2 * CHUNK_SIZE)
        proc.kill()  # right in the middle of replacing it
        proc.communicate(timeout=HANG_S)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert out.read_bytes() == old  # the old recording is untouched
    assert side(out).stat().st_size > 2 * CHUNK_SIZE  # the killed run's chunks are kept
    out.rename(tmp_path / "old.mcap")
    again = rsstp_record("thesis-roulette", "--steps", "20", "-o", out)
    assert_one_line_error(again, r"run.mcap.partial: left by an interrupted recording")
    forced = rsstp_record("thesis-roulette", "--steps", "20", "-o", out, "--force")
    assert forced.returncode == 0, forced.stderr
    assert out.read_bytes() == old and not side(out).exists()  # same run, same bytes


def test_a_second_writer_on_the_same_output_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "run.mcap"
    first = start_long_recording(out)
    try:
        wait_for_chunks(first, out, min_bytes=CHUNK_SIZE)
        second = rsstp_record("thesis-roulette", "--steps", "20", "-o", out, "--force")
        assert_one_line_error(second, r"another recording is being written there")
        first.send_signal(signal.SIGINT)
        first.communicate(timeout=HANG_S)
    finally:
        if first.poll() is None:
            first.kill()
            first.communicate()
    assert first.returncode == 128 + signal.SIGINT
    assert out.read_bytes().endswith(MCAP_MAGIC) and not side(out).exists()


@pytest.mark.parametrize(
    ("steps", "limit"),
    [
        pytest.param("50000", 200_000, id="alone"),
        pytest.param("500000", 8_000_000, id="helped", marks=pytest.mark.slow),
    ],
)
def test_a_file_size_limit_is_one_line_saying_what_is_safe(
    tmp_path: Path, steps: str, limit: int
) -> None:
    """EFBIG (RLIMIT_FSIZE in the child): exit 1, one line; the side file holds the steps it
    names, and a reader recovers exactly those. A run of 500,000 steps builds its chunks in
    a helper process after its first 65,536 (some 5 MB), and the recorder writes them."""
    import resource

    out = tmp_path / "run.mcap"

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "record", "three-joint", "--steps", steps,
         "-o", str(out)],
        env=cli_env(), capture_output=True, text=True, timeout=HANG_S, preexec_fn=small_files,
    )  # fmt: skip
    assert done.returncode == 1, done.stderr
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and "File too large" in lines[0], done.stderr
    safe = int(re.search(r"steps 1 to ([\d,]+) are safe", lines[0])[1].replace(",", ""))
    assert not out.exists()
    from rsstp_replay import open_recording

    with pytest.warns(UserWarning, match="not finished"), open_recording(side(out)) as rec:
        assert rec.n_steps == safe > 0
    if steps == "500000":
        assert safe > 65_536  # (the helper's chunks among them)


@pytest.mark.parametrize(
    ("steps", "size"),
    [
        pytest.param("30000", "512k", id="alone"),
        pytest.param("300000", "8m", id="helped", marks=pytest.mark.slow),
    ],
)
def test_a_full_disk_is_one_line_saying_what_is_safe(tmp_path: Path, steps: str, size: str) -> None:
    """ENOSPC on a real small tmpfs (mounting needs root: CI runs as root); the run of
    300,000 steps (some 22 MB) builds its chunks in a helper process."""
    if os.geteuid() != 0:
        pytest.skip("needs root to mount a small tmpfs (CI runs as root)")
    disk = tmp_path / "disk"
    disk.mkdir()
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(disk)])
    if mounted.returncode != 0:
        pytest.skip("this machine refuses to mount a tmpfs")
    try:
        out = disk / "run.mcap"
        done = rsstp_record("three-joint", "--steps", steps, "-o", out)
        assert done.returncode == 1, done.stderr
        assert "No space left on device; steps 1 to " in done.stderr
        assert len(done.stderr.splitlines()) == 1 and not out.exists()
        assert side(out).exists()
        safe = int(re.search(r"steps 1 to ([\d,]+) are safe", done.stderr)[1].replace(",", ""))
        assert safe > (65_536 if steps == "300000" else 0)  # (the helper's chunks among them)
    finally:
        subprocess.run(["umount", str(disk)], check=True)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--steps", "10", "-o", "/dev/null", "--force"], r"/dev/null: a character device"),
        (["--steps", str(10**13), "-o", "{tmp}/x.mcap"], r"--steps .*more than this machine"),
        (["--param", "actions=[0,", "--strategy", "script", "--steps", "5", "-o", "{tmp}/x.mcap"],
         r"--param actions: not valid JSON"),
    ],
)  # fmt: skip
def test_extreme_or_malformed_input_is_refused_up_front(
    args: list[str], message: str, tmp_path: Path
) -> None:
    done = rsstp_record("thesis-roulette", *(a.format(tmp=tmp_path) for a in args))
    assert_one_line_error(done, message)
    assert not (tmp_path / "x.mcap").exists() and not list(tmp_path.glob("*.partial"))


def test_a_named_pipe_is_refused_not_waited_on(tmp_path: Path) -> None:
    pipe = tmp_path / "scenario.toml"
    os.mkfifo(pipe)
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "run", str(pipe), "--steps", "3"],
        env=cli_env(), capture_output=True, text=True, timeout=HANG_S,
    )  # fmt: skip
    assert_one_line_error(done, r"scenario.toml: a named pipe, not a scenario file")
    replay = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "info", str(pipe)],
        env=cli_env(), capture_output=True, text=True, timeout=HANG_S,
    )  # fmt: skip
    assert replay.returncode == 2 and "a named pipe, not a recording" in replay.stderr
