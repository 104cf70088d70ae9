"""Strategies from outside the package: ``package.module:Class`` and the ``rsstp.strategies``
entry points of installed distributions; a strategy that fails stops the run in one line."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from rsstp_replay import open_recording
from waiting import HANG_S

STRATEGIES = """
from rsstp_sim import AgentView, StrategyBase


class Clockwise(StrategyBase):
    name = "clockwise"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[-1]


class Breaks(StrategyBase):
    name = "breaks"

    def choose_action(self, agent: AgentView) -> int:
        if agent.step == 6:
            raise RuntimeError("boom")
        return agent.actions[0]


class Wanders(StrategyBase):
    name = "wanders"

    def choose_action(self, agent: AgentView) -> int:
        return 99


class Corrupts(StrategyBase):
    name = "corrupts"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[0]

    def refine(self, agent: AgentView) -> None:
        if agent.step == 5:
            agent.model.merge(0, 99)


class NotOne:
    pass
"""


def cli(program: str, *args: str, path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", program, *args],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        env={**os.environ, "PYTHONPATH": f"{path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"},
    )


@pytest.fixture
def mine(tmp_path: Path) -> Path:
    """A module of strategies, and a distribution declaring one as an entry point (found by
    importlib.metadata on the path, as an installed one is)."""
    (tmp_path / "my_strategies.py").write_text(STRATEGIES)
    info = tmp_path / "my_strategies-1.2.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: my-strategies\nVersion: 1.2\n")
    (info / "top_level.txt").write_text("my_strategies\n")
    (info / "entry_points.txt").write_text(
        "[rsstp.strategies]\nclockwise = my_strategies:Clockwise\n"
    )
    return tmp_path


@pytest.mark.parametrize("provided", [True, False], ids=["installed", "on-the-path"])
def test_a_class_by_its_import_path_records_and_audits(mine: Path, provided: bool) -> None:
    """The recording names the class, and the distribution providing its package if any."""
    if not provided:
        (mine / "my_strategies-1.2.dist-info" / "top_level.txt").unlink()
    out = mine / "run.mcap"
    done = cli(
        "rsstp_cli.sim", "record", "thesis-roulette", "--strategy", "my_strategies:Clockwise",
        "--steps", "20", "-o", str(out), path=mine,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    with open_recording(out) as recording:
        assert recording.strategy == "clockwise"
        assert recording.n_steps == 20
        strategy = recording.scenario_record.strategy
        assert strategy.import_path == "my_strategies:Clockwise"
        found = (strategy.distribution, strategy.version)
        assert found == (("my-strategies", "1.2") if provided else (None, None))
        assert recording.metadata["strategy_distribution"] == ("my-strategies" if provided else "")
    assert cli("rsstp_cli.replay", "audit", str(out), path=mine).returncode == 0


@pytest.mark.slow
def test_an_entry_point_is_listed_and_runs_by_name(mine: Path) -> None:
    listed = cli("rsstp_cli.sim", "strategies", path=mine)
    assert listed.returncode == 0
    assert "clockwise    my_strategies:Clockwise (my-strategies 1.2)" in listed.stdout
    ran = cli("rsstp_cli.sim", "run", "thesis-roulette", "--strategy", "clockwise", "--steps", "8",
              path=mine)  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    assert "sensations seen: false: 6, true: 3" in ran.stdout  # the start, then every 4 moves
    out = mine / "by-name.mcap"
    recorded = cli("rsstp_cli.sim", "record", "thesis-roulette", "--strategy", "clockwise",
                   "--steps", "4", "-o", str(out), path=mine)  # fmt: skip
    assert recorded.returncode == 0, recorded.stderr
    info = cli("rsstp_cli.replay", "info", str(out), path=mine)
    assert "  class: my_strategies:Clockwise (from my-strategies 1.2)" in info.stdout


@pytest.mark.parametrize(
    ("strategy", "message", "kept"),
    [
        (  # its own code raises
            "Breaks",
            "strategy 'breaks' failed in choose_action at step 7: RuntimeError: boom",
            6,
        ),
        (  # a model operation that would break the model's invariants
            "Corrupts",
            "strategy 'corrupts' failed in refine at step 5: "
            "ModelError: merge: unknown state 99 (states: [0])",
            4,
        ),
    ],
)
def test_a_failing_strategy_stops_in_one_line_and_keeps_a_valid_file(
    mine: Path, strategy: str, message: str, kept: int
) -> None:
    out = mine / "broken.mcap"
    done = cli(
        "rsstp_cli.sim", "record", "thesis-roulette", "--strategy", f"my_strategies:{strategy}",
        "--steps", "50", "-o", str(out), path=mine,
    )  # fmt: skip
    side = mine / "broken.mcap.partial"
    assert done.returncode == 2
    assert done.stderr.strip() == (
        f"rsstp-sim: error: {message}; the steps before it are in {side} (finished); {out} was "
        "not touched"
    )
    assert not out.exists()
    with open_recording(side) as recording:
        assert recording.finished and recording.n_steps == kept
    assert cli("rsstp_cli.replay", "check", str(side), path=mine).returncode == 0


def test_the_documented_strategy_records_and_learns_its_world(tmp_path: Path) -> None:
    """docs/strategies.md's complete strategy, run with the page's own commands, records the
    class's import path."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "strategies.md").read_text()
    code = re.search(r"```python file=my_strategies.py\n(.*?)```", page, re.S)
    assert code is not None
    (tmp_path / "my_strategies.py").write_text(code[1])
    commands = re.search(r"```sh\n(PYTHONPATH=\. rsstp-sim record .*?)```", page, re.S)
    assert commands is not None
    bin_folder = Path(sys.executable).parent
    done = subprocess.run(
        ["bash", "-e", "-c", commands[1]],
        capture_output=True, text=True, timeout=HANG_S, cwd=tmp_path,
        env={**os.environ, "PATH": f"{bin_folder}{os.pathsep}{os.environ['PATH']}"},
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    expected = "verdict: learned: equivalent to the minimal model (4 states) from step 4 to the end"
    assert (tmp_path / "cycle-audit.txt").read_text().splitlines()[0] == expected
    with open_recording(tmp_path / "cycle.mcap") as recording:
        assert recording.scenario_record.strategy.import_path == "my_strategies:Cycle"


@pytest.mark.parametrize(
    ("strategy", "message"),
    [
        (
            "my_strategies:Wanders",
            "strategy 'wanders' at step 1: action 99 is not one of the scenario's actions [0]",
        ),
        ("my_strategies:NotOne", "strategy 'my_strategies:NotOne': NotOne is not a strategy"),
        ("my_strategies:Nowhere", "strategy 'my_strategies:Nowhere': 'my_strategies' has no"),
        ("no_such_module:X", "strategy 'no_such_module:X': cannot import 'no_such_module'"),
        ("nameless", "unknown strategy 'nameless' (built-in: learner, random, roulette"),
    ],
)
def test_a_strategy_that_cannot_run_is_one_line(mine: Path, strategy: str, message: str) -> None:
    done = cli("rsstp_cli.sim", "run", "thesis-roulette", "--strategy", strategy, "--steps", "5",
               path=mine)  # fmt: skip
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert message in lines[0]
