"""Streaming a recording to Rerun: the world, the learned model, time series and audit findings.

>>> with open_recording("run.mcap") as recording:  # doctest: +SKIP
...     result = view(recording, save=Path("run.rrd"), spawn=False, serve_web=False,
...                   start=None, end=None)
...     render_graph(recording, 500, Path("model.svg"))

Everything is on one sequence timeline, ``step`` (step 0 is the reset), and is logged column
by column (``rr.send_columns``: one call per entity and 1,024 steps), so a 100,000-step
recording streams in about a second. ``docs/viewer.md`` lists every entity path, what it
shows and how; :data:`ENTITY_PATHS` is that list for code.

This is the one lenient part of the project (as Rerun's own ``error_utils``): what cannot be
shown (an audit that fails on the data, a viewer that cannot be spawned) is reported as a
:class:`ViewerWarning` and the rest is still shown. Bad arguments (a step outside the
recording, an output in a missing folder) still raise.
"""

from __future__ import annotations

import bisect
import os
import tempfile
import time
import uuid
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np
import numpy.typing as npt
import pandas as pd
import rerun as rr

from rsstp_format.records import ModelRecord
from rsstp_replay.audits.class_roles import model_state_roles
from rsstp_replay.audits.consistency import ConsistencyFindings, audit_consistency_by_version
from rsstp_replay.audits.determinism import DeterminismFindings, audit_determinism
from rsstp_replay.audits.truth import step_true_classes
from rsstp_replay.errors import ReplayError, StepOutOfRange, ViewerWarning
from rsstp_replay.reader import body_reader, version_heads, version_sizes
from rsstp_replay.viewer import _large as large_part
from rsstp_replay.viewer import _map as map_part
from rsstp_replay.viewer import _model as model_part
from rsstp_replay.viewer import _plots as plots_part
from rsstp_replay.viewer import _world as world_part
from rsstp_replay.viewer._blueprint import default_blueprint, view_frame
from rsstp_replay.viewer._chunks import TIMELINE
from rsstp_replay.viewer._layout import graph_positions
from rsstp_replay.viewer._serve import (
    DEFAULT_BIND,
    CtrlC,
    WebServer,
    check_port,
    ctrl_c_remembered,
    has_display,
    rerun_command,
)
from rsstp_replay.viewer._world import body_view
from rsstp_sim import graph
from rsstp_sim.errors import OutputError, RsstpError
from rsstp_sim.files import side_file, write_whole
from rsstp_sim.memory import Memory
from rsstp_sim.scenario import AnyScenario
from rsstp_sim.transition_system import TransitionSystem
from rsstp_sim.truth import GroundTruth
from rsstp_sim.truth.cache import load_truth
from rsstp_sim.words import counted

__all__ = [
    "APPLICATION_ID",
    "ENTITY_PATHS",
    "OVERVIEW_MAX_STEPS",
    "TIMELINE",
    "LogSummary",
    "ViewResult",
    "ViewSource",
    "ViewerWarning",
    "check_port",
    "ctrl_c_remembered",
    "default_blueprint",
    "graph_positions",
    "has_display",
    "log_recording",
    "render_graph",
    "rerun_command",
    "view",
]

APPLICATION_ID = "rsstp"
SPAWN_PORT = 9876
"""The port of a spawned native viewer (Rerun's default)."""
TRUTH_MAX_POSES = 500_000
"""The viewer colours states by the truth audit only for worlds of at most this many poses
(the truth of 322,000 poses takes about 3 s)."""
SERVE_PORT = 9877
"""The default gRPC port of ``serve_web``'s server (the data; the web page is on 9090)."""
WEB_PORT = 9090
"""The default port of the web viewer's page."""

ENTITY_PATHS: tuple[str, ...] = (
    world_part.WORLD,
    world_part.OBSTACLES,
    world_part.FEEDBACK_POINTS,
    world_part.BLOCKED,
    *(path for name in world_part.BODY_VIEWS for path in world_part.body_view(name).paths),
    model_part.STATES + "/{id}",
    model_part.CURRENT,
    model_part.LEGEND,
    large_part.STATE_BLOCKS + "/{block}",
    large_part.NEAR,
    map_part.MAP,
    map_part.CELLS + "/{block}",
    map_part.NO_POSE,
    map_part.POSE,
    map_part.MAP_LEGEND,
    plots_part.SENSATION,
    plots_part.FEEDBACK,
    plots_part.DISTANCE,
    plots_part.MODEL_STATES,
    plots_part.MODEL_TRANSITIONS,
    plots_part.LOG,
)
"""Every entity path the viewer writes (``{id}``: a state id; ``{block}``: a block of a
large model's states, or of the map's cells)."""


class ViewSource(Protocol):
    """What the viewer reads of a recording (:class:`rsstp_replay.reader.recording.Recording`)."""

    @property
    def path(self) -> Path: ...

    @property
    def scenario(self) -> AnyScenario: ...

    @property
    def n_steps(self) -> int: ...

    def steps(self) -> pd.DataFrame: ...

    def model_versions(self) -> Sequence[ModelRecord]: ...

    def events(self) -> pd.DataFrame: ...

    def model_at(self, step: int) -> TransitionSystem: ...


@dataclass(frozen=True, slots=True)
class LogSummary:
    """What :func:`log_recording` wrote: steps ``first_step .. last_step``, the rows of every
    time-indexed entity path, and where the time went (seconds): reading the recording,
    auditing it and laying out the graph, building and sending the Rerun columns."""

    first_step: int
    last_step: int
    rows: dict[str, int]
    model_versions: int
    log_lines: int
    thinned: tuple[str, ...]
    """The series paths that kept only their extremes (more changes than
    :data:`~rsstp_replay.viewer._plots.SERIES_MAX_ROWS` in the steps shown)."""
    every: int
    """The arm, its blocked marker and the current state are shown every ``every``-th step
    (1: every step; more over :data:`OVERVIEW_MAX_STEPS` steps shown)."""
    seconds_read: float
    seconds_prepare: float
    seconds_rerun: float


@dataclass(slots=True)
class ViewResult:
    """The outcome of :func:`view`. ``seconds_rerun`` includes flushing the sinks (writing
    the ``.rrd``). With ``web_url`` set, a web server serves the view until :meth:`close`
    (or the end of :meth:`serve_forever`)."""

    summary: LogSummary
    saved: Path | None
    spawned: bool
    web_url: str | None
    seconds_rerun: float
    _server: WebServer | None = field(default=None, repr=False)
    _folder: tempfile.TemporaryDirectory[str] | None = field(default=None, repr=False)

    def to_text(self) -> str:
        """For the command line: one line, and one more for an overview and for thinned
        series."""
        s = self.summary
        where = [f"saved {self.saved}"] if self.saved is not None else []
        if self.spawned:
            where.append("sent to a native viewer")
        if self.web_url is not None:
            where.append(f"serving the web viewer at {self.web_url}")
        lines = [
            f"steps {s.first_step:,}..{s.last_step:,}: "
            f"{counted(len(s.rows), 'entity', 'entities')}, "
            f"{counted(s.model_versions, 'model version')}, "
            f"{counted(s.log_lines, 'log line')}; read {s.seconds_read:.2f} s, audits and "
            f"placing {s.seconds_prepare:.2f} s, Rerun {self.seconds_rerun:.2f} s"
            + ("; " + ", ".join(where) if where else "")
        ]
        if s.every > 1:
            lines.append(_overview_text(s.every))
        if s.thinned:
            lines.append(
                f"thinned to each curve's extremes (over {plots_part.SERIES_MAX_ROWS:,} "
                f"changes): {', '.join(s.thinned)}; --from/--to on a shorter window shows "
                "every change"
            )
        return "\n".join(lines)

    def serve_forever(self, stop: CtrlC | None = None) -> None:
        """Keep serving the web viewer until Ctrl-C (or until ``stop`` is pressed), then stop."""
        try:
            if self._server is not None:
                self._server.wait(stop)
        finally:
            self.close()

    def close(self) -> None:
        """Stop serving (if serving) and remove the file served when it was a temporary one."""
        if self._server is not None:
            self._server.close()
            self._server = None
        if self._folder is not None:
            self._folder.cleanup()
            self._folder = None


def view(
    recording: ViewSource,
    *,
    save: Path | None,
    spawn: bool,
    serve_web: bool,
    start: int | None,
    end: int | None,
    bind: str = DEFAULT_BIND,
    web_port: int = WEB_PORT,
    grpc_port: int = SERVE_PORT,
) -> ViewResult:
    """Stream steps ``start .. end`` (inclusive; default: all) of ``recording`` to Rerun.

    ``save``: write an ``.rrd`` file (the default blueprint inside); ``spawn``: send to a native
    viewer, started if none listens on port 9876; ``serve_web``: serve the web viewer on
    ``bind`` (127.0.0.1 by default), the page on ``web_port``, the data on ``grpc_port``, from
    the ``.rrd`` (``save``, or a temporary file) by the ``rerun`` program (``web_url``; keep
    the process alive with :meth:`ViewResult.serve_forever`). With none of them a native
    viewer is spawned. Raises :class:`~rsstp_replay.errors.StepOutOfRange` for a bad range and
    :class:`~rsstp_replay.errors.ReplayError` for an unwritable ``save`` or a port in use.
    """
    first, last = _step_range(recording, start, end)
    if save is not None:
        save = Path(save)
        if not save.parent.is_dir():
            raise ReplayError(f"cannot write {save}: the folder {save.parent} does not exist")
    if save is None and not spawn and not serve_web:
        spawn = True
    folder = None
    if serve_web:
        check_port(bind, web_port, option="--web-port")
        check_port(bind, grpc_port, option="--grpc-port")
        if save is None:
            folder = tempfile.TemporaryDirectory(prefix="rsstp-view-")
    target = save if folder is None else Path(folder.name) / "view.rrd"
    # The .rrd is written to a side file and renamed onto ``target`` only when whole: a full
    # disk or a file-size limit never leaves a truncated file under the name, nor destroys
    # the file that was there. Without a viewer to feed, Rerun encodes into memory and the
    # bytes are written here (:func:`rsstp_sim.files.write_whole`): Rerun's file-writer thread
    # can hang its flush for good once a write of its fails, and no write of ours can.
    writing = None if target is None else side_file(target)
    loaded = _load(recording)
    stream = rr.RecordingStream(APPLICATION_ID, recording_id=uuid.uuid4())
    blueprint = default_blueprint(
        recording.scenario, first=first, last=last, with_map=loaded.map_changes is not None
    )
    spawned = False
    in_memory: rr.BinaryStream | None = None
    if target is not None and not spawn:
        in_memory = rr.binary_stream(recording=stream)
        # Active as well as default: the web viewer ignores a default blueprint of a file it
        # serves and lays the views out itself.
        stream.send_blueprint(blueprint, make_active=True, make_default=True)
    else:
        sinks: list[rr.FileSink | rr.GrpcSink] = []
        if writing is not None:
            sinks.append(rr.FileSink(writing))
        try:
            stream.spawn(port=SPAWN_PORT, connect=False)
        except Exception as exc:  # the lenient adapter: no viewer, still save or serve
            warnings.warn(ViewerWarning(f"could not spawn a Rerun viewer: {exc}"), stacklevel=2)
        else:
            sinks.append(rr.GrpcSink(f"rerun+http://127.0.0.1:{SPAWN_PORT}/proxy"))
            spawned = True
        stream.set_sinks(*sinks, default_blueprint=blueprint)
    summary = _log(recording, loaded, stream, first, last)
    del loaded  # the tables, before Rerun hands over the encoded file
    began = time.perf_counter()
    if in_memory is not None:
        assert target is not None
        data = in_memory.read(flush=True)
        stream.disconnect()
        try:
            write_whole(target, data or b"")
        except OutputError:
            if folder is not None:
                folder.cleanup()
            raise
    else:
        try:
            stream.flush()
        except RuntimeError as exc:
            if writing is not None and not spawned:  # only the file sink can have failed
                stream.disconnect()
                writing.unlink(missing_ok=True)
                if folder is not None:
                    folder.cleanup()
                raise ReplayError(f"{target}: cannot write the .rrd: {exc}") from None
            # A spawned viewer that never listened (the file, if any, is checked below).
            warnings.warn(
                ViewerWarning(f"the Rerun viewer could not be reached: {exc}"), stacklevel=2
            )
            spawned = False
        stream.disconnect()  # finishes the file (its footer) and the connection
        if writing is not None and target is not None:
            _finish_rrd(writing, target, folder)
    seconds = summary.seconds_rerun + time.perf_counter() - began
    server = None
    if serve_web:
        assert target is not None
        try:
            server = WebServer(target, bind=bind, web_port=web_port, grpc_port=grpc_port)
        except BaseException:  # Ctrl-C as well: the temporary file goes with the server
            if folder is not None:
                folder.cleanup()
            raise
    return ViewResult(
        summary=summary,
        saved=save,
        spawned=spawned,
        web_url=None if server is None else server.url,
        seconds_rerun=seconds,
        _server=server,
        _folder=folder,
    )


def _finish_rrd(
    writing: Path, target: Path, folder: tempfile.TemporaryDirectory[str] | None
) -> None:
    """Rename the finished side file onto ``target``, once Rerun's file writer has closed it
    whole (its end-of-stream footer written); else remove it and say why."""
    try:
        whole = writing.stat().st_size > 0 and _has_rrd_end(writing)
    except OSError:
        whole = False
    if not whole:
        writing.unlink(missing_ok=True)
        if folder is not None:
            folder.cleanup()
        raise ReplayError(
            f"{target}: cannot write the .rrd: Rerun's file writer did not finish it "
            "(a full disk or a file-size limit?)"
        )
    os.replace(writing, target)


_RRD_FOOTER = b"RRF2FOOT"
"""How a whole .rrd of rerun-sdk 0.41 ends: its stream footer's magic, then 4 bytes."""


def _has_rrd_end(path: Path) -> bool:
    with path.open("rb") as file:
        file.seek(max(0, path.stat().st_size - 64))
        return _RRD_FOOTER in file.read()


def log_recording(
    recording: ViewSource,
    stream: rr.RecordingStream,
    *,
    start: int | None = None,
    end: int | None = None,
) -> LogSummary:
    """Log steps ``start .. end`` (inclusive; default: all) of ``recording`` to ``stream``
    (the caller sets its sinks, and the blueprint if it wants one, and flushes it). The audits
    run over the whole recording; the model version in force at ``start`` is shown from
    ``start`` on."""
    first, last = _step_range(recording, start, end)
    return _log(recording, _load(recording), stream, first, last)


@dataclass(frozen=True, slots=True)
class _Loaded:
    """A recording read once, audited, its states placed on the world."""

    steps: pd.DataFrame
    versions: Sequence[ModelRecord]
    events: pd.DataFrame
    within: ConsistencyFindings | None
    determinism: DeterminismFindings | None
    roles: model_part.Roles | None
    truth: GroundTruth | None
    map_changes: map_part.RoleChanges | None
    places: model_part.StatePlaces
    labelled: set[int]
    seconds_read: float
    seconds_prepare: float


def _load(recording: ViewSource) -> _Loaded:
    began = time.perf_counter()
    steps = _narrowed(recording.steps())
    versions = recording.model_versions()  # (rebuilt whole only where indexed)
    events = recording.events()
    read = time.perf_counter()
    within, determinism = _audits(steps, versions)
    scenario = recording.scenario
    scale = view_frame(scenario).scale
    places = model_part.state_places(
        steps,
        versions,
        columns=_place_columns(scenario),
        pose_columns=_pose_columns(scenario),
        reach=scale,
    )
    labelled = model_part.labelled_states(places.places, room=model_part.LABEL_ROOM * scale)
    truth, roles, map_changes = _roles(scenario, steps, recording)
    return _Loaded(
        steps,
        versions,
        events,
        within,
        determinism,
        roles,
        truth,
        map_changes,
        places,
        labelled,
        seconds_read=read - began,
        seconds_prepare=time.perf_counter() - read,
    )


def _log(
    recording: ViewSource, loaded: _Loaded, stream: rr.RecordingStream, first: int, last: int
) -> LogSummary:
    began = time.perf_counter()
    window = loaded.steps.iloc[first : last + 1]
    scenario = recording.scenario
    stream.send_recording_name(f"{scenario.name} ({getattr(recording, 'path', 'recording')})")
    # The small entities first: a viewer reads the file in order, so the model, its size and
    # the audit log show while the per-step series still load.
    body = body_view(scenario.body)
    body.log_static(stream, scenario)
    if loaded.roles is not None:
        frame = view_frame(scenario)
        model_part.log_legend(stream, reach=frame.half, center=frame.center)
    shown, times, sizes = _versions_in(loaded.versions, first, last)
    large = int(sizes[0].max()) > large_part.ALL_ARROWS_MAX_STATES
    log_model = large_part.log_large_model if large else model_part.log_model
    rows = log_model(
        stream, shown, times, loaded.places, roles=loaded.roles, labelled=loaded.labelled
    )
    grid = map_part.joint_grid(scenario)
    if grid is not None and loaded.truth is not None and loaded.map_changes is not None:
        rows |= map_part.log_map(
            stream,
            grid,
            loaded.truth,
            loaded.map_changes,
            version_steps={
                r.version: r.step for r in version_heads(loaded.versions) if r.step <= last
            },
            first=first,
        )
    rows |= plots_part.log_model_size(stream, sizes, times, last)
    rows |= plots_part.log_phases(stream, loaded.events, first, last)
    every_line = plots_part.audit_lines(
        version_heads(loaded.versions),
        loaded.within,
        loaded.determinism,
        loaded.events,
        last_step=recording.n_steps,
    )
    lines = [line for line in every_line if first <= line.step <= last]
    every = -(-len(window) // OVERVIEW_MAX_STEPS)
    if every > 1:
        lines.insert(0, plots_part.LogLine(first, "INFO", _overview_text(every)))
    if lines:
        rows[plots_part.LOG] = plots_part.log_lines(stream, lines)
    sampled = window.iloc[np.unique(np.r_[0 : len(window) : every, len(window) - 1])]
    sampled_steps = sampled.index.to_numpy(np.int64)
    sampled_states = sampled["internal_state"].to_numpy(np.int64)
    rows[model_part.CURRENT] = model_part.log_current_state(
        stream, sampled_steps, sampled_states, loaded.places
    )
    if large:
        rows[large_part.NEAR] = large_part.log_near(
            stream, shown, times, sampled_steps, sampled_states, loaded.places
        )
    if grid is not None and loaded.truth is not None:
        angles = sampled[list(loaded.truth.value_names)].to_numpy(np.int64)
        rows[map_part.POSE] = map_part.log_map_pose(stream, grid, sampled_steps, angles)
    rows |= body.log_steps(stream, sampled, scenario, sensor=every == 1)
    series, thinned = plots_part.log_series(
        stream, window, distances=body.distance_series(scenario)
    )
    rows |= series
    return LogSummary(
        first_step=first,
        last_step=last,
        rows=rows,
        model_versions=len(shown),
        log_lines=len(lines),
        thinned=tuple(thinned),
        every=every,
        seconds_read=loaded.seconds_read,
        seconds_prepare=loaded.seconds_prepare,
        seconds_rerun=time.perf_counter() - began,
    )


OVERVIEW_MAX_STEPS = 25_000
"""Over this many steps shown, the arm, its blocked marker and the current state are an
overview: shown every k-th step (and at the last), k the least that keeps them within this
many rows, and the obstacle sensor is left out (the distances stay as plots); a
``--from``/``--to`` window of at most this many steps shows every step. (A
million-step run has a row per step in each; the web viewer needs minutes to take them in.
100,000 until issue 32: the web viewer took 240 s to settle on a 643,244-step learner run's
overview on the 2-core development machine, 87 s at 25,000.)"""


def _overview_text(every: int) -> str:
    return (
        f"overview: the arm, its blocked marker and the current state at one step in {every:,} "
        f"(over {OVERVIEW_MAX_STEPS:,} steps shown); a --from/--to window of at most "
        f"{OVERVIEW_MAX_STEPS:,} steps shows every step"
    )


def render_graph(recording: ViewSource, step: int, path: Path, *, on_world: bool = False) -> Path:
    """Draw the model at the end of step ``step`` with Graphviz (the format from the suffix:
    ``.svg``, ``.png``, ``.pdf``, ``.dot``, ``.gv``), the current state filled. Every state is
    where the same layout of all versions puts it (the thesis-style picture), or, with
    ``on_world``, where the viewer draws it on the world (the mean tip position while it was
    current; 200 points to a length unit). Returns ``path``.

    Raises :class:`~rsstp_replay.errors.StepOutOfRange` for a bad step and
    :class:`~rsstp_sim.errors.GraphvizFailed` when Graphviz fails.
    """
    model = recording.model_at(step)
    versions = recording.model_versions()
    if on_world:
        scenario = recording.scenario
        places = model_part.state_places(
            recording.steps(),
            versions,
            columns=_place_columns(scenario),
            pose_columns=_pose_columns(scenario),
            reach=view_frame(scenario).scale,
        ).places
        positions = {s: (200.0 * places[s][0], 200.0 * places[s][1]) for s in model.states}
    else:
        layout = graph_positions(versions)
        positions = {s: layout[s] for s in model.states}
    return graph.render(model, path, positions=positions)


# ------------------------------------------------------------------------------ helpers

_UNREAD_COLUMNS = ("state_before", "no_transition")
"""The steps table's columns the viewer does not read."""


def _narrowed(steps: pd.DataFrame) -> pd.DataFrame:
    """``steps`` as the viewer keeps it while it audits and logs: without
    :data:`_UNREAD_COLUMNS`, each integer column (nullable ones too) in the narrowest dtype
    that holds its values. The columns hold the same values; every reader converts to the
    dtype it computes in. (A long run's table is most of the viewer's memory: 374 MiB for
    2,296,166 steps of a two-link arm, 212 MiB so.)"""
    columns = {
        name: pd.to_numeric(column, downcast="integer")
        if pd.api.types.is_integer_dtype(column.dtype)
        else column
        for name, column in steps.items()
        if name not in _UNREAD_COLUMNS
    }
    return pd.DataFrame(columns, index=steps.index, copy=False)


def _pose_columns(scenario: AnyScenario) -> tuple[str, ...]:
    """The steps table's integer columns that say a pose (an arm's angles, a rover's cell and
    heading)."""
    return body_reader(scenario.body).pose_columns(scenario)


def _place_columns(scenario: AnyScenario) -> tuple[str, str]:
    """The steps table's columns a state is placed by on the world (an arm's last tip, a
    rover's position)."""
    return body_reader(scenario.body).place_columns(scenario)


def _step_range(recording: ViewSource, start: int | None, end: int | None) -> tuple[int, int]:
    n = recording.n_steps
    where = getattr(recording, "path", "the recording")
    bounds = (0 if start is None else start, n if end is None else end)
    for name, value in zip(("start", "end"), bounds, strict=True):
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise StepOutOfRange(f"{where}: the {name} step must be an integer, got {value!r}")
        if not 0 <= value <= n:
            raise StepOutOfRange(
                f"{where}: the {name} step {value} is out of range: the recording has steps 0 "
                f"to {n}"
            )
    first, last = int(bounds[0]), int(bounds[1])
    if first > last:
        raise StepOutOfRange(f"{where}: no step from {first} to {last}: the start is after the end")
    return first, last


def _versions_in(
    versions: Sequence[ModelRecord], first: int, last: int
) -> tuple[list[ModelRecord], list[int], tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]]:
    """The versions to show for steps ``first .. last``, the step of each and their sizes
    (states, transitions): the version in force at ``first`` (at ``first``, whole), then
    every later one up to ``last`` (its message: the operations that made it)."""
    heads = version_heads(versions)
    steps = [record.step for record in heads]
    begin = max(0, bisect.bisect_right(steps, first) - 1)
    stop = bisect.bisect_right(steps, last)
    shown = [versions[begin], *heads[begin + 1 : stop]]
    n_states, n_transitions = version_sizes(versions)
    sizes = (n_states[begin:stop], n_transitions[begin:stop])
    return shown, [max(record.step, first) for record in shown], sizes


def _audits(
    steps: pd.DataFrame, versions: Sequence[ModelRecord]
) -> tuple[ConsistencyFindings | None, DeterminismFindings | None]:
    """The consistency audit within versions and the determinism audit; None (with a
    warning) for an audit that fails. (The same consistency audit over the whole history,
    state ids across versions, is ``rsstp-replay audit``'s: a learner's early versions reused
    ids that meant something else then, and a million steps audit in seconds.)"""
    within: ConsistencyFindings | None = None
    determinism: DeterminismFindings | None = None
    try:
        memory = Memory.from_arrays(
            steps["action"].fillna(-1).to_numpy(np.int64),
            steps["internal_state"].to_numpy(np.int64),
            steps["sensation"].to_numpy(np.bool_),
            steps["feedback"].to_numpy(np.float64),
        )
        within = audit_consistency_by_version(memory, steps["model_version"].to_numpy(np.int64))
    except RsstpError as exc:
        warnings.warn(ViewerWarning(f"consistency audit not shown: {exc}"), stacklevel=3)
    try:
        determinism = audit_determinism(versions)
    except RsstpError as exc:
        warnings.warn(ViewerWarning(f"determinism audit not shown: {exc}"), stacklevel=3)
    return within, determinism


def _roles(
    scenario: AnyScenario, steps: pd.DataFrame, recording: ViewSource
) -> tuple[GroundTruth | None, model_part.Roles | None, map_part.RoleChanges | None]:
    """The truth, every visited state's role per version by the truth audit and (for an arm
    the map draws) where each true class's role changes; in the final version, the states and
    classes as its model has them (visited or not). Nones (with a warning) when the truth
    cannot be computed (a world of more than :data:`TRUTH_MAX_POSES` poses)."""
    try:
        truth = load_truth(scenario, max_poses=TRUTH_MAX_POSES)
        classes = step_true_classes(steps, truth)
    except RsstpError as exc:
        warnings.warn(ViewerWarning(f"states not coloured by the truth audit: {exc}"), stacklevel=3)
        return None, None, None
    step_versions = steps["model_version"].to_numpy(np.int64)
    step_states = steps["internal_state"].to_numpy(np.int64)
    roles = model_part.roles_by_version(step_versions, step_states, classes)
    final = int(step_versions[-1])
    model = recording.model_at(recording.n_steps)
    walked = model_state_roles(model, truth, int(step_states[-1]), int(classes[-1]))
    roles[final] = {**roles.get(final, {}), **walked}
    changes = None
    if map_part.joint_grid(scenario) is not None:
        reached, given = map_part.model_class_roles(
            model, truth, int(step_states[-1]), int(classes[-1])
        )
        changes = map_part.class_role_changes(
            step_versions,
            step_states,
            classes,
            state_roles=roles,
            final=(final, reached, given),
        )
    return truth, roles, changes
