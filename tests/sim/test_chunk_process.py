"""A long run's chunks built in a helper process: the same bytes, and failures said in a line.

The recorder builds a long run's chunks in a helper process (``Recorder.run(helper=True)``,
by default past ``HELPER_STEPS`` steps, when they are light). Its file must be the one the
recorder writes alone (which ``test_chunks.py`` and ``test_step_messages.py`` hold to mcap's
``Writer`` and the record encoder), whatever the run does: model changes, notes, blocked
moves, steps with no transition, chunks of every size, steps recorded one at a time before.
A helper that dies or fails is one line, and the recorder keeps the steps it had written; a helper
that cannot start leaves the recorder to do the work alone. The signals and the disk's
errors of a helped run are in ``test_record_cli.py``.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from mcap.reader import make_reader

from rsstp_replay import open_recording
from rsstp_sim import RandomStrategy, load_scenario
from rsstp_sim.errors import ChunkProcessFailed, RecordingError
from rsstp_sim.recording.chunk_process import ChunkProcess
from rsstp_sim.recording.chunks import OpenChunk
from rsstp_sim.recording.recorder import HELPER_STEPS, TRIAL_STEPS, Recorder
from rsstp_sim.recording.step_messages import Steps
from rsstp_sim.scenario import parse_scenario
from rsstp_sim.strategies import make_strategy
from waiting import wait_until

RUNS = [
    # scenario, strategy, steps, chunk size: what the run has
    pytest.param(  # blocked moves, many small chunks
        "three-joint", "random", 20_000, 4096, marks=pytest.mark.slow
    ),
    pytest.param(  # all in the first chunk: the helper's last
        "three-joint", "random", 9_000, 1 << 20, marks=pytest.mark.slow
    ),
    ("thesis-algo", "learner", 3_000, 2048),  # model changes, notes, phases
    ("two-joint-30", "splitter", 3_000, 8192),  # splits, steps with no transition
    ("thesis-obstacles", "roulette", 5_000, 3000),
]


def recorded(
    path: Path, scenario: str, strategy: str, *, chunk_size: int, compact: bool = False
) -> Recorder:
    return Recorder(
        path,
        load_scenario(scenario),
        make_strategy(strategy),
        seed=4,
        chunk_size=chunk_size,
        compact=compact,
    )


@pytest.mark.parametrize(("scenario", "strategy", "steps", "chunk_size"), RUNS)
def test_a_helped_run_writes_the_bytes_of_a_run_alone(
    tmp_path: Path, scenario: str, strategy: str, steps: int, chunk_size: int
) -> None:
    alone, helped = tmp_path / "alone.mcap", tmp_path / "helped.mcap"
    first = recorded(alone, scenario, strategy, chunk_size=chunk_size).run(steps, helper=False)
    second = recorded(helped, scenario, strategy, chunk_size=chunk_size).run(steps, helper=True)
    assert helped.read_bytes() == alone.read_bytes()
    assert second.messages == first.messages
    with helped.open("rb") as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics is not None
    counts = summary.statistics.channel_message_counts
    assert {c.topic: counts.get(c.id, 0) for c in summary.channels.values()} == second.messages


@pytest.mark.parametrize("helper", [False, True])
def test_a_compact_recording_holds_the_same_messages_in_fewer_bytes(
    tmp_path: Path, helper: bool
) -> None:
    """``compact``: no message indexes, harder compression; the same messages, read back by
    mcap's own reader and by ours, and the same bytes again for the same run."""
    default, compact, again = (tmp_path / f"{name}.mcap" for name in ("default", "c", "again"))
    recorded(default, "thesis-algo", "learner", chunk_size=2048).run(3_000, helper=helper)
    for path in (compact, again):
        recorded(path, "thesis-algo", "learner", chunk_size=2048, compact=True).run(
            3_000, helper=helper
        )
    assert compact.read_bytes() == again.read_bytes()
    assert compact.stat().st_size < default.stat().st_size
    read = {}
    for path in (default, compact):
        with path.open("rb") as stream:
            reader = make_reader(stream, validate_crcs=True)
            read[path] = [(c.topic, m.log_time, m.data) for _, c, m in reader.iter_messages()]
            summary = reader.get_summary()
        assert summary is not None
        indexed = [bool(index.message_index_offsets) for index in summary.chunk_indexes]
        assert all(indexed) if path == default else not any(indexed)
    assert read[compact] == read[default]
    with open_recording(default) as ours, open_recording(compact) as small:
        assert small.steps().equals(ours.steps())
        assert small.events().equals(ours.events())
        assert small.model_at(3_000) == ours.model_at(3_000)


def test_steps_one_at_a_time_then_a_helped_run(tmp_path: Path) -> None:
    """The recorder hands the chunk its own steps were building to the helper, and takes
    back the helper's last one for the stop event and the summary."""
    files = []
    for helper in (False, True):
        path = tmp_path / f"{helper}.mcap"
        recorder = recorded(path, "thesis-algo", "learner", chunk_size=4096)
        for _ in range(300):
            recorder.step()
        recorder.run(2_000, helper=helper)
        files.append(path.read_bytes())
    assert files[0] == files[1]


FREE_ARM = """
[arm]
lengths = [3.0, 2.0, 1.0]
initial_deg = [330, 3, 357]
step_deg = 5
"""
"""three-joint's arm without its obstacles: its random walk roams, half its steps at a new
pose."""


@pytest.mark.slow
def test_left_to_choose_a_run_keeps_its_helper_while_its_steps_are_light(
    tmp_path: Path,
) -> None:
    """Past HELPER_STEPS steps, a helper starts with the run; after the first TRIAL_STEPS
    steps it stays for a random walk of three-joint (its poses met again) and ends for an
    arm that roams free (each new pose's tail would go to the helper). The bytes are the
    run's alone."""
    seen: dict[str, list[list[int]]] = {}
    for name, scenario in [
        ("walk", load_scenario("three-joint")),
        ("roaming", parse_scenario(FREE_ARM, origin="free.toml")),
    ]:
        files = []
        for helper in (None, False):
            path = tmp_path / f"{name}-{helper}.mcap"
            recorder = Recorder(path, scenario, RandomStrategy(), seed=1, chunk_size=1 << 16)
            found = seen.setdefault(name, []) if helper is None else []
            recorder.run(
                HELPER_STEPS + 4_096,
                progress=lambda done, found=found: found.append([done, *helpers()]),
                helper=helper,
            )
            files.append(path.read_bytes())
        assert files[0] == files[1]
    walk, roaming = seen["walk"], seen["roaming"]
    assert [len(found) for found in walk] == [2] * len(walk)  # one helper, all along
    assert len({found[1] for found in walk}) == 1 and not alive([walk[0][1]])
    before = [found for found in roaming if found[0] < TRIAL_STEPS]
    after = [found for found in roaming if found[0] >= TRIAL_STEPS]
    assert before and all(len(found) == 2 for found in before)
    assert after and all(len(found) == 1 for found in after)  # ended at the choice


@pytest.mark.slow
def test_a_short_run_has_no_helper(tmp_path: Path) -> None:
    recorder = recorded(tmp_path / "short.mcap", "three-joint", "random", chunk_size=1 << 16)
    found: list[list[int]] = []
    recorder.run(HELPER_STEPS, progress=lambda done: found.append(helpers()))
    assert found and not any(found)


def helpers() -> list[int]:
    """The process ids of this process's helpers (its children running chunk_process)."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = Path(f"/proc/{entry}/stat").read_text()
            command = Path(f"/proc/{entry}/cmdline").read_bytes()
        except OSError:  # ended meanwhile
            continue
        parent = int(stat.rpartition(")")[2].split()[1])
        if parent == os.getpid() and b"rsstp_sim.recording.chunk_process" in command:
            found.append(int(entry))
    return found


def alive(pids: list[int]) -> bool:
    return any(Path(f"/proc/{pid}").exists() for pid in pids)


@pytest.mark.slow
def test_a_helper_killed_mid_run_is_one_line_and_the_steps_written_stay(tmp_path: Path) -> None:
    path = tmp_path / "run.mcap"
    recorder = recorded(path, "three-joint", "random", chunk_size=4096)
    killed: list[int] = []

    def kill_the_helper(done: int) -> None:
        if done >= 4 * 4096 and not killed:
            (pid,) = helpers()
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    side = tmp_path / "run.mcap.partial"
    said = (
        "the helper process that builds the chunks ended before the run did (signal SIGKILL); "
        f"the steps before it are in {side} (finished); {path} was not touched"
    )
    with pytest.raises(RecordingError, match=re.escape(said)):
        recorder.run(200_000, progress=kill_the_helper, helper=True)
    assert killed and not path.exists()
    with side.open("rb") as stream:
        reader = make_reader(stream)
        steps = [
            int(re.match(rb'\{"step":(\d+)', message.data)[1])  # type: ignore[index]
            for _, channel, message in reader.iter_messages(log_time_order=False)
            if channel.topic == "/rsstp/step"
        ]
    assert len(steps) > 4096  # the chunks written before the helper died
    assert steps == list(range(len(steps)))


@pytest.mark.slow
def test_a_helper_that_dies_before_it_is_used_leaves_the_run_to_go_on_alone(
    tmp_path: Path,
) -> None:
    """Killed during the steps the run records itself before it chooses: the run goes on
    alone, whole, to the same bytes."""
    path = tmp_path / "run.mcap"
    recorder = recorded(path, "three-joint", "random", chunk_size=1 << 16)
    killed: list[int] = []

    def kill_the_helper(done: int) -> None:
        if not killed:
            (pid,) = helpers()
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    result = recorder.run(HELPER_STEPS + 4_096, progress=kill_the_helper)
    assert killed and result.steps == HELPER_STEPS + 4_096
    alone = tmp_path / "alone.mcap"
    recorded(alone, "three-joint", "random", chunk_size=1 << 16).run(
        HELPER_STEPS + 4_096, helper=False
    )
    assert path.read_bytes() == alone.read_bytes()


def test_a_helper_that_fails_says_why_in_one_line() -> None:
    helper = ChunkProcess(chunk_size=1024, channels=(1, 2))
    try:
        helper.take_over(OpenChunk([], 0, 0))
        # A tail number no block gave: the helper's own code fails.
        helper.send([Steps(1, 0, [b"}"], [0, 0, 0, 5])])
        with pytest.raises(
            ChunkProcessFailed,
            match=r"^the helper process that builds the chunks failed: IndexError: list index",
        ):
            helper.finish()
    finally:
        helper.close()


def test_a_helper_gives_back_the_chunk_it_was_given_when_nothing_came() -> None:
    records = [b"a lead record"]
    helper = ChunkProcess(chunk_size=1024, channels=(1, 2))
    try:
        helper.take_over(OpenChunk(records, 1, 13))
        assert helper.finish() == ([], OpenChunk(records, 1, 13))
    finally:
        helper.close()


def test_closing_a_helper_ends_it_at_once() -> None:
    """The helper ends as its pipe closes (exit status 1: nobody to tell), not killed by
    ``close``'s last resort, which waits 5 s first. Closed once it waits on its pipe, so that
    a machine slow to start it does not reach that resort."""
    helper = ChunkProcess(chunk_size=1024, channels=(1, 2))  # given nothing yet
    (pid,) = helpers()

    def waiting_on_its_pipe() -> bool:  # the kernel's wait: its wchan
        state = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
        assert state != "Z", "the helper ended before it read its pipe"
        return "pipe_read" in Path(f"/proc/{pid}/wchan").read_text()

    wait_until(waiting_on_its_pipe, "the helper waiting on its pipe")
    helper.close()
    assert helper._process.returncode == 1 and not alive([pid])


@pytest.mark.slow
def test_no_helper_can_start_and_the_recorder_does_the_work(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    alone = tmp_path / "alone.mcap"
    recorded(alone, "three-joint", "random", chunk_size=4096).run(6_000, helper=False)
    monkeypatch.setattr(sys, "executable", str(tmp_path / "no-python-here"))
    helped = tmp_path / "helped.mcap"
    recorded(helped, "three-joint", "random", chunk_size=4096).run(6_000, helper=True)
    assert helped.read_bytes() == alone.read_bytes()


@pytest.mark.slow
def test_the_helper_runs_this_process_code_wherever_it_was_imported_from(
    tmp_path: Path,
) -> None:
    """A script that put a copy of the package on its path itself: its helper imports that
    copy, not the installed one. The copy compresses at another zstd level, so a file whose
    chunks came from the installed package would differ from the copy's run alone."""
    copy = tmp_path / "copy"
    shutil.copytree(Path(__file__).resolve().parents[2] / "src" / "rsstp_sim", copy / "rsstp_sim")
    chunks = copy / "rsstp_sim" / "recording" / "chunks.py"
    text = chunks.read_text()
    assert "_ZSTD_LEVEL = 3" in text
    chunks.write_text(text.replace("_ZSTD_LEVEL = 3", "_ZSTD_LEVEL = 9"))
    script = tmp_path / "script.py"
    script.write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(copy)!r})\n"
        "import rsstp_sim\n"
        f"assert rsstp_sim.__file__.startswith({str(copy)!r})\n"
        "from rsstp_sim import RandomStrategy, load_scenario\n"
        "from rsstp_sim.recording.recorder import Recorder\n"
        "recorder = Recorder(sys.argv[1], load_scenario('three-joint'), RandomStrategy(), seed=4,\n"
        "                    chunk_size=4096)\n"
        "recorder.run(5_000, helper=sys.argv[2] == 'helped')\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    files = []
    for how in ("alone", "helped"):
        out = tmp_path / f"{how}.mcap"
        done = subprocess.run(
            [sys.executable, str(script), str(out), how], env=env, capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        files.append(out.read_bytes())
    assert files[0] == files[1]
    installed = tmp_path / "installed.mcap"
    recorded(installed, "three-joint", "random", chunk_size=4096).run(5_000, helper=False)
    assert installed.read_bytes() != files[0]  # the copy's level shows
