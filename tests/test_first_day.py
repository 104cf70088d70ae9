"""What a first day finds (issue 22): a strategy parameter error names the parameter and the
form it takes; ``sweep -o`` refuses a missing parent folder as every other command does; a
Python ``record`` onto an existing file says how to replace it in Python."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rsstp_cli.sim import main
from rsstp_sim import RecordingError, load_scenario, make_strategy
from rsstp_sim.recording import record

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    ("argv", "expected"),
    [
        (
            ["--strategy", "script", "--param", "actions=zero"],
            "script: parameter actions: expected a list of integers >= 0 (actions=[0,1]), "
            "got 'zero'",
        ),
        (
            ["--strategy", "random", "--param", "foo=1"],
            "strategy 'random': unknown parameter 'foo' (it takes block=VALUE)",
        ),
        (
            ["--strategy", "learner", "--param", "budget=3"],
            "strategy 'learner': unknown parameter 'budget' (it takes doubts=VALUE, stop=VALUE)",
        ),
        (
            ["--strategy", "roulette", "--param", "action=x"],
            "roulette: parameter action: expected an integer >= 0 (action=0), got 'x'",
        ),
        (
            ["--strategy", "splitter", "--param", "horizon=0"],
            "splitter: parameter horizon: expected an integer >= 1 (horizon=3), got 0",
        ),
    ],
)
def test_a_parameter_error_names_the_parameter_and_its_form(
    argv: list[str], expected: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["run", "thesis-roulette", "--steps", "2", *argv]) == 2
    assert capsys.readouterr().err == f"rsstp-sim: error: {expected}\n"


def test_sweep_refuses_a_missing_parent(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "missing" / "a" / "b"
    assert main(["sweep", str(ROOT / "sweeps" / "ci-learner.toml"), "-o", str(out)]) == 2
    assert capsys.readouterr().err == (
        f"rsstp-sim: error: {out}: the output directory {out.parent} does not exist\n"
    )
    assert list(tmp_path.iterdir()) == []


def test_record_in_python_onto_a_file_names_force_true(tmp_path: Path) -> None:
    path = tmp_path / "algo.mcap"
    path.write_bytes(b"old")
    said = f"{path}: already exists (use --force, or force=True in Python, to overwrite)"
    with pytest.raises(RecordingError, match=re.escape(said)):
        record(path, load_scenario("thesis-algo"), make_strategy("random"), steps=3, seed=1)
    assert path.read_bytes() == b"old"
