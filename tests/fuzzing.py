"""Fuzzing: hypothesis strategies for scenario files and recording bytes, and what every case
must keep to.

- :func:`scenario_texts`: a valid scenario with one to four keys set to anything TOML can
  hold (or to plausible values, so that many cases get past validation and run), keys
  deleted, unknown keys added, and now and then a character of the text changed.
- :func:`recording_mutations`: edits of a real recording's bytes: bit flips, truncation,
  ranges overwritten, deleted, duplicated or inserted.
- :func:`deep_texts`: TOML and JSON texts nested up to thousands deep, for every command line
  input that is parsed (a scenario file, a sweep file, ``--matrix``, ``--param``).
- :func:`semantic_rewrites`: a real recording re-encoded with a ground-truth value of a step
  changed (integer extremes among the values): still well-formed, it must be refused, or
  caught by ``check --physics`` (the re-simulation).
- :func:`output_faults`: every command that writes, with its output in a read-only folder or
  past a file-size limit.

:func:`check_scenario` and :func:`check_recording` return what went wrong with one case
(``None`` when nothing did): an exception that is not the package's documented error, a
command line that ends in anything but its exit code and one line, a case over its time
bound (in the suite a hang guard, :data:`waiting.HANG_S`, where a case takes some 0.03 s: a
test never depends on how fast the machine is; ``bench/fuzz.py`` gives
:data:`STALL_SECONDS`, a stall on the machine it measures), or (for recordings) a message
returned that was never written. The default test run
(``tests/test_fuzz.py``) runs a short budget; ``bench/fuzz.py`` runs a long one and counts.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
import resource
import signal
import sys
import time
import warnings
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parent / "replay"))  # test_corrupt's rewrite

from conftest import VALID_SCENARIO
from rsstp_cli import replay as replay_cli
from rsstp_cli import sim as sim_cli
from rsstp_replay import ReplayError, UnfinishedRecordingWarning, open_recording
from rsstp_sim import RsstpError, load_scenario, make_strategy, parse_scenario
from rsstp_sim.recording import record
from scenarios import toml_text
from waiting import HANG_S

STALL_SECONDS = 10.0
"""``bench/fuzz.py``'s time bound of one case: over it, a stall (a finding) on the machine the
bench runs on, measured there; not a property of the code that any machine could check."""

# ------------------------------------------------------------------------ scenario files

_KEYS = [
    "name",
    "description",
    "arm",
    "arm.lengths",
    "arm.initial_deg",
    "arm.step_deg",
    "arm.actions",
    "obstacles",
    "obstacles.0",
    "obstacles.0.center",
    "obstacles.0.radius",
    "feedback",
    "feedback.target_deg",
    "feedback.points",
    "feedback.mode",
    "feedback.tolerance",
    "motion",
    "motion.collision",
    "unknown",
    "arm.unknown",
    "obstacles.0.unknown",
]
"""Every key of a scenario file (``obstacles.0`` is the first obstacle's table), and a few
unknown ones."""

_BARE_KEY = st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=8)
_SCALARS = st.one_of(
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 359, 360, 361, 1e308, -1e308, 5e-324, 1e-6, 3e307, 1e12, 1e13]),
    st.sampled_from([2**63 - 1, 2**63, -(2**63) - 1, 2**64, 10**30, -(10**30)]),
    st.text(max_size=12),
)
_TOML = st.recursive(
    _SCALARS,
    lambda inner: st.lists(inner, max_size=8) | st.dictionaries(_BARE_KEY, inner, max_size=3),
    max_leaves=24,
)
"""Any value a TOML file can hold (datetimes aside)."""

_LENGTH = st.floats(min_value=0.01, max_value=10.0)
_ANGLE = st.integers(-720, 720)
_PLAUSIBLE: dict[str, st.SearchStrategy[Any]] = {
    "arm.lengths": st.lists(_LENGTH, min_size=1, max_size=4),
    "arm.initial_deg": st.lists(_ANGLE, min_size=1, max_size=4),
    "arm.step_deg": st.integers(1, 359),
    "arm.actions": st.lists(st.integers(0, 3), min_size=1, max_size=4, unique=True),
    "obstacles": st.lists(
        st.fixed_dictionaries(
            {
                "center": st.tuples(st.floats(-5, 5), st.floats(-5, 5)).map(list),
                "radius": st.floats(0.01, 3.0),
            }
        ),
        max_size=6,
    ),
    "obstacles.0.center": st.tuples(st.floats(-5, 5), st.floats(-5, 5)).map(list),
    "obstacles.0.radius": st.floats(0.0, 5.0),
    "feedback.target_deg": st.lists(_ANGLE, min_size=1, max_size=4),
    "feedback.points": st.lists(
        st.tuples(st.floats(-5, 5), st.floats(-5, 5)).map(list), min_size=1, max_size=3
    ),
    "feedback.mode": st.sampled_from(["bool", "float"]),
    "feedback.tolerance": st.floats(0.0, 1.0),
    "motion.collision": st.sampled_from(["swept", "endpoint"]),
}
"""Values of the right shape, so that many cases pass validation and run."""
_SHAPE_KEEPING = [
    key for key in sorted(_PLAUSIBLE) if not key.endswith(("_deg", "lengths", "points"))
]
"""The plausible keys that keep the joint count (``arm.actions`` aside) and the kind of
feedback."""


@st.composite
def _arms(draw: st.DrawFn) -> tuple[dict[str, Any], dict[str, Any]]:
    """An ``[arm]`` of one to four joints and a ``[feedback]`` that agree on the count."""
    n = draw(st.integers(1, 4))
    joints = st.lists(_ANGLE, min_size=n, max_size=n)
    arm = {
        "lengths": draw(st.lists(_LENGTH, min_size=n, max_size=n)),
        "initial_deg": draw(joints),
        "step_deg": draw(st.integers(1, 180)),
    }
    if draw(st.booleans()):
        arm["actions"] = draw(st.lists(st.integers(0, 2 * n - 1), min_size=1, unique=True))
    return arm, {"target_deg": draw(joints), "mode": draw(st.sampled_from(["bool", "float"]))}


def _put(data: dict[str, Any], path: str, value: Any, *, delete: bool) -> None:
    """Set (or delete) ``path`` in ``data``, making the tables on the way when needed."""
    *parents, last = path.split(".")
    here: Any = data
    for part in parents:
        if part == "0":
            if not isinstance(here, list) or not here or not isinstance(here[0], dict):
                return
            here = here[0]
        else:
            if not isinstance(here.get(part), dict | list):
                if delete:
                    return
                here[part] = {}
            here = here[part]
    if last == "0":
        if isinstance(here, list) and here:
            if delete:
                here.pop(0)
            else:
                here[0] = value
        return
    if not isinstance(here, dict):
        return
    if delete:
        here.pop(last, None)
    else:
        here[last] = value


@st.composite
def scenario_texts(draw: st.DrawFn) -> str:
    """A scenario file's text: the valid one with a few keys changed (see the module)."""
    data = copy.deepcopy(VALID_SCENARIO)
    plausible_only = draw(st.booleans())  # half the cases: values of the right shape only
    if plausible_only and draw(st.booleans()):
        data["arm"], data["feedback"] = draw(_arms())
    for _ in range(draw(st.integers(1, 4))):
        if plausible_only:
            path = draw(st.sampled_from(_SHAPE_KEEPING))
            _put(data, path, draw(_PLAUSIBLE[path]), delete=False)
            continue
        path = draw(st.sampled_from(_KEYS))
        if draw(st.integers(0, 5)) == 0:
            _put(data, path, None, delete=True)
            continue
        plausible = _PLAUSIBLE.get(path)
        value = draw(plausible if plausible is not None and draw(st.booleans()) else _TOML)
        _put(data, path, value, delete=False)
    text = toml_text(data)
    if draw(st.integers(0, 7)) == 0 and text:  # a character changed, dropped or added
        at = draw(st.integers(0, len(text) - 1))
        text = text[:at] + draw(st.text(max_size=2)) + text[at + draw(st.integers(0, 1)) :]
    return text


# ------------------------------------------------------------------------- recording bytes


@dataclass(frozen=True, slots=True)
class Mutation:
    """One edit of a file's bytes, at a fraction ``where`` of its length."""

    kind: str
    where: float
    size: int
    data: bytes

    def apply(self, raw: bytes) -> bytes:
        at = min(int(self.where * len(raw)), max(len(raw) - 1, 0))
        end = min(at + self.size, len(raw))
        if self.kind == "flip":
            if not raw:
                return raw
            return raw[:at] + bytes([raw[at] ^ (1 << (self.size % 8))]) + raw[at + 1 :]
        if self.kind == "truncate":
            return raw[:at]
        if self.kind == "overwrite":
            return raw[:at] + self.data[: end - at] + raw[at + len(self.data[: end - at]) :]
        if self.kind == "delete":
            return raw[:at] + raw[end:]
        if self.kind == "duplicate":
            return raw[:end] + raw[at:end] + raw[end:]
        assert self.kind == "insert"
        return raw[:at] + self.data + raw[at:]


_MUTATION = st.builds(
    Mutation,
    kind=st.sampled_from(
        ["flip", "flip", "truncate", "overwrite", "delete", "duplicate", "insert"]
    ),
    where=st.floats(0.0, 1.0),
    size=st.integers(1, 4096),
    data=st.binary(min_size=1, max_size=64),
)


def recording_mutations() -> st.SearchStrategy[list[Mutation]]:
    """One to three edits of a recording's bytes."""
    return st.lists(_MUTATION, min_size=1, max_size=3)


# ---------------------------------------------------------------------------------- checks


class _OverTime(Exception):
    pass


@contextlib.contextmanager
def _time_bound(seconds: float) -> Iterator[None]:
    """Raise :class:`_OverTime` in the block after ``seconds`` (a stall is a finding, not a
    hang of the suite); main thread only."""

    def expire(signum: int, frame: object) -> None:
        raise _OverTime

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _command(main: Callable[[list[str]], int], argv: list[str], prog: str) -> str | None:
    """Run a command line in this process; what is wrong with how it ended, if anything:
    exit 0, 1 or 2, and on 2 exactly one error line (warnings aside)."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(argv)
    lines = err.getvalue().splitlines()
    errors = [line for line in lines if not line.startswith(f"{prog}: warning: ")]
    if code not in (0, 1, 2):
        return f"{prog} {' '.join(argv[:1])} exited {code}: {lines[-3:]}"
    if code == 2 and (len(errors) != 1 or not errors[0].startswith(f"{prog}: error: ")):
        return f"{prog} {argv[0]} exited 2 with {len(errors)} error line(s): {errors[:3]}"
    if code != 2 and errors:
        return f"{prog} {argv[0]} exited {code} but wrote {errors[:3]}"
    return None


def check_scenario(text: str, folder: Path, *, seconds: float = HANG_S) -> str | None:
    """Parse the text (only :class:`ScenarioError` may come out); if it is a scenario, record
    five steps of it with ``rsstp-sim record`` (exit 0, or 2 and one line); within
    ``seconds``."""
    began = time.perf_counter()
    try:
        with _time_bound(seconds):
            try:
                parse_scenario(text, origin="fuzz.toml")
            except RsstpError:
                return None
            path = folder / "fuzz.toml"
            path.write_text(text, encoding="utf-8")
            out = folder / "fuzz.mcap"
            argv = ["record", str(path), "--steps", "5", "-o", str(out), "--force", "--quiet"]
            return _command(sim_cli.main, argv, "rsstp-sim")
    except _OverTime:
        return f"over {seconds} s ({time.perf_counter() - began:.1f} s)"
    except Exception as exc:  # the finding: anything but the documented errors
        return f"{type(exc).__name__}: {str(exc)[:300]}"


class Written:
    """A recording's bytes and what it holds, read from the intact file: the reference for a
    damaged copy (a plain class, so that hypothesis prints it by its short repr)."""

    def __init__(
        self,
        raw: bytes,
        steps: pd.DataFrame,
        models: dict[int, Any],
        events: set[tuple[int, str, str, str]],
    ) -> None:
        self.raw = raw
        self.steps = steps
        self.models = models
        self.events = events

    @classmethod
    def read(cls, path: Path) -> Written:
        with open_recording(path) as recording:
            return cls(
                path.read_bytes(),
                recording.steps(),
                {record.version: record for record in recording.model_versions()},
                _event_set(recording.events()),
            )

    def __repr__(self) -> str:
        return f"Written({len(self.raw):,} bytes, {len(self.steps):,} steps)"


def splitter_run(folder: Path) -> Written:
    """The recording the fuzz cases damage: a three-joint splitter run of 300 steps in chunks of
    8 KiB, so it holds several chunks, model versions and events."""
    path = folder / "three-joint-splitter.mcap"
    record(
        path,
        load_scenario("three-joint"),
        make_strategy("splitter"),
        steps=300,
        seed=3,
        chunk_size=8_192,
    )
    return Written.read(path)


def _event_set(events: pd.DataFrame) -> set[tuple[int, str, str, str]]:
    return set(
        zip(
            events["step"].tolist(),
            events["kind"].astype(str).tolist(),
            events["text"].tolist(),
            events["data"].tolist(),
            strict=True,
        )
    )


def _plain(table: pd.DataFrame) -> pd.DataFrame:
    """The table with categorical columns as text: a file read in part holds fewer
    categories, in the same order of first appearance."""
    return table.astype({c: object for c in table.columns if table[c].dtype == "category"})


def _not_written(path: Path, written: Written) -> str | None:
    """Read the damaged file through the API: only :class:`ReplayError` may come out, and
    every step, model version and event it returns must be one that was written."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnfinishedRecordingWarning)
        try:
            with open_recording(path) as recording:
                steps = recording.steps()
                models = recording.model_versions()
                events = recording.events()
                recording.memory()
        except ReplayError:
            return None
    steps = _plain(steps)
    original = _plain(written.steps)
    if len(steps) and not steps.index.isin(original.index).all():
        return f"steps {sorted(set(steps.index) - set(original.index))[:5]} were never written"
    expected = original.loc[steps.index.to_numpy()]
    if not steps.equals(expected):
        changed = steps.compare(expected)
        return f"steps read back differ from those written: {changed.head(3).to_dict()}"
    for model in models:
        if written.models.get(model.version) != model:
            return f"model version {model.version} differs from the one written"
    extra = _event_set(events) - written.events
    if extra:
        return f"events never written: {sorted(extra)[:2]}"
    return None


def check_recording(
    mutations: list[Mutation], written: Written, folder: Path, *, seconds: float = HANG_S
) -> str | None:
    """Damage a real recording's bytes, read it through the API and with ``rsstp-replay
    check`` within ``seconds``; what went wrong, if anything."""
    data = written.raw
    for mutation in mutations:
        data = mutation.apply(data)
    path = folder / "fuzz.mcap"
    path.write_bytes(data)
    began = time.perf_counter()
    try:
        with _time_bound(seconds):
            found = _not_written(path, written)
            if found is not None:
                return found
            return _command(replay_cli.main, ["check", str(path)], "rsstp-replay")
    except _OverTime:
        return f"over {seconds} s ({time.perf_counter() - began:.1f} s)"
    except Exception as exc:
        return f"{type(exc).__name__}: {str(exc)[:300]}"


# ----------------------------------------------------------------------------- deep nesting


@dataclass(frozen=True, slots=True)
class Deep:
    """A text nested ``depth`` deep given to one of the command line's parsed inputs."""

    where: str  # "scenario", "sweep", "matrix" or "param"
    depth: int
    opener: str  # "[" or "{"

    def text(self) -> str:
        if self.where in ("matrix", "param"):  # JSON
            inner = "[" * self.depth + "]" * self.depth
            if self.opener == "{":
                inner = '{"a":' * self.depth + "0" + "}" * self.depth
            return inner
        if self.opener == "{":
            return "x = " + "{a = " * self.depth + "1" + "}" * self.depth + "\n"
        return "x = " + "[" * self.depth + "]" * self.depth + "\n"


def deep_texts() -> st.SearchStrategy[Deep]:
    return st.builds(
        Deep,
        where=st.sampled_from(["scenario", "sweep", "matrix", "param"]),
        depth=st.one_of(st.integers(1, 200), st.integers(200, 5000)),
        opener=st.sampled_from(["[", "{"]),
    )


def check_deep(case: Deep, folder: Path) -> str | None:
    """The command ends in 0, 1 or 2 with at most one error line; never a traceback; past
    the nesting limit it is refused (exit 2)."""
    from rsstp_sim.nesting import MAX_NESTING

    text = case.text()
    file = folder / "deep.toml"
    file.write_text(text, encoding="utf-8")
    argv = {
        "scenario": ["run", str(file), "--steps", "1"],
        "sweep": ["sweep", str(file), "-o", str(folder / "deep-sweep")],
        "matrix": ["graph", "--matrix", text, "-o", str(folder / "deep.dot"), "--force"],
        "param": ["run", "thesis-roulette", "--steps", "1", "--param", f"actions={text}"],
    }[case.where]
    try:
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = sim_cli.main(argv)
    except Exception as exc:
        return f"{type(exc).__name__}: {str(exc)[:200]}"
    errors = err.getvalue().splitlines()
    if code not in (0, 1, 2) or len([e for e in errors if "error:" in e]) > 1:
        return f"{case.where}: exit {code}, {errors[:3]}"
    if case.depth > MAX_NESTING and code != 2:
        return f"{case.where}: nested {case.depth} deep, exit {code}"
    return None


# ------------------------------------------------------------------------ semantic rewrites

_EXTREMES = [0, -1, 1, 7, 359, 360, 2**31, 2**63 - 1, 2**63, 2**64, -(2**63) - 1, 10**30]


@dataclass(frozen=True, slots=True)
class Rewrite:
    """A ground-truth field of the step message at ``where`` (a fraction of the steps)
    given ``value`` (``nudge``: the old number plus ``value``)."""

    where: float
    field: str
    value: Any
    nudge: bool


_FIELDS = [
    "agent.sensation",
    "agent.feedback",
    "agent.action",
    "truth.angles_deg.0",
    "truth.angles_deg.2",
    "truth.joint_positions.1.x",
    "truth.joint_positions.3.y",
    "truth.distances.2.obstacles.0",
    "truth.blocked",
]


def semantic_rewrites() -> st.SearchStrategy[Rewrite]:
    number = st.one_of(
        st.sampled_from(_EXTREMES),
        st.integers(-400, 400),
        st.floats(allow_nan=False, allow_infinity=False, width=64),
        st.sampled_from([1e-12, 5e-324, 0.5, 1e308]),
    )
    return st.builds(
        Rewrite,
        where=st.floats(0.0, 1.0),
        field=st.sampled_from(_FIELDS),
        value=number,
        nudge=st.booleans(),
    )


def _rewrite_message(data: bytes, case: Rewrite) -> bytes | None:
    """The message with the field changed, or None when the change would not change it."""
    message = json.loads(data)
    *path, last = case.field.split(".")
    here: Any = message
    for key in path:
        here = here[int(key)] if key.isdigit() else here[key]
    key: Any = int(last) if last.isdigit() else last
    old = here[key]
    if isinstance(old, bool):
        new: Any = not old
    elif case.nudge and isinstance(case.value, int | float):
        new = old + case.value
    else:
        new = case.value
    same_kind = type(new) is type(old) or (
        isinstance(new, int | float) and isinstance(old, int | float) and type(new) is not bool
    )
    if same_kind and new == old:  # the same value (1 for 1.0 too): nothing to catch
        return None
    here[key] = new
    return json.dumps(message, separators=(",", ":")).encode()


def check_rewrite(
    case: Rewrite, source: Path, steps: int, folder: Path, *, seconds: float = HANG_S
) -> str | None:
    """A recording with one ground-truth value changed must not pass ``check --physics``
    (within ``seconds``)."""
    from test_corrupt import rewrite

    step = max(1, min(steps, int(case.where * (steps + 1))))
    target = step
    changed: list[bool] = []

    def message(topic: str, log_time: int, data: bytes) -> bytes:
        if topic != "/rsstp/step" or log_time != target * 1_000_000:
            return data
        new = _rewrite_message(data, case)
        if new is None:
            return data
        changed.append(True)
        return new

    path = rewrite(source, folder / "rewritten.mcap", message=message)
    if not changed:
        return None
    began = time.perf_counter()
    try:
        with _time_bound(seconds):
            err, out = io.StringIO(), io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
                code = replay_cli.main(["check", "--physics", str(path)])
    except _OverTime:
        return f"over {seconds} s ({time.perf_counter() - began:.1f} s)"
    except Exception as exc:
        return f"{type(exc).__name__}: {str(exc)[:300]}"
    if code == 0:
        return f"{case.field} changed at step {step} passed check --physics"
    if code == 2 and len(err.getvalue().splitlines()) != 1:
        return f"exit 2 with {err.getvalue().splitlines()[:3]}"
    return None


# ----------------------------------------------------------------------------- output faults

_WRITERS = ["table.csv", "table.parquet", "events.csv", "view", "export", "graph", "sim-graph"]


@dataclass(frozen=True, slots=True)
class OutputFault:
    """A command that writes, its output in a read-only folder or past ``limit`` bytes."""

    command: str
    read_only: bool
    limit: int


def output_faults() -> st.SearchStrategy[OutputFault]:
    return st.builds(
        OutputFault,
        command=st.sampled_from(_WRITERS),
        read_only=st.booleans(),
        limit=st.one_of(st.integers(0, 4096), st.integers(4096, 400_000)),
    )


def read_only_folder() -> Path:
    """A folder where no file can be created, by root too (procfs)."""
    return Path("/proc/1") if os.geteuid() == 0 else Path("/")


def check_output_fault(case: OutputFault, source: Path, folder: Path) -> str | None:
    """Exit 0 (it fit), 1 (a write error) or 2 (refused before work) with one line; on a
    failure the old output stays as it was and no side file is left."""
    where = read_only_folder() if case.read_only else folder
    suffix = {
        "table.csv": "t.csv",
        "table.parquet": "t.parquet",
        "events.csv": "e.csv",
        "view": "v.rrd",
        "export": "f.mcap",
        "graph": "g.dot",
        "sim-graph": "m.dot",
    }
    out = where / suffix[case.command]
    argv, main, prog = {
        "table.csv": (["table", str(source), "-o"], replay_cli.main, "rsstp-replay"),
        "table.parquet": (["table", str(source), "-o"], replay_cli.main, "rsstp-replay"),
        "events.csv": (["events", str(source), "-o"], replay_cli.main, "rsstp-replay"),
        "view": (["view", str(source), "--quiet", "--save"], replay_cli.main, "rsstp-replay"),
        "export": (["export", "--foxglove", str(source), "-o"], replay_cli.main, "rsstp-replay"),
        "graph": (["graph", str(source), "--step", "3", "-o"], replay_cli.main, "rsstp-replay"),
        "sim-graph": (["graph", "--matrix", "[[[0],[1]],[[1],[0]]]", "-o"], sim_cli.main,
                      "rsstp-sim"),
    }[case.command]  # fmt: skip
    if not case.read_only:
        out.write_bytes(b"the old output")
        for stale in out.parent.glob(out.name + "*"):
            if stale != out:
                stale.unlink()
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    err = io.StringIO()
    try:
        if not case.read_only:
            resource.setrlimit(resource.RLIMIT_FSIZE, (case.limit, hard))
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = main([*argv, str(out), "--force"])
    except Exception as exc:
        return f"{case.command}: {type(exc).__name__}: {str(exc)[:300]}"
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    lines = err.getvalue().splitlines()
    errors = [line for line in lines if not line.startswith(f"{prog}: warning: ")]
    if code not in (0, 1, 2) or (code and len(errors) != 1):
        return f"{case.command}: exit {code} with {errors[:3]}"
    if case.read_only:
        return None if code == 2 else f"{case.command}: read-only folder, exit {code}"
    left = sorted(p.name for p in out.parent.glob(out.name + "*") if p != out)
    if code and [n for n in left if n.endswith(".partial")]:
        return f"{case.command}: side files left: {left}"
    if code and out.read_bytes() != b"the old output":
        return f"{case.command}: a failed write changed the old output"
    return None
