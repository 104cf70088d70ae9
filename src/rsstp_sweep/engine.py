"""Run a checked sweep on Dask and gather one table.

Without a scheduler address, :func:`run_sweep` starts a ``distributed.LocalCluster`` of
worker processes (one thread each, listening on 127.0.0.1) and closes it at the end; with
one, it submits to that cluster and leaves it running. Each run is one task
(:func:`~rsstp_sweep.execute.execute_run`); its row arrives as it finishes. The output
directory gets, besides the recordings and ``findings/``:

- ``sweep.toml``: the sweep file as given;
- ``sweep.json``: the package and library versions, the runs' names and the sweep's origin;
- ``runs.parquet``: one row per run, in the sweep file's order, written at the end and also
  when the sweep is interrupted (runs that did not finish are rows with status ``not run``).

A worker process that dies (out of memory, a signal, a crash in native code) takes with it
every run the scheduler had given it, and Dask gives up on a run that was on dying workers
too often (``KilledWorker``; on the local cluster at the first death), whether it was the
culprit or a bystander. So such a run is run once more at the end, alone on the cluster: only
a run that kills its worker then too is a failed row. A run's result leaves the cluster as
soon as its row is taken, so that a worker that dies later has nothing to recompute.
"""

from __future__ import annotations

import io
import json
import logging
import signal
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import pandas as pd

from rsstp_sweep.execute import ROW_FIELDS, execute_run, failed_row, finished_row
from rsstp_sweep.plan import Run, Sweep, check_starts

__all__ = ["RUNS_TABLE", "SweepResult", "run_sweep", "runs_frame"]

RUNS_TABLE = "runs.parquet"

_LOCAL_CLUSTER_CONFIG = {
    # A run on a worker that dies is suspect at once: it runs again alone at the end, where
    # one death settles it (Dask's default, 3 retries, would kill 4 workers per such run).
    "distributed.scheduler.allowed-failures": 0,
    # A dead worker's nanny starts another, however long that takes on a busy machine. Dask's
    # default closes the nanny of a worker not back within 15 s: once every nanny was closed,
    # the runs left waited for a worker forever.
    "distributed.deploy.lost-worker-timeout": "1 day",
}

_KILLED = (
    "its worker process died while running it, also when it ran alone (killed: out of "
    "memory, a signal, or a crash in native code)"
)


@dataclass(frozen=True, slots=True)
class SweepResult:
    """What a sweep did: its table (one row per run) and whether it was interrupted."""

    runs: pd.DataFrame
    interrupted: bool

    @property
    def failed(self) -> pd.DataFrame:
        return self.runs[self.runs["status"] == "failed"]

    @property
    def done(self) -> int:
        return int((self.runs["status"] == "done").sum())


def run_sweep(
    sweep: Sweep,
    output: str,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    on_row: Callable[[Mapping[str, Any]], None] | None = None,
) -> SweepResult:
    """Run every run of ``sweep`` into ``output`` (a folder or fsspec URL); see the module
    docstring. ``on_row`` is called with each row as its run ends. Ctrl-C cancels the runs
    not finished and returns with ``interrupted`` set; the finished runs are kept. A scenario
    whose body cannot stand at its start pose is refused first (:func:`~rsstp_sweep.plan.
    check_starts`)."""
    import dask
    import fsspec

    check_starts(sweep)
    fs, root = fsspec.core.url_to_fs(output)
    fs.makedirs(root, exist_ok=True)
    _write_metadata(fs, root, sweep)
    rows: dict[str, dict[str, Any]] = {}
    # The local cluster's settings last as long as the cluster: its event loop reads them.
    with dask.config.set(_LOCAL_CLUSTER_CONFIG if scheduler is None else {}):
        interrupted = _run_on_cluster(
            sweep, output, workers=workers, scheduler=scheduler, rows=rows, on_row=on_row
        )
    if interrupted:  # a run may have finished while its result was on the way
        for run in sweep.runs:
            if run.name not in rows:
                row = finished_row(run, output)
                if row is not None:
                    rows[run.name] = row
                    if on_row is not None:
                        on_row(row)
    table = runs_frame([rows.get(run.name) or _not_run(run) for run in sweep.runs])
    buffer = io.BytesIO()
    table.to_parquet(buffer, index=False)
    with fs.open(f"{root.rstrip('/')}/{RUNS_TABLE}", "wb") as out:
        out.write(buffer.getvalue())
    return SweepResult(table, interrupted)


def _run_on_cluster(
    sweep: Sweep,
    output: str,
    *,
    workers: int | None,
    scheduler: str | None,
    rows: dict[str, dict[str, Any]],
    on_row: Callable[[Mapping[str, Any]], None] | None,
) -> bool:
    """Run the sweep's runs on the cluster at ``scheduler`` (None: a local one, closed at the
    end), putting each run's row in ``rows`` as it comes; whether Ctrl-C stopped it."""
    from distributed import Client, KilledWorker, LocalCluster, as_completed

    cluster = None
    if scheduler is None:
        # The workers are started ignoring SIGINT (a disposition a new process inherits): a
        # Ctrl-C at the terminal reaches the whole process group, and it is this process
        # that stops the sweep and then the cluster, the runs in flight with it.
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            cluster = LocalCluster(
                n_workers=workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address="127.0.0.1:0",  # any free port: never 8787 taken by another
                silence_logs=logging.CRITICAL,  # a run's failure is its row and one line
            )
        finally:
            signal.signal(signal.SIGINT, previous)
    try:
        with Client(cluster if cluster is not None else scheduler, timeout="20s") as client:
            by_key = {}
            for run in sweep.runs:
                future = client.submit(
                    execute_run, run, output, key=f"rsstp-{run.name}", pure=False
                )
                by_key[future.key] = (run, future)

            def take(future: Any) -> tuple[Run, dict[str, Any] | None]:
                """The future's run and row (None: killed), its result let go of."""
                run, _ = by_key.pop(future.key)
                row = _result(run, future, KilledWorker)
                future.release()
                return run, row

            suspects: list[Run] = []
            try:
                for future in as_completed([f for _, f in by_key.values()]):
                    run, row = take(future)
                    if row is None:  # it, or a run beside it, killed its workers
                        suspects.append(run)
                        continue
                    rows[run.name] = row
                    if on_row is not None:
                        on_row(row)
                for run in suspects:  # once more, alone: only the culprit dies again
                    future = client.submit(
                        execute_run, run, output, key=f"rsstp-{run.name}-alone", pure=False
                    )
                    by_key[future.key] = (run, future)
                    rows[run.name] = take(future)[1] or failed_row(run, _KILLED)
                    if on_row is not None:
                        on_row(rows[run.name])
            except KeyboardInterrupt:
                client.cancel([f for _, f in by_key.values()])
                return True
    finally:
        if cluster is not None:
            cluster.close()
    return False


def _result(run: Run, future: Any, killed: type[Exception]) -> dict[str, Any] | None:
    """The run's row from its future; None when Dask gave up because its workers died
    (``killed``: distributed's ``KilledWorker``, imported with Dask)."""
    try:
        row: dict[str, Any] = future.result()
    except killed:
        return None
    except Exception as exc:  # the cluster lost it another way
        return failed_row(run, f"the cluster lost the run: {exc}")
    return row


def runs_frame(rows: list[dict[str, Any]]) -> pd.DataFrame:
    """The runs table with its column types fixed (nullable where a failed run has none)."""
    frame = pd.DataFrame(rows, columns=list(ROW_FIELDS))
    types = {
        "seed": "int64",
        "steps": "int64",
        "reused": "bool",
        "seconds": "Float64",
        "seconds_record": "Float64",
        "seconds_audit": "Float64",
        "recorded_steps": "Int64",
        "stopped_at_step": "Int64",
        "model_versions": "Int64",
        "final_states": "Int64",
        "final_transitions": "Int64",
        "final_deterministic": "boolean",
        "minimal_states": "Int64",
        "equivalent": "boolean",
        "learned_at_step": "Int64",
        "contradictory_states": "Int64",
        "contradictions_within_versions": "Int64",
        "blocked": "Int64",
        "no_transition": "Int64",
    }
    for column in ("run", "scenario", "scenario_sha256", "strategy", "params", "status"):
        types[column] = "string"
    types["error"] = "string"
    types["recording"] = "string"
    return frame.astype(types)


def _not_run(run: Run) -> dict[str, Any]:
    row = failed_row(run, "not run: the sweep was interrupted")
    row["status"] = "not run"
    return row


def _write_metadata(fs: Any, root: str, sweep: Sweep) -> None:
    from rsstp_sim.recording.recorder import environment_versions

    base = root.rstrip("/")
    with fs.open(f"{base}/sweep.toml", "w") as out:
        out.write(sweep.source)
    document = {
        "origin": sweep.origin,
        **environment_versions(),
        "runs": [run.name for run in sweep.runs],
    }
    with fs.open(f"{base}/sweep.json", "w") as out:
        json.dump(document, out, indent=1)
