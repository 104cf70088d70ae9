"""Inputs that once ended in a traceback (issue 22): each is one line on stderr and exit code
2, or 1 when an output could not be written.

- an integer of 2**63 or more in a step message (``check``, ``audit``, ``table``, ``view``);
- a model message after the last step (``audit --truth``, ``table --truth``);
- TOML, ``--matrix``, ``--param`` or a recording's message nested 3,000 deep;
- an output in a read-only folder (every command that writes) or past a file-size limit;
- scenario numbers so large that the geometry overflows (lengths 1e308, tolerance 3e307).
"""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest

from rsstp_cli.replay import main as replay_main
from rsstp_cli.sim import main as sim_main
from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.arm.table import WorldTable
from rsstp_sim.recording import record
from rsstp_sim.scenario import MAX_MAGNITUDE
from waiting import HANG_S

sys.path.insert(0, str(Path(__file__).parent / "replay"))
from test_corrupt import rewrite  # noqa: E402

SRC = Path(__file__).resolve().parents[1] / "src"
STEPS = 30
DEEP = "[" * 3000 + "]" * 3000


@pytest.fixture(scope="module")
def roulette(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A run with several model versions (the roulette splits every few steps)."""
    path = tmp_path_factory.mktemp("faults") / "roulette.mcap"
    scenario = load_scenario("thesis-roulette")
    record(path, scenario, make_strategy("roulette"), steps=STEPS, seed=0)
    return path


def one_line(
    main: Callable[[list[str]], int], argv: list[str], capsys: pytest.CaptureFixture[str]
) -> tuple[int, str]:
    """Run a command in process: its exit code and its one line of stderr."""
    code = main(argv)
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return code, err[0]


def _changed(source: Path, target: Path, change: Callable[[dict[str, object]], bool]) -> Path:
    """``source`` rewritten with the first step message that ``change`` edits (it returns
    True once it changed the message)."""
    done: list[bool] = []

    def message(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/step" or done:
            return data
        decoded = json.loads(data)
        if change(decoded):
            done.append(True)
            return json.dumps(decoded).encode()
        return data

    return rewrite(source, target, message=message)


def _big_step(message: dict[str, object]) -> bool:
    if message["step"] != 5:
        return False
    message["step"] = 2**64 + 5
    return True


def _big_state(message: dict[str, object]) -> bool:
    if message["step"] != 7:
        return False
    agent = message["agent"]
    assert isinstance(agent, dict)
    agent["internal_state"] = 2**63
    return True


@pytest.mark.parametrize("change", [_big_step, _big_state], ids=["step", "internal_state"])
def test_an_integer_past_int64_is_one_line(
    change: Callable[[dict[str, object]], bool],
    roulette: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    bad = _changed(roulette, tmp_path / "big.mcap", change)
    for argv in (
        ["check", str(bad)],
        ["audit", str(bad)],
        ["audit", "--truth", str(bad)],
        ["table", str(bad), "-o", str(tmp_path / "t.csv")],
        ["view", str(bad), "--save", str(tmp_path / "v.rrd")],
    ):
        code, line = one_line(replay_main, argv, capsys)
        assert code == 2 and "<= 9223372036854775807" in line, (argv, line)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.mcap"]


def test_a_model_message_after_the_last_step_is_one_line(
    roulette: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The last model message moved past the last step (its step and log time)."""
    with open(roulette, "rb") as stream:
        from mcap.reader import make_reader

        last = [
            json.loads(m.data)
            for _, _, m in make_reader(stream).iter_messages(topics=["/rsstp/model"])
        ][-1]
    after = (STEPS + 1) * 1_000_000

    def message(topic: str, log_time: int, data: bytes) -> bytes:
        if topic == "/rsstp/model" and json.loads(data)["version"] == last["version"]:
            return json.dumps({**json.loads(data), "step": STEPS + 1}).encode()
        return data

    def retime(topic: str, log_time: int) -> int:
        moved = topic == "/rsstp/model" and log_time == last["step"] * 1_000_000
        return after if moved else log_time

    bad = rewrite(roulette, tmp_path / "late.mcap", message=message, retime=retime)
    expected = (
        f"rsstp-replay: error: {bad}: model version {last['version']} (step {STEPS + 1}) "
        f"comes after the last step, {STEPS}"
    )
    for argv in (
        ["audit", "--truth", str(bad)],
        ["table", "--truth", str(bad), "-o", str(tmp_path / "t.parquet")],
        ["check", str(bad)],
    ):
        assert one_line(replay_main, argv, capsys) == (2, expected), argv


def test_deep_nesting_is_refused_before_parsing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    deep_toml = tmp_path / "deep.toml"
    deep_toml.write_text(f"x = {DEEP}\n")
    deep_sweep = tmp_path / "sweep.toml"
    deep_sweep.write_text(f"x = {DEEP}\n")
    said = "nested 3,000 levels deep, more than the 100 this reader takes"
    for argv, where in (
        (["run", str(deep_toml)], str(deep_toml)),
        (["truth", str(deep_toml)], str(deep_toml)),
        (["record", str(deep_toml), "-o", str(tmp_path / "r.mcap")], str(deep_toml)),
        (["graph", "--matrix", DEEP, "-o", str(tmp_path / "m.dot")], "--matrix"),
        (["run", "thesis-algo", "--param", f"actions={DEEP}"], "--param actions"),
        (["sweep", str(deep_sweep), "-o", str(tmp_path / "out")], str(deep_sweep)),
    ):
        assert one_line(sim_main, argv, capsys) == (2, f"rsstp-sim: error: {where}: {said}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deep.toml", "sweep.toml"]


@pytest.mark.parametrize("topic", ["/rsstp/step", "/rsstp/event", "/rsstp/model"])
def test_a_message_nested_deep_is_one_line(
    topic: str, roulette: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    done: list[bool] = []

    def message(found: str, log_time: int, data: bytes) -> bytes:
        if found != topic or done:
            return data
        done.append(True)
        return data[:-1] + b',"deep":' + DEEP.encode() + b"}"

    bad = rewrite(roulette, tmp_path / "deep.mcap", message=message)
    code, line = one_line(replay_main, ["check", str(bad)], capsys)
    assert code == 2 and line.endswith("nested too deeply"), line


def test_a_read_only_folder_is_one_line_for_every_output(
    roulette: Path, unwritable_directory: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = unwritable_directory
    for main, prog, argv, out in (
        (replay_main, "rsstp-replay", ["table", str(roulette), "-o"], "t.csv"),
        (replay_main, "rsstp-replay", ["table", str(roulette), "-o"], "t.parquet"),
        (replay_main, "rsstp-replay", ["events", str(roulette), "-o"], "e.csv"),
        (replay_main, "rsstp-replay", ["view", str(roulette), "--save"], "v.rrd"),
        (replay_main, "rsstp-replay", ["export", "--foxglove", str(roulette), "-o"], "f.mcap"),
        (replay_main, "rsstp-replay", ["graph", str(roulette), "--step", "3", "-o"], "g.dot"),
        (sim_main, "rsstp-sim", ["graph", "--matrix", "[[[0]]]", "-o"], "m.dot"),
        (sim_main, "rsstp-sim", ["record", "thesis-algo", "--steps", "3", "-o"], "r.mcap"),
    ):
        target = folder / out
        code, line = one_line(main, [*argv, str(target)], capsys)
        expected = f"{prog}: error: {target}: the output directory {folder} is not writable"
        assert (code, line) == (2, expected), argv


def _limited(size: int) -> Callable[[], None]:
    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (size, size))

    return limit


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_table_past_a_file_size_limit_is_one_line_and_exit_1(
    suffix: str, roulette: Path, tmp_path: Path
) -> None:
    """EFBIG while writing the table (RLIMIT_FSIZE in the child): the old table stays."""
    out = tmp_path / f"steps{suffix}"
    out.write_bytes(b"keep me")
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "table", str(roulette), "-o", str(out)]
        + ["--force"],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        preexec_fn=_limited(2_000),
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": "/tmp",
             "PYTHONDONTWRITEBYTECODE": "1"},  # no .pyc cut short by the limit
    )  # fmt: skip
    assert done.returncode == 1, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"rsstp-replay: error: {out}: cannot write")
    assert out.read_bytes() == b"keep me"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


@pytest.mark.parametrize(
    ("section", "key", "value"),
    [
        ("arm", "lengths", "[1e308, 1e308]"),
        ("arm", "lengths", "[1e300, 1.0]"),
        ("feedback", "tolerance", "3e307"),
    ],
)
def test_numbers_that_overflow_the_geometry_are_refused_first(
    section: str, key: str, value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Refused before any numpy warning (the suite turns warnings into errors)."""
    scenario = tmp_path / "big.toml"
    arm = {"lengths": "[1.0, 1.0]", "initial_deg": "[0, 90]", "step_deg": "10"}
    feedback = {"tolerance": "1e-6"}
    {"arm": arm, "feedback": feedback}[section][key] = value
    scenario.write_text(
        "[arm]\n"
        + "".join(f"{k} = {v}\n" for k, v in arm.items())
        + "[feedback]\n"
        + "".join(f"{k} = {v}\n" for k, v in feedback.items())
    )
    first = float(value.strip("[]").split(",")[0])
    where = f"{section}.{key}" + ("[0]" if section == "arm" else "")
    for command in ("run", "truth", "record"):
        argv = [command, str(scenario)] + (["-o", str(tmp_path / "r.mcap")] * (command == "record"))
        code, line = one_line(sim_main, argv, capsys)
        assert (code, line) == (
            2,
            f"rsstp-sim: error: {scenario}: {where}: expected a number of size at most "
            f"{MAX_MAGNITUDE:g}, found {first!r}",
        )


def test_view_save_never_starts_reruns_file_writer(
    roulette: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Rerun's file-writer thread can hang its flush for good after a failed write (``view
    --save`` under ``ulimit -f 8`` hung in 4 of 8 tries): a save without a viewer to feed
    encodes in memory and writes the bytes itself, so that thread never runs."""
    import rerun as rr

    from rsstp_replay import open_recording
    from rsstp_replay.viewer import view

    def no_file_sink(*args: object, **kwargs: object) -> None:
        raise AssertionError("rr.FileSink was used")

    monkeypatch.setattr(rr, "FileSink", no_file_sink)
    out = tmp_path / "run.rrd"
    with open_recording(roulette) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=None, end=None)
    assert out.read_bytes().startswith(b"RRF2")
    assert [p.name for p in tmp_path.iterdir()] == ["run.rrd"]


def test_a_world_too_big_to_tabulate_is_refused_at_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Three joints among 1,000 obstacles: `truth` took 130 s and 8.6 GB; now one line, before
    any of the world is tabulated."""

    def tabulated(*_: object, **__: object) -> None:
        pytest.fail("the world was tabulated before it was refused")

    obstacles = "".join(
        f"[[obstacles]]\ncenter = [{40 + i % 40}.0, {40 + i // 40}.0]\nradius = 0.1\n"
        for i in range(1000)
    )
    scenario = tmp_path / "many.toml"
    scenario.write_text(
        "[arm]\nlengths = [3.0, 2.0, 1.0]\ninitial_deg = [330, 3, 357]\nstep_deg = 5\n" + obstacles
    )
    monkeypatch.setattr(WorldTable, "__init__", tabulated)
    assert sim_main(["truth", str(scenario)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        "rsstp-sim: error: many: refused: tabulating the world would take about 6,718,464,000 "
        "link-obstacle checks (373,248 poses x 6 moves x 3 links x 1,000 obstacles), more than "
        "the 1,000,000,000 (about 20 s) the ground truth takes on"
    )
