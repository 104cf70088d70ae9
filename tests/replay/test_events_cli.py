"""``rsstp-replay events``: the events table of a real recording, as Parquet or CSV."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from rsstp_replay import open_recording
from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.recording import record
from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[2]


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", *args],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Roulette splits at every sensation change; three-joint's random walk is blocked."""
    path = tmp_path_factory.mktemp("events") / "roulette.mcap"
    record(path, load_scenario("thesis-roulette"), make_strategy("roulette"), steps=50, seed=0)
    return path


def test_events_to_parquet_equal_the_recordings_events(run: Path, tmp_path: Path) -> None:
    out = tmp_path / "events.parquet"
    done = run_cli("events", str(run), "-o", str(out))
    assert done.returncode == 0, done.stderr
    with open_recording(run) as recording:
        expected = recording.events()
    assert done.stdout.strip() == f"wrote {len(expected):,} rows and 4 columns to {out}"
    found = pd.read_parquet(out)
    pd.testing.assert_frame_equal(found, expected)
    assert (found["kind"] == "split").sum() > 5


def test_events_of_some_kinds_to_csv(run: Path, tmp_path: Path) -> None:
    out = tmp_path / "splits.csv"
    done = run_cli("events", str(run), "-o", str(out), "--kind", "split", "--kind", "merge")
    assert done.returncode == 0, done.stderr
    with open_recording(run) as recording:
        events = recording.events()
    expected = events.loc[events["kind"].isin(["split", "merge"])]
    found = pd.read_csv(out)
    assert found["step"].tolist() == expected["step"].tolist()
    assert set(found["kind"]) == {"split"}  # roulette never merges
    assert found["text"].tolist() == expected["text"].tolist()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["-o", "{tmp}/e.txt"], "unknown table format '.txt': expected .parquet or .csv"),
        (["-o", "{tmp}/missing/e.csv"], "the output directory {tmp}/missing does not exist"),
        (["-o", "{tmp}/e.csv", "--kind", "bump"], "events: unknown kind 'bump': expected one of"),
        (["-o", "{existing}"], "already exists (use --force to overwrite)"),
    ],
)
def test_bad_outputs_are_one_line(run: Path, tmp_path: Path, args: list[str], message: str) -> None:
    existing = tmp_path / "old.csv"
    existing.write_text("kept\n")
    filled = [a.format(tmp=tmp_path, existing=existing) for a in args]
    done = run_cli("events", str(run), *filled)
    assert done.returncode == 2
    assert message.format(tmp=tmp_path) in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr
    assert existing.read_text() == "kept\n"
