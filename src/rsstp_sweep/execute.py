"""One run of a sweep, as a worker does it: record, audit, keep the findings beside the file.

:func:`execute_run` records the run to a local temporary file (byte for byte what
``rsstp-sim record`` writes), audits it against the ground truth of the world the run was
recorded in (read from the truth cache, or enumerated by that world's own table, and handed
to the truth audit), copies it into the output
directory under a temporary name and renames it there, then writes its findings to
``findings/<run>.json``. A recording in the output is therefore finished or absent under its
own name; a run interrupted anywhere leaves nothing a later sweep would trust.

A later sweep into the same directory reuses a run whose recording is finished, passes its
chunk checks and matches the run's scenario, strategy, parameters, seed and steps: with its
findings file the run is not touched at all, without it only the audit runs again.

Every failure inside a run (the strategy raising, a full disk) becomes the run's ``failed``
row with the error's one line; the worker itself never raises for it.
"""

from __future__ import annotations

import json
import tempfile
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rsstp_sweep.plan import Run

if TYPE_CHECKING:
    from rsstp_sim.interface import World
    from rsstp_sim.truth import GroundTruth

__all__ = ["FINDINGS", "ROW_FIELDS", "execute_run", "failed_row", "finished_row"]

FINDINGS = "findings"
"""The folder of the output directory that holds each run's findings as JSON."""

ROW_FIELDS = (
    "run",
    "scenario",
    "scenario_sha256",
    "strategy",
    "params",
    "seed",
    "steps",
    "status",
    "error",
    "reused",
    "recording",
    "seconds",
    "seconds_record",
    "seconds_audit",
    "recorded_steps",
    "stopped_at_step",
    "model_versions",
    "final_states",
    "final_transitions",
    "final_deterministic",
    "minimal_states",
    "equivalent",
    "learned_at_step",
    "contradictory_states",
    "contradictions_within_versions",
    "blocked",
    "no_transition",
)
"""The columns of ``runs.parquet``, in order (see the README for what each means)."""


def execute_run(run: Run, output: str) -> dict[str, Any]:
    """Record and audit ``run`` into ``output`` (a local folder or an fsspec URL); return its
    row of ``runs.parquet``."""
    import fsspec

    began = time.perf_counter()
    try:
        fs, root = fsspec.core.url_to_fs(output)
        target = f"{root.rstrip('/')}/{run.recording}"
        findings_path = f"{root.rstrip('/')}/{FINDINGS}/{run.name}.json"
        kept = _kept_findings(fs, target, findings_path, run)
        if kept is not None:
            return {**kept, "reused": True}
        with tempfile.TemporaryDirectory(prefix="rsstp-sweep-", dir=_scratch()) as scratch:
            local = Path(scratch) / run.recording
            reused = _fetch_valid(fs, target, local, run)
            seconds_record, world = 0.0, None
            if not reused:
                seconds_record, world = _record(run, local)
            started = time.perf_counter()
            truth = None if world is None else _truth_of(world)
            world = None  # its table goes before the recording is read
            findings = _audit(local, truth)
            seconds_audit = time.perf_counter() - started
            if not reused:
                part = f"{target}.part"
                fs.put_file(str(local), part)
                fs.mv(part, target)
        row = {
            **_config(run),
            "status": "done",
            "error": None,
            "reused": reused,
            "seconds": time.perf_counter() - began,
            "seconds_record": seconds_record,
            "seconds_audit": seconds_audit,
            **findings,
        }
        fs.makedirs(f"{root.rstrip('/')}/{FINDINGS}", exist_ok=True)
        with fs.open(f"{findings_path}.part", "w") as out:
            json.dump(row, out, indent=1)
        fs.mv(f"{findings_path}.part", findings_path)
        return row
    except Exception as exc:  # a run's own failure is its row; the sweep goes on
        return failed_row(run, _one_line(exc), seconds=time.perf_counter() - began)


def finished_row(run: Run, output: str) -> dict[str, Any] | None:
    """The row a run wrote when it finished (its findings, its recording whole), or None: for
    a run whose result never reached the sweep (it was interrupted just then)."""
    import fsspec

    try:
        fs, root = fsspec.core.url_to_fs(output)
        target = f"{root.rstrip('/')}/{run.recording}"
        return _kept_findings(fs, target, f"{root.rstrip('/')}/{FINDINGS}/{run.name}.json", run)
    except OSError:
        return None


def failed_row(run: Run, error: str, *, seconds: float | None = None) -> dict[str, Any]:
    """The row of a run that did not finish, with the error's one line."""
    row = dict.fromkeys(ROW_FIELDS)
    row.update(_config(run))
    row.update(status="failed", error=error, reused=False, seconds=seconds)
    return row


def _config(run: Run) -> dict[str, Any]:
    return {
        "run": run.name,
        "scenario": run.scenario,
        "scenario_sha256": run.scenario_sha256,
        "strategy": run.strategy,
        "params": run.params_json,
        "seed": run.seed,
        "steps": run.steps,
        "recording": run.recording,
    }


def _record(run: Run, path: Path) -> tuple[float, World]:
    """Record ``run`` to ``path``: the seconds it took, and the world it ran in."""
    from rsstp_sim.recording.recorder import Recorder
    from rsstp_sim.scenario import parse_scenario
    from rsstp_sim.strategies import make_strategy

    # The plan checked the text; the start pose is checked where the world is built.
    scenario = parse_scenario(run.scenario_source, origin=run.scenario_origin, check_start=False)
    started = time.perf_counter()
    recorder = Recorder(path, scenario, make_strategy(run.strategy, run.params), seed=run.seed)
    recorder.run(run.steps)  # what record() does, keeping the recorder's world at hand
    return time.perf_counter() - started, recorder.runner.world


def _truth_of(world: World) -> GroundTruth:
    """The ground truth of the world a run was recorded in: read from the truth cache, or
    enumerated by the world's own table (not another one built from the scenario)."""
    from rsstp_sim.truth.cache import load_truth

    return load_truth(world.scenario, world=world)


def _audit(path: Path, truth: GroundTruth | None) -> dict[str, Any]:
    """The findings of the recording at ``path``; ``truth``: its world's ground truth (None:
    a recording kept from an earlier sweep, whose truth the truth audit loads)."""
    from rsstp_replay.audits import audit_truth, run_audits
    from rsstp_replay.audits.loaded import load
    from rsstp_replay.reader.recording import open_recording

    with open_recording(path) as recording:
        loaded = load(recording)
        report = run_audits(loaded)
        audited = audit_truth(loaded, truth=truth, within_versions=report.within_versions)
    summary, verdict = report.summary, audited.verdict
    final = report.determinism.final.version
    return {
        "recorded_steps": summary.steps,
        "stopped_at_step": None if summary.stop is None else summary.stop.step,
        "model_versions": len(summary.sizes),
        "final_states": summary.final_size.states,
        "final_transitions": summary.final_size.transitions,
        "final_deterministic": summary.final_deterministic,
        "minimal_states": verdict.minimal_states,
        "equivalent": verdict.learned,
        "learned_at_step": verdict.learned_at_step,
        "contradictory_states": sum(
            found.version == final for found in report.within_versions.contradictions
        ),
        "contradictions_within_versions": len(report.within_versions.contradictions),
        "blocked": summary.blocked,
        "no_transition": summary.no_transition,
    }


def _kept_findings(fs: Any, target: str, findings_path: str, run: Run) -> dict[str, Any] | None:
    """The findings of an earlier sweep's run, when they and its recording are whole."""
    if not fs.exists(findings_path) or not fs.exists(target):
        return None
    try:
        with fs.open(findings_path, "r") as file:
            row: dict[str, Any] = json.load(file)
    except (OSError, ValueError):
        return None
    if row.get("status") != "done" or any(row.get(k) != v for k, v in _config(run).items()):
        return None
    with _local_copy(fs, target) as local:
        if _check(local, run) != "valid":
            return None
    return row


def _fetch_valid(fs: Any, target: str, local: Path, run: Run) -> bool:
    """Copy an earlier sweep's recording of ``run`` to ``local`` when it is valid; refuse to
    replace a whole recording of another run (``target`` is only redone when broken)."""
    if not fs.exists(target):
        return False
    fs.get_file(target, str(local))
    found = _check(local, run)
    if found == "valid":
        return True
    local.unlink()
    if found == "other":
        raise FileExistsError(
            f"{target}: already holds a finished recording of another run (other steps, "
            "seed, parameters or scenario text); not overwritten: sweep into another folder"
        )
    return False


@contextmanager
def _local_copy(fs: Any, path: str) -> Iterator[Path]:
    """``path`` as a local file (itself on a local file system, else a temporary copy)."""
    if "file" in fs.protocol or "local" in fs.protocol:
        yield Path(path)
        return
    with tempfile.TemporaryDirectory(prefix="rsstp-sweep-", dir=_scratch()) as scratch:
        local = Path(scratch) / "recording.mcap"
        fs.get_file(path, str(local))
        yield local


def _check(path: Path, run: Run) -> str:
    """``valid``: a finished recording of exactly this run whose every chunk passes its CRC;
    ``other``: such a recording, of another run; ``broken``: anything else."""
    from rsstp_replay.reader.recording import open_recording
    from rsstp_sim.errors import RsstpError

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an unfinished file is simply broken
            with open_recording(path) as recording:
                if not recording.finished:
                    return "broken"
                recording.verify_chunks()
                same = (
                    _steps_of(recording) == run.steps
                    and recording.seed == run.seed
                    and recording.strategy_params == dict(run.recorded_params)
                    and recording.metadata.get("scenario_sha256") == run.scenario_sha256
                    and recording.strategy == run.strategy_name
                )
                return "valid" if same else "other"
    except (RsstpError, OSError):
        return "broken"


def _steps_of(recording: Any) -> int:
    """The steps a finished recording was given: its last step, or its budget when the strategy
    ended the run before it (its stop event says so)."""
    from rsstp_replay.audits.summary import strategy_stop

    stop = strategy_stop(recording.events())
    if stop is None or stop.budget is None or stop.step != recording.n_steps:
        return int(recording.n_steps)
    return stop.budget


def _scratch() -> str | None:
    """The Dask worker's own folder (removed with the worker, even when a run is cut off), or
    the system's temporary folder outside a worker."""
    try:
        from distributed import get_worker

        return str(get_worker().local_directory)
    except (ImportError, ValueError):
        return None


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    if not isinstance(exc, OSError) and type(exc).__module__ != "rsstp_sim.errors":
        text = f"{type(exc).__name__}: {text}"
    return text[:500]
