"""Time series and the audit log for the viewer.

Series (``rr.Scalars``, drawn as step functions with a row only where the value changes): the
sensation (0 or 1), the float feedback, the obstacle sensor readings (one entity, a series per
tip and obstacle), the model's size, and the strategy's phase (a series per phase, 1 while the
strategy is in it, 0 otherwise: a timeline of its phase notes).

The log (``rr.TextLog`` at ``log/audit``) holds, at their steps: every contradiction the
consistency audit finds within a model version (the state, its shortest witness, the number of
contradicting pairs, the version): a WARN when the memory proved it while that version was in
force (or at the step that replaced it), else an INFO (an old version, proved wrong after it
was gone); the step from which the model stayed deterministic (or, at the
last step, that it never did), the first step at which it was deterministic and complete,
every split and merge, and the contradictions and notes a strategy recorded as events.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_format.records import ModelRecord
from rsstp_replay.audits.consistency import ConsistencyFindings, StateContradiction
from rsstp_replay.audits.determinism import DeterminismFindings
from rsstp_replay.audits.summary import phase_changes
from rsstp_replay.viewer._chunks import TIMELINE, send_rows
from rsstp_sim.words import counted

__all__ = [
    "DISTANCE",
    "FEEDBACK",
    "LOG",
    "MODEL_STATES",
    "MODEL_TRANSITIONS",
    "PHASE",
    "SENSATION",
    "SERIES_MAX_ROWS",
    "LogLine",
    "audit_lines",
    "log_lines",
    "log_model_size",
    "log_phases",
    "log_series",
]

SENSATION = "plots/agent/sensation"
FEEDBACK = "plots/agent/feedback"
DISTANCE = "plots/distance"
MODEL_STATES = "plots/model/states"
MODEL_TRANSITIONS = "plots/model/transitions"
PHASE = "plots/strategy/phase"
LOG = "log/audit"


def log_series(
    stream: rr.RecordingStream,
    steps: pd.DataFrame,
    *,
    distances: list[tuple[str, str]],
) -> tuple[dict[str, int], list[str]]:
    """Sensation, feedback and the sensor readings (``distances``: the steps table's distance
    columns, each with its series name); returns rows per path, and the paths thinned to
    their extremes.

    A step's value holds until the next step, so every series is drawn as steps
    (``StepAfter``) and has a row only where its value changes (and at the first and last
    step): exact, and small on long runs (a sensation that is false for a million steps is
    two rows). The distances are one entity with a series per tip and obstacle. A series
    that changes more than :data:`SERIES_MAX_ROWS` times in the steps shown (the closeness
    or the distances over a long run, which change with every pose) keeps each curve's
    least and greatest value in each of equal runs of steps (:func:`_extremes`); a shorter
    ``--from``/``--to`` window shows every change.
    """
    times = steps.index.to_numpy(np.int64)
    series: list[tuple[str, list[str], list[str]]] = [
        (SENSATION, ["sensation"], ["sensation"]),
        (FEEDBACK, ["feedback"], ["feedback"]),
    ]
    if distances:
        series.append(
            (DISTANCE, [name for _, name in distances], [column for column, _ in distances])
        )
    logged, thinned = {}, []
    for path, names, columns in series:
        # One series' values at a time (a float64 copy of a column is 8 bytes a step).
        values = steps[columns].to_numpy(np.float64)
        # A boolean drawn zoomed out: min and max per pixel, not their average (0.5 is no
        # sensation the agent ever had).
        aggregation = rr.components.AggregationPolicy.MinMax if path == SENSATION else None
        stream.log(
            path,
            rr.SeriesLines(
                names=names, interpolation_mode="StepAfter", aggregation_policy=aggregation
            ),
            static=True,
        )
        rows = _changes(values)
        if len(rows) > SERIES_MAX_ROWS:
            rows = _extremes(times, values, rows, buckets=SERIES_MAX_ROWS // (2 * len(names)))
            thinned.append(path)
        logged[path] = send_rows(stream, path, times[rows], _scalars(values[rows]))
    return logged, thinned


SERIES_MAX_ROWS = 25_000
"""A series with more changes than this in the steps shown (a closeness or a distance that
changes with every pose of a long run) keeps only its extremes: :func:`_extremes` (100,000
until issue 32: the web viewer's load, as :data:`~rsstp_replay.viewer.OVERVIEW_MAX_STEPS`)."""


def _extremes(
    times: npt.NDArray[np.int64],
    values: npt.NDArray[np.float64],
    rows: npt.NDArray[np.int64],
    *,
    buckets: int,
) -> npt.NDArray[np.int64]:
    """Of the change ``rows``, those holding each column's least and greatest value in each
    of ``buckets`` equal runs of steps, and the first and last row: every extreme of every
    curve is drawn at its step with its value, the values between are the nearest kept
    ones (at most ``2 * buckets * columns + 2`` rows)."""
    bucket = times[rows]  # (in place below: each step-long array is 8 bytes a row)
    span = int(bucket[-1] - bucket[0]) + 1
    width = -(-span // max(buckets, 1))
    bucket -= bucket[0]
    bucket //= width
    starts = np.flatnonzero(np.r_[True, bucket[1:] != bucket[:-1]])
    ends = np.r_[starts[1:], len(rows)] - 1
    kept = [rows[:1], rows[-1:]]
    for k in range(values.shape[1]):  # a column's changes at a time
        order = np.lexsort((values[rows, k], bucket))  # by bucket, then by value
        kept += [rows[order[starts]], rows[order[ends]]]
    return np.unique(np.concatenate(kept))


def _scalars(values: npt.NDArray[np.float64]) -> Callable[[slice], rr.ComponentColumnList]:
    def columns(rows: slice) -> rr.ComponentColumnList:
        return rr.Scalars.columns(scalars=values[rows])

    return columns


def _changes(values: npt.NDArray[np.float64]) -> npt.NDArray[np.int64]:
    """The rows where any column differs from the row before, with the first and last row."""
    if not len(values):
        return np.zeros(0, np.int64)
    differs = np.r_[True, (values[1:] != values[:-1]).any(axis=1)]
    differs[-1] = True
    return np.flatnonzero(differs)


def log_model_size(
    stream: rr.RecordingStream,
    sizes: tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]],
    steps: Sequence[int],
    last_step: int,
) -> dict[str, int]:
    """States and transitions (``sizes``: one per version) of each version at its step, and
    once more at ``last_step`` so the step function reaches the end; returns rows per path."""
    times = [*steps, last_step] if steps[-1] != last_step else list(steps)
    index = rr.TimeColumn(TIMELINE, sequence=np.asarray(times, np.int64))
    n_states, n_transitions = (np.r_[column, column[-1:]][: len(times)] for column in sizes)
    counts = {
        MODEL_STATES: ("states", n_states),
        MODEL_TRANSITIONS: ("transitions", n_transitions),
    }
    for path, (name, values) in counts.items():
        stream.log(path, rr.SeriesLines(names=name, interpolation_mode="StepAfter"), static=True)
        stream.send_columns(
            path,
            indexes=[index],
            columns=rr.Scalars.columns(scalars=np.asarray(values, np.float64)),
        )
    return {path: len(times) for path in counts}


def log_phases(
    stream: rr.RecordingStream, events: pd.DataFrame, first: int, last: int
) -> dict[str, int]:
    """The strategy's phase over steps ``first .. last``, from its phase notes: a series per
    phase, 1 from the step it is entered until the next phase's, else 0 (nothing when the
    strategy recorded no phase); returns rows per path."""
    changes = phase_changes(events)
    if not changes:
        return {}
    names = list(dict.fromkeys(phase for _, phase in changes))
    steps = np.array([step for step, _ in changes], np.int64)
    column = np.array([names.index(phase) for _, phase in changes], np.int64)
    inside = (steps > first) & (steps <= last)
    times: npt.NDArray[np.int64] = np.concatenate([[first], steps[inside], [last]]).astype(np.int64)
    # The phase at each time: the last change at or before it (none before the first).
    at = np.asarray(np.searchsorted(steps, times, side="right"), np.int64) - 1
    values = np.zeros((len(times), len(names)), np.float64)
    known = at >= 0
    values[np.flatnonzero(known), column[at[known]]] = 1.0
    stream.log(PHASE, rr.SeriesLines(names=names, interpolation_mode="StepAfter"), static=True)
    return {PHASE: send_rows(stream, PHASE, times, _scalars(values))}


@dataclass(frozen=True, slots=True)
class LogLine:
    """One line of the audit log."""

    step: int
    level: str
    text: str


def audit_lines(
    versions: Sequence[ModelRecord],
    within: ConsistencyFindings | None,
    determinism: DeterminismFindings | None,
    events: pd.DataFrame,
    *,
    last_step: int,
) -> list[LogLine]:
    """Every line of the audit log over the whole recording, sorted by step (stable):
    ``within`` is the consistency audit within versions
    (:func:`~rsstp_replay.audits.consistency.audit_consistency_by_version`)."""
    lines: list[LogLine] = []
    for record in versions:
        for operation in record.operations:
            if not operation.changed:
                continue
            if operation.kind == "split":
                lines.append(
                    LogLine(
                        record.step,
                        "INFO",
                        f"split: state {operation.args[0]} -> new state {operation.result} "
                        f"(model version {record.version})",
                    )
                )
            elif operation.kind == "merge":
                s, t = operation.args[:2]
                lines.append(
                    LogLine(
                        record.step,
                        "INFO",
                        f"merge: state {t} into state {s} (model version {record.version})",
                    )
                )
    if within is not None:
        replaced = _replaced_at(versions)
        for found in within.contradictions:
            gone = replaced.get(-1 if found.version is None else found.version)
            if gone is None or found.first_step <= gone:
                lines.append(LogLine(found.first_step, "WARN", _contradiction(found)))
            else:
                lines.append(
                    LogLine(
                        found.first_step,
                        "INFO",
                        f"{_contradiction(found)} (an old version: replaced at step {gone})",
                    )
                )
    if determinism is not None:
        lines += _determinism_lines(determinism, last_step=last_step)
    for step, kind, text in zip(
        events["step"].tolist(),
        events["kind"].astype(str).tolist(),
        events["text"].tolist(),
        strict=True,
    ):
        if kind == "contradiction":
            lines.append(LogLine(int(step), "WARN", f"recorded contradiction: {text}"))
        elif kind == "note":
            lines.append(LogLine(int(step), "DEBUG", f"strategy note: {text}"))
    lines.sort(key=lambda line: line.step)
    return lines


def _replaced_at(versions: Sequence[ModelRecord]) -> dict[int, int]:
    """The step at which each version (by number) but the last was replaced."""
    return {
        record.version: following.step
        for record, following in zip(versions[:-1], versions[1:], strict=True)
    }


def _contradiction(found: StateContradiction) -> str:
    witness = found.witness
    return (
        f"contradiction: state {found.state}: after steps {witness.i} and {witness.j} (both in "
        f"state {found.state}) the actions {list(witness.actions)} give different sensations "
        f"at steps {witness.i + witness.k} and {witness.j + witness.k}; "
        f"{counted(found.pairs, 'contradicting pair')}"
        + ("" if found.version is None else f"; model version {found.version}")
    )


def _determinism_lines(found: DeterminismFindings, *, last_step: int) -> list[LogLine]:
    lines = []
    since = found.deterministic_from
    if since is None:
        final = found.final
        lines.append(
            LogLine(
                last_step,
                "WARN",
                f"the final model (version {final.version}) is nondeterministic: "
                f"{len(final.nondeterministic)} (state, action) pairs with several successors",
            )
        )
    else:
        version = next(v for v in found.versions if v.step == since)
        lines.append(
            LogLine(
                since,
                "INFO",
                f"deterministic: the model is deterministic from here to the end (version "
                f"{version.version}, {version.states} states, {version.transitions} transitions)",
            )
        )
    complete = found.first_complete_step
    if complete is not None:
        lines.append(
            LogLine(
                complete,
                "INFO",
                "complete: the model is deterministic and complete (one successor for every "
                "state and action) for the first time",
            )
        )
    return lines


def log_lines(stream: rr.RecordingStream, lines: Sequence[LogLine]) -> int:
    """The audit log lines at their steps; returns the rows logged."""
    if not lines:
        return 0
    stream.send_columns(
        LOG,
        indexes=[rr.TimeColumn(TIMELINE, sequence=[line.step for line in lines])],
        columns=rr.TextLog.columns(
            text=[line.text for line in lines], level=[line.level for line in lines]
        ),
    )
    return len(lines)
