"""``rsstp-replay``: info, table, audit and compare on real recordings.

Most commands run in process (``main(argv)`` with captured output); the entry point itself
(``python -m rsstp_replay``) runs as a subprocess for an unfinished file, whose warning must be
one line on stderr. Damaged files are the business of ``test_corrupt.py``.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import ClassVar

import pandas as pd
import pytest

from rsstp_cli.replay import main
from rsstp_replay import open_recording, read_table
from rsstp_replay.audits import audit_truth, compare, run_audits
from rsstp_replay.audits.physics import check_physics
from rsstp_sim import AgentView, StrategyBase, load_scenario, make_strategy
from rsstp_sim.recording.recorder import record
from waiting import HANG_S

SRC = Path(__file__).resolve().parents[2] / "src"
STEPS = 1500


class SplitOnce(StrategyBase):
    """Random actions; splits the start state at the reset and never resolves it: the final
    model is nondeterministic."""

    name: ClassVar[str] = "test-split-once"

    def reset(self, agent: AgentView) -> None:
        agent.model.split(agent.model.current)

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[int(agent.rng.integers(len(agent.actions)))]


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "run.mcap"
    record(
        path,
        load_scenario("three-joint"),
        make_strategy("random"),
        steps=STEPS,
        seed=1,
        chunk_size=16 * 1024,
    )
    return path


@pytest.fixture(scope="module")
def split_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("cli") / "split.mcap"
    record(path, load_scenario("one-joint-10"), SplitOnce(), steps=200, seed=2)
    return path


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


# ------------------------------------------------------------------------------- info


def test_info_describes_the_recording(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "info", str(run))
    assert (code, err) == (0, "")
    assert f"file: {run} (" in out
    assert re.search(r"bytes, finished, \d+ chunks checked\)", out)
    assert "scenario: three-joint (Three links" in out
    assert "joints: 3 (lengths 3, 2, 1; start [330, 3, 357] deg; step 5 deg; actions" in out
    assert "obstacles: 2: centre (1.5, 1) radius 0.5; centre (1.5, -1.5) radius 0.5" in out
    assert "feedback: bool (tolerance 1e-06); collision: swept" in out
    assert "strategy: random {}; seed: 1\n" in out
    assert "steps: 0 to 1,500 (the reset, then 1,500 steps)" in out
    assert re.search(r"\n  /rsstp/step +1,501\n", out)
    assert "model at the end: version 0, 1 state, 6 transitions, deterministic" in out


def test_info_on_an_unfinished_file_warns_in_one_line(run: Path, tmp_path: Path) -> None:
    cut = tmp_path / "cut.mcap"
    data = run.read_bytes()
    cut.write_bytes(data[: len(data) // 2])
    process = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "info", str(cut)],
        env={**os.environ, "PYTHONPATH": str(SRC)},
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert process.returncode == 0, process.stderr
    assert "Traceback" not in process.stderr
    lines = process.stderr.splitlines()
    assert len(lines) == 1
    assert lines[0].startswith(f"rsstp-replay: warning: {cut}: the file was not finished; ")
    assert "steps from its complete chunks" in lines[0]
    assert re.search(r"NOT finished \(recovered from its \d+ complete chunks\)", process.stdout)


# ------------------------------------------------------------------------------ table


def test_table_writes_parquet(
    run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "steps.parquet"
    code, printed, err = run_cli(capsys, "table", str(run), "-o", str(out))
    assert (code, err) == (0, "")
    assert printed == f"wrote 1,501 rows and 31 columns (index step) to {out}\n"
    expected = open_recording(run).steps()
    pd.testing.assert_frame_equal(pd.read_parquet(out), expected)  # the index as written
    assert read_table(out).equals(expected)


def test_a_file_size_limit_never_leaves_a_part_of_a_table(run: Path, tmp_path: Path) -> None:
    """EFBIG on the thread that writes the row groups (RLIMIT_FSIZE in the child): one
    line, exit 1, the table that was there untouched, no side file."""
    import resource

    out = tmp_path / "steps.parquet"
    out.write_bytes(b"keep me")

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (20_000, 20_000))

    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "table", str(run), "-o", str(out), "--force"],
        capture_output=True, text=True, timeout=HANG_S, preexec_fn=small_files,
        env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "HOME": "/tmp",
             "PYTHONDONTWRITEBYTECODE": "1"},  # no .pyc cut short by the limit
    )  # fmt: skip
    assert (done.returncode, done.stdout) == (1, "")
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"rsstp-replay: error: {out}: cannot write: ")
    assert done.stderr.endswith("File too large\n")  # (pyarrow's words before it)
    assert out.read_bytes() == b"keep me"
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


def test_table_truth_adds_class_pose_and_aliasing(
    run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "truth.parquet"
    code, printed, err = run_cli(capsys, "table", str(run), "--truth", "-o", str(out))
    assert (code, err) == (0, "")
    assert printed == f"wrote 1,501 rows and 34 columns (index step) to {out}\n"
    table = read_table(out)
    with open_recording(run) as recording:
        truth = recording.ground_truth()
        findings = audit_truth(recording, truth=truth)
        pd.testing.assert_frame_equal(table.iloc[:, :31], recording.steps())
    assert table["true_class"].tolist() == findings.true_class.tolist()
    assert table["aliased"].tolist() == findings.aliased_step.tolist()
    angles = table[list(truth.value_names)].to_numpy()
    assert (truth.angles_deg[table["pose"].to_numpy()] == angles).all()


def test_table_writes_csv(run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "steps.csv"
    code, printed, err = run_cli(capsys, "table", str(run), "-o", str(out))
    assert (code, err) == (0, "")
    assert printed.endswith(f"to {out}; dtypes in {out}.dtypes.json\n")
    expected = open_recording(run).steps()
    assert read_table(out).equals(expected)  # every dtype and the index, through the sidecar
    exact = {"float_precision": "round_trip"} if pd.__version__.startswith("2.") else {}
    table = pd.read_csv(out, **exact)  # plain pandas: pandas 3 reads floats exactly
    assert list(table.columns) == ["step", *expected.columns]
    assert table["step"].tolist() == expected.index.tolist()
    assert table["feedback"].tolist() == expected["feedback"].tolist()  # exact round trip
    assert table["joint3_x"].tolist() == expected["joint3_x"].tolist()


def test_table_refuses_to_overwrite_without_force(
    run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "steps.csv"
    out.write_text("keep me\n", encoding="utf-8")
    code, printed, err = run_cli(capsys, "table", str(run), "-o", str(out))
    assert (code, printed) == (2, "")
    assert err == f"rsstp-replay: error: {out}: already exists (use --force to overwrite)\n"
    assert out.read_text(encoding="utf-8") == "keep me\n"
    code, _, err = run_cli(capsys, "table", str(run), "-o", str(out), "--force")
    assert (code, err) == (0, "")
    assert out.read_text(encoding="utf-8").startswith("step,action,")


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("steps.xlsx", r"steps\.xlsx: unknown table format '\.xlsx': expected \.parquet or \.csv"),
        ("no-such-dir/steps.csv", r"steps\.csv: the output directory .*no-such-dir does not"),
    ],
)
def test_table_refuses_bad_outputs(
    run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, message: str
) -> None:
    code, _, err = run_cli(capsys, "table", str(run), "-o", str(tmp_path / name))
    assert code == 2
    assert err.count("\n") == 1
    assert re.search(message, err), err


# ------------------------------------------------------------------------------ audit


def test_audit_prints_the_report(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "audit", str(run))
    assert (code, err) == (0, "")
    with open_recording(run) as recording:
        physics = check_physics(recording).to_text()
        assert out == run_audits(recording).to_text() + physics + "\n"
    assert physics.startswith("physics: the world follows from the scenario and the actions")


def test_audit_json(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run_cli(capsys, "audit", str(run), "--json")
    assert code == 0
    document = json.loads(out)
    assert document.pop("model_recorded") is True
    assert document.pop("physics")["holds"] is True
    with open_recording(run) as recording:
        assert document == json.loads(json.dumps(run_audits(recording).to_json()))


@pytest.mark.parametrize(
    ("which", "fail_on", "expected"),
    [
        ("random", ["contradiction"], 1),  # state 0 of the one-state model is contradictory
        ("random", ["nondeterministic"], 0),
        ("random", ["nondeterministic", "contradiction"], 1),
        ("split", ["nondeterministic"], 1),
        ("split", [], 0),
    ],
)
def test_audit_fail_on(
    run: Path,
    split_run: Path,
    capsys: pytest.CaptureFixture[str],
    which: str,
    fail_on: list[str],
    expected: int,
) -> None:
    path = run if which == "random" else split_run
    flags = [arg for reason in fail_on for arg in ("--fail-on", reason)]
    code, out, err = run_cli(capsys, "audit", str(path), *flags)
    assert code == expected
    assert "== summary ==" in out
    if expected:
        assert err.startswith("rsstp-replay: audit failed: ") and err.count("\n") == 1
    else:
        assert err == ""


def test_audit_refuses_an_unknown_fail_on(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run_cli(capsys, "audit", str(run), "--fail-on", "everything")
    assert code == 2
    assert "invalid choice: 'everything'" in err and err.count("\n") == 1


# ---------------------------------------------------------------------------- compare


def test_compare_prints_kind_and_offset(run: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli(capsys, "compare", str(run), "5", "10")
    assert (code, err) == (0, "")
    with open_recording(run) as recording:
        findings = compare(recording, 5, 10)
    assert out == findings.to_text() + "\n"
    assert f"at offset {findings.offset}" in out or "no difference" in out
    code, out, _ = run_cli(capsys, "compare", str(run), "5", "10", "--json")
    assert json.loads(out) == findings.to_json()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["compare", "{run}", "3", "3"], "compare: N and M must differ (both are 3)"),
        (["compare", "{run}", "-1", "3"], "{run}: compare N = -1 is out of range"),
        (["compare", "{run}", "1", "x"], "argument M: expected an integer, got 'x'"),
        ([], "the following arguments are required: command"),
        (["replay"], "invalid choice: 'replay'"),
    ],
)
def test_usage_errors_are_one_line(
    run: Path, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    code, out, err = run_cli(capsys, *(arg.format(run=run) for arg in argv))
    assert (code, out) == (2, "")
    assert err.startswith("rsstp-replay: error: ") and err.count("\n") == 1
    assert message.format(run=run) in err
