"""``rsstp-sim sweep`` on real Dask clusters: a LocalCluster of two worker processes, and a
scheduler and a worker started as separate processes on 127.0.0.1. Each run's recording is
byte for byte what ``rsstp-sim record`` writes; failures are rows, not crashes; a rerun keeps
what is whole and redoes the rest; Ctrl-C keeps every finished run."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

from rsstp_replay import open_recording
from rsstp_sim.recording.recorder import record
from rsstp_sim.scenario import load_scenario
from rsstp_sim.strategies import make_strategy
from rsstp_sim.truth.cache import truth_cache_dir, truth_key
from scenarios import sweep_toml
from waiting import HANG_S, wait_until

FAULTY = """
import os
import signal

from rsstp_sim import AgentView, StrategyBase


class Breaks(StrategyBase):
    name = "breaks"

    def choose_action(self, agent: AgentView) -> int:
        if agent.step == 40:
            raise RuntimeError("boom at 40")
        return agent.actions[0]


class Dies(StrategyBase):
    name = "dies"

    def choose_action(self, agent: AgentView) -> int:
        if agent.step == 40:
            os.kill(os.getpid(), signal.SIGKILL)  # as the kernel's OOM killer would
        return agent.actions[0]
"""

SWEEP = sweep_toml(steps=300, seeds=2, more_strategies=["sweep_faulty:Breaks"])


def sweep_cli(*args: str, path: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "sweep", *args],
        capture_output=True,
        text=True,
        timeout=HANG_S,
        env=_env(path),
    )


def report_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.replay", "report", *args],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )


def _env(path: Path) -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": f"{path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}"}


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A sweep file and the faulty strategy's module beside it."""
    base = tmp_path_factory.mktemp("sweep")
    (base / "sweep_faulty.py").write_text(FAULTY)
    (base / "sweep.toml").write_text(SWEEP)
    return base


@pytest.fixture(scope="module")
def swept(folder: Path) -> tuple[Path, subprocess.CompletedProcess[str]]:
    out = folder / "out"
    done = sweep_cli(str(folder / "sweep.toml"), "-o", str(out), "--workers", "2", path=folder)
    return out, done


def test_every_run_is_a_row_and_a_failing_run_does_not_stop_the_others(
    swept: tuple[Path, subprocess.CompletedProcess[str]],
) -> None:
    out, done = swept
    assert done.returncode == 1, done.stderr
    assert "8 of 12 runs done, 0 kept" not in done.stdout
    assert "8 of 12 runs done, 4 failed" in done.stdout
    failures = [line for line in done.stderr.splitlines() if "failed:" in line]
    assert len(failures) == 4 and all("boom at 40" in line for line in failures)
    assert "Traceback" not in done.stderr
    runs = pd.read_parquet(out / "runs.parquet")
    assert len(runs) == 12
    assert list(runs["status"]).count("done") == 8
    failed = runs[runs["status"] == "failed"]
    assert set(failed["strategy"]) == {"sweep_faulty:Breaks"}
    assert failed["error"].str.contains("RuntimeError: boom at 40").all()
    assert not any((out / name).exists() for name in failed["recording"])  # no half file
    learner = runs[(runs["strategy"] == "learner") & (runs["scenario"] == "thesis-roulette")]
    assert learner["equivalent"].all() and (learner["learned_at_step"] > 0).all()
    assert (learner["minimal_states"] == 4).all() and (learner["final_states"] == 4).all()
    # The learner stops when done: its steps used, of the sweep's budget; a script never stops.
    assert (learner["stopped_at_step"] == learner["recorded_steps"]).all()
    assert (learner["recorded_steps"] < learner["steps"]).all()
    script = runs[runs["strategy"] == "script"]
    assert script["stopped_at_step"].isna().all()
    assert (script["recorded_steps"] == script["steps"]).all()
    assert not script["equivalent"].any() and script["learned_at_step"].isna().all()
    assert (runs.loc[runs["status"] == "done", "seconds"] > 0).all()
    assert (out / "sweep.toml").read_text() == SWEEP
    meta = json.loads((out / "sweep.json").read_text())
    assert meta["package_version"] and meta["runs"] == list(runs["run"])
    kept = {path.stem for path in truth_cache_dir().glob("*.npz")}  # the workers share it
    assert {truth_key(load_scenario(name)) for name in set(runs["scenario"])} <= kept


def test_each_recording_is_the_one_record_writes(
    swept: tuple[Path, subprocess.CompletedProcess[str]], tmp_path: Path
) -> None:
    out, _ = swept
    runs = pd.read_parquet(out / "runs.parquet")
    for row in runs[runs["status"] == "done"].itertuples():
        alone = tmp_path / f"{row.run}.mcap"
        strategy = make_strategy(row.strategy, json.loads(row.params))
        record(alone, load_scenario(row.scenario), strategy, steps=row.steps, seed=row.seed)
        assert alone.read_bytes() == (out / row.recording).read_bytes(), row.run


@pytest.mark.slow
def test_a_rerun_keeps_whole_runs_and_redoes_broken_ones(
    swept: tuple[Path, subprocess.CompletedProcess[str]], folder: Path, tmp_path: Path
) -> None:
    out = tmp_path / "again"
    shutil.copytree(swept[0], out)
    truncated = out / "one-joint-10__learner__seed1.mcap"
    whole = truncated.read_bytes()
    truncated.write_bytes(whole[: len(whole) // 2])  # a killed writer's half file
    (out / "thesis-roulette__learner__seed0.mcap").unlink()
    (out / "findings" / "one-joint-10__learner__seed0.json").unlink()  # only the audit redone
    untouched = out / "thesis-roulette__learner__seed1.mcap"
    before = untouched.stat().st_mtime_ns
    (out / "runs.parquet").unlink()

    done = sweep_cli(str(folder / "sweep.toml"), "-o", str(out), "--workers", "2", path=folder)
    assert done.returncode == 1, done.stderr
    assert "8 of 12 runs done (6 kept from before), 4 failed" in done.stdout
    assert truncated.read_bytes() == whole
    assert untouched.stat().st_mtime_ns == before
    runs = pd.read_parquet(out / "runs.parquet").set_index("run")
    assert not runs.loc["one-joint-10__learner__seed1", "reused"]
    assert runs.loc["one-joint-10__learner__seed0", "reused"]
    assert runs.loc["thesis-roulette__learner__seed1", "reused"]
    original = pd.read_parquet(swept[0] / "runs.parquet").set_index("run")
    columns = ["final_states", "learned_at_step", "equivalent", "blocked"]
    assert runs[columns].equals(original[columns])

    # The same folder with other steps: a whole recording of another run is never replaced.
    changed = folder / "longer.toml"
    changed.write_text(SWEEP.replace("steps = 300", "steps = 310"))
    done = sweep_cli(str(changed), "-o", str(out), "--workers", "2", path=folder)
    assert done.returncode == 1
    assert "already holds a finished recording of another run" in done.stderr
    assert truncated.read_bytes() == whole


@pytest.mark.slow
def test_a_run_that_kills_its_worker_is_a_failed_row(folder: Path, tmp_path: Path) -> None:
    sweep = tmp_path / "kills.toml"
    sweep.write_text(
        'steps = 300\nseeds = 2\nscenarios = ["thesis-roulette"]\n'
        '[[strategy]]\nname = "learner"\n[[strategy]]\nname = "sweep_faulty:Dies"\n'
    )
    out = tmp_path / "out"
    done = sweep_cli(str(sweep), "-o", str(out), "--workers", "2", path=folder)
    assert done.returncode == 1
    assert "Traceback" not in done.stderr and "distributed" not in done.stderr
    assert done.stderr.count("its worker process died while running it") == 2
    runs = pd.read_parquet(out / "runs.parquet")
    assert list(runs["status"]) == ["done", "done", "failed", "failed"]


@pytest.mark.slow
def test_a_sweep_runs_on_a_scheduler_started_apart(folder: Path, tmp_path: Path) -> None:
    """`dask scheduler` and `dask worker` as their own processes, on 127.0.0.1."""
    dask = shutil.which("dask", path=str(Path(sys.executable).parent))
    assert dask is not None
    info = tmp_path / "scheduler.json"
    env = _env(folder)
    scheduler = subprocess.Popen(
        [dask, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
         "--scheduler-file", str(info)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
    )  # fmt: skip
    worker = None
    try:
        wait_until(info.exists, "the scheduler's file", process=scheduler)
        address = json.loads(info.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        worker = subprocess.Popen(
            [dask, "worker", "--scheduler-file", str(info), "--nthreads", "1",
             "--no-dashboard", "--host", "127.0.0.1"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
        )  # fmt: skip
        sweep = tmp_path / "small.toml"
        sweep.write_text(
            'steps = 200\nseeds = [4, 9]\nscenarios = ["thesis-roulette"]\n'
            '[[strategy]]\nname = "learner"\n'
        )
        out = tmp_path / "out"
        url = f"file://{out}"  # an fsspec URL, as s3://... would be
        done = sweep_cli(str(sweep), "-o", url, "--scheduler", address, path=folder)
        assert done.returncode == 0, done.stderr
        assert "2 of 2 runs done, 0 failed" in done.stdout
        runs = pd.read_parquet(out / "runs.parquet")
        assert list(runs["seed"]) == [4, 9] and runs["equivalent"].all()
        assert report_cli(url, "--fail-if", "learned_fraction < 1").returncode == 0
        assert scheduler.poll() is None  # a cluster given is left running
    finally:
        for process in (worker, scheduler):
            if process is not None:
                process.terminate()
                process.wait(timeout=HANG_S)


@pytest.mark.slow
def test_ctrl_c_keeps_every_finished_run(folder: Path, tmp_path: Path) -> None:
    """Ctrl-C reaches the sweep and its workers; the sweep stops them, writes its table and
    keeps each finished recording; nothing half written remains."""
    sweep = tmp_path / "long.toml"
    sweep.write_text(
        'steps = 4000\nseeds = 40\nscenarios = ["one-joint-10"]\n[[strategy]]\nname = "learner"\n'
        "params = { stop = false }\n"  # each run its whole 4,000 steps, done or not
    )
    out = tmp_path / "out"
    process = subprocess.Popen(
        [sys.executable, "-m", "rsstp_cli.sim", "sweep", str(sweep), "-o", str(out)]
        + ["--workers", "1"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(folder),
        start_new_session=True,
    )
    try:
        wait_until(lambda: len(_findings(out)) >= 2, "two runs' findings", process=process)
        os.killpg(process.pid, signal.SIGINT)  # as Ctrl-C at a terminal: the whole group
        stdout, stderr = process.communicate(timeout=HANG_S)
    finally:
        if process.poll() is None:
            process.kill()
    assert process.returncode == 130, stderr
    assert "interrupted: kept" in stderr and "Traceback" not in stderr
    runs = pd.read_parquet(out / "runs.parquet")
    done = runs[runs["status"] == "done"]
    assert 2 <= len(done) < 40
    assert (runs["status"] == "not run").sum() == 40 - len(runs[runs["status"] != "not run"])
    for name in done["recording"]:
        with open_recording(out / name) as recording:
            assert recording.finished and recording.n_steps == 4000
    assert not list(out.glob("*.part"))


def _findings(out: Path) -> list[Path]:
    return list((out / "findings").glob("*.json")) if (out / "findings").exists() else []


@pytest.mark.parametrize(
    ("sweep", "message"),
    [
        ("steps = 10\nseeds = 1\nscenarios = ['nope']\n[[strategy]]\nname = 'learner'\n",
         "nope: no such scenario file"),
        ("steps = 10\nseeds = 1\nscenarios = ['one-joint-10']\n[[strategy]]\nname = 'zzz'\n",
         "strategy[0]: unknown strategy 'zzz'"),
    ],
)  # fmt: skip
def test_a_bad_sweep_is_one_line_before_anything_runs(
    sweep: str, message: str, tmp_path: Path
) -> None:
    file = tmp_path / "bad.toml"
    file.write_text(sweep)
    done = sweep_cli(str(file), "-o", str(tmp_path / "out"), path=tmp_path)
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1 and message in done.stderr
    assert not (tmp_path / "out").exists()


def test_an_output_that_is_a_file_is_one_line(folder: Path, tmp_path: Path) -> None:
    taken = tmp_path / "taken"
    taken.write_text("mine")
    done = sweep_cli(str(folder / "sweep.toml"), "-o", str(taken), path=folder)
    assert done.returncode == 2
    assert f"{taken}: exists and is not a folder" in done.stderr
    assert taken.read_text() == "mine"


@pytest.fixture
def report_dir(swept: tuple[Path, subprocess.CompletedProcess[str]]) -> Iterator[Path]:
    yield swept[0]


def test_report_gives_one_row_per_scenario_and_strategy(report_dir: Path) -> None:
    done = report_cli(str(report_dir), "--json")
    assert done.returncode == 0, done.stderr
    rows = {(r["scenario"], r["strategy"]): r for r in json.loads(done.stdout)}
    assert len(rows) == 6
    learner = rows[("thesis-roulette", "learner")]
    assert learner["runs"] == 2 and learner["learned_fraction"] == 1.0
    assert learner["learned_at_step_median"] > 0 and learner["minimal_states"] == 4
    faulty = rows[("one-joint-10", "sweep_faulty:Breaks")]
    assert faulty["failed"] == 2 and faulty["learned_fraction"] == 0.0
    assert faulty["learned_at_step_median"] is None
    text = report_cli(str(report_dir)).stdout
    assert "thesis-roulette" in text and "100%" in text and "4 / 4" in text


@pytest.mark.slow
def test_report_gates_and_plots(report_dir: Path, tmp_path: Path) -> None:
    gate = ["--strategy", "learner", "--fail-if"]
    passing = report_cli(str(report_dir), *gate, "learned_fraction < 0.5", "--quiet-not-an-option")
    assert passing.returncode == 2  # an unknown option is one line
    on_roulette = report_cli(str(report_dir), "--strategy", "learner", "--fail-if", "failed > 0")
    assert on_roulette.returncode == 0, on_roulette.stderr
    failing = report_cli(str(report_dir), *gate, "learned_fraction < 0.9")
    assert failing.returncode == 1  # one-joint-10 is not learned in 300 steps
    assert "one-joint-10 / learner: learned_fraction = 0" in failing.stderr
    assert "thesis-roulette" not in failing.stderr
    bad = report_cli(str(report_dir), "--fail-if", "learnt < 1")
    assert bad.returncode == 2 and "unknown metric 'learnt'" in bad.stderr
    plot = tmp_path / "learned.png"
    done = report_cli(str(report_dir), "--plot", str(plot))
    assert done.returncode == 0, done.stderr
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and plot.stat().st_size > 10_000
    again = report_cli(str(report_dir), "--plot", str(plot))
    assert again.returncode == 2 and "already exists" in again.stderr


def test_report_of_a_folder_that_is_not_a_sweep_is_one_line(tmp_path: Path) -> None:
    done = report_cli(str(tmp_path))
    assert done.returncode == 2
    assert "no runs.parquet (is it a sweep's output folder?)" in done.stderr
