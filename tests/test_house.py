"""House rules a reader relies on: errors live in the errors modules and every error raised on
purpose is the package's own (``except RsstpError`` catches them all)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from types import FrameType

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
REFERENCE = SRC.parent / "recordings" / "three-joint-random.mcap"
BUILT_IN = {"Exception", "ValueError", "TypeError", "KeyError", "IndexError", "RuntimeError"}
SIGNALS = {"Refuted", "Confined"}
"""Exceptions used as control flow inside one module, never raised to a caller outside it:
the learner's walk tells its planner that the hypothesis was refuted, or that the agent is
confined to a part of the world that never senses."""


def _modules() -> list[tuple[Path, ast.Module]]:
    return [(path, ast.parse(path.read_text(encoding="utf-8"))) for path in SRC.rglob("*.py")]


def test_exception_and_warning_classes_live_in_errors_modules() -> None:
    outside = [
        f"{path.relative_to(SRC)}: {node.name}"
        for path, tree in _modules()
        if path.name != "errors.py"
        for node in ast.walk(tree)
        if isinstance(node, ast.ClassDef)
        and node.name not in SIGNALS
        and any(
            isinstance(base, ast.Name) and base.id.endswith(("Error", "Exception", "Warning"))
            for base in node.bases
        )
    ]
    assert outside == []


def test_no_built_in_exception_is_raised_on_purpose() -> None:
    raised = [
        f"{path.relative_to(SRC)}:{node.lineno}: {node.exc.func.id}"
        for path, tree in _modules()
        for node in ast.walk(tree)
        if isinstance(node, ast.Raise)
        and isinstance(node.exc, ast.Call)
        and isinstance(node.exc.func, ast.Name)
        and node.exc.func.id in BUILT_IN
    ]
    assert raised == []


# ------------------------------------------------------------------- one direction of import

PACKAGES = ("rsstp_format", "rsstp_sim", "rsstp_replay", "rsstp_sweep", "rsstp_cli")
"""Bottom to top: each package may import those before it, never one after it (the file
format imports neither the simulator nor the replay side)."""
READER_LAYERS = ("_container", "_chunks", "_contract", "recording")
"""The replay side's reader, bottom to top: the MCAP file's records, the messages inside its
chunks, the recording contract, the recording."""


def _imports(tree: ast.Module) -> set[str]:
    """Every module named by an import anywhere in ``tree`` (inside functions and
    ``TYPE_CHECKING`` blocks too: a deferred import is still an arrow)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def test_no_package_imports_one_above_it() -> None:
    upward = []
    for path, tree in _modules():
        package = path.relative_to(SRC).parts[0]
        if package not in PACKAGES:
            continue
        above = PACKAGES[PACKAGES.index(package) + 1 :]
        upward += [
            f"{path.relative_to(SRC)} imports {name}"
            for name in sorted(_imports(tree))
            if name.split(".")[0] in above
        ]
    assert upward == []


def test_no_package_imports_another_packages_private_module() -> None:
    """A module whose name starts with ``_`` is its package's own: another package reaches
    what it needs through a public module, so the private one can change freely."""
    reaching = []
    for path, tree in _modules():
        package = path.relative_to(SRC).parts[0]
        for name in sorted(_imports(tree)):
            parts = name.split(".")
            if parts[0] in PACKAGES and parts[0] != package:
                private = [part for part in parts[1:] if part.startswith("_")]
                if private and not all(p.startswith("__") for p in private):
                    reaching.append(f"{path.relative_to(SRC)} imports {name}")
    assert reaching == []


BODY_INSIDES = {
    "rsstp_sim/arm": ("rsstp_sim.arm.geometry", "rsstp_sim.arm.table"),
    "rsstp_sim/rover": ("rsstp_sim.rover.table",),
}
"""A body's package -> the modules of its insides: its geometry and its table, which no
module outside the package imports (everything else goes through the world interface)."""


def test_no_floor_of_the_replay_side_imports_anothers_private_module() -> None:
    """The replay side's floors (reader, audits, viewer, export) reach each other through
    public modules and names only, as packages do."""
    reaching = []
    for path, tree in _modules():
        parts = path.relative_to(SRC).parts
        if parts[0] != "rsstp_replay" or len(parts) < 3:
            continue
        floor = parts[1]
        for name in sorted(_imports(tree)):
            names = name.split(".")
            if names[0] != "rsstp_replay" or len(names) < 3 or names[1] == floor:
                continue
            if any(part.startswith("_") and not part.startswith("__") for part in names[2:]):
                reaching.append(f"{path.relative_to(SRC)} imports {name}")
    assert reaching == []


def test_only_a_body_imports_its_own_geometry() -> None:
    reaching = []
    for path, tree in _modules():
        where = path.relative_to(SRC).as_posix()
        for package, insides in BODY_INSIDES.items():
            if where.startswith(package + "/"):
                continue
            reaching += [
                f"{where} imports {name}"
                for name in sorted(_imports(tree))
                if any(name == inside or name.startswith(inside + ".") for inside in insides)
            ]
    assert reaching == []


def test_the_five_packages_are_all_there_is() -> None:
    """No top-level module beside the packages in every user's site-packages, and the
    console scripts start in the command-line package."""
    import tomllib

    installed = sorted(
        p.stem for p in SRC.iterdir() if p.suffix == ".py" or (p / "__init__.py").is_file()
    )
    assert installed == sorted(PACKAGES)
    project = tomllib.loads((SRC.parent / "pyproject.toml").read_text(encoding="utf-8"))
    assert "py-modules" not in project["tool"]["setuptools"]
    assert {script.split(":")[0] for script in project["project"]["scripts"].values()} == {
        "rsstp_cli.start"
    }


def test_the_reader_layers_import_only_downwards() -> None:
    upward = []
    for rank, layer in enumerate(READER_LAYERS):
        tree = ast.parse(
            (SRC / "rsstp_replay" / "reader" / f"{layer}.py").read_text(encoding="utf-8")
        )
        above = {f"rsstp_replay.reader.{name}" for name in READER_LAYERS[rank + 1 :]}
        upward += [f"{layer} imports {name}" for name in sorted(_imports(tree) & above)]
    assert upward == []


def _calls_between_layers(action: Callable[[], object]) -> list[tuple[str, str]]:
    """(caller layer, called layer) for every call from one reader layer into another while
    ``action`` runs (a generator resumed counts as a call from its resumer)."""
    files = {str(SRC / "rsstp_replay" / "reader" / f"{layer}.py"): layer for layer in READER_LAYERS}
    calls: list[tuple[str, str]] = []

    def profile(frame: FrameType, event: str, arg: object) -> None:
        if event != "call" or frame.f_back is None:
            return
        called = files.get(frame.f_code.co_filename)
        caller = files.get(frame.f_back.f_code.co_filename)
        if called is not None and caller is not None and called != caller:
            calls.append((caller, called))

    sys.setprofile(profile)
    try:
        action()
    finally:
        sys.setprofile(None)
    return calls


@pytest.mark.parametrize("finished", [True, False], ids=["finished", "unfinished"])
def test_reading_a_recording_never_calls_back_up(finished: bool, tmp_path: Path) -> None:
    """Opening a recording goes down the layers once (container, chunks, contract, recording:
    each calls only those below it), and so does reading its tables; a file cut short by a
    killed writer is scanned the same way."""
    from rsstp_replay import open_recording

    path = REFERENCE
    if not finished:
        path = tmp_path / "cut.mcap"
        path.write_bytes(REFERENCE.read_bytes()[: REFERENCE.stat().st_size * 2 // 3])

    def read() -> None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            recording = open_recording(path)
        recording.steps()
        recording.events()
        recording.model_at(recording.n_steps)

    calls = _calls_between_layers(read)
    rank = {layer: at for at, layer in enumerate(READER_LAYERS)}
    assert {called for _, called in calls} >= {"_container", "_chunks", "_contract"}
    assert sorted({(a, b) for a, b in calls if rank[a] < rank[b]}) == []

    def just_open() -> None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            open_recording(path)

    # Opening: the recording finds the file's records (the container), then has them checked
    # (the contract), which reads the scenario message through the chunks layer, which reads
    # the chunk records through the container: one descent, no layer skipped on the way.
    assert set(_calls_between_layers(just_open)) == {
        ("recording", "_container"),
        ("recording", "_contract"),
        ("_contract", "_chunks"),
        ("_chunks", "_container"),
    }


WALK = SRC.parent / "bench" / "walk.py"


@pytest.mark.parametrize(
    ("scenario", "strategy", "body"),
    [("thesis-algo", "random", "rsstp_sim/arm"), ("rover-room", "learner", "rsstp_sim/rover")],
)
def test_a_sweep_runs_scenario_goes_down_the_floors_without_coming_back(
    scenario: str, strategy: str, body: str
) -> None:
    """The scenario of a sweep's run, planned and then recorded and audited as a worker does
    (``bench/walk.py``), is handed to each floor once, top down: the plan, the recorder, the
    run, the body (its world, checked at its start, and the header read from it), the ground
    truth of that world, the reader. No floor goes back with it to one it has left (issue 31:
    the plan, the worker and the reader each checked the start with the body's geometry,
    the header and the audit's truth went back down to the registry and the body)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("walk", WALK)
    assert spec is not None and spec.loader is not None
    walk = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(walk)
    visits = walk.walk(scenario, strategy, 300)
    floors = [floor for floor, _ in walk.stops_of([(walk.floor_of(w), f) for w, f in visits])]
    assert floors == [
        "rsstp_sweep",
        "rsstp_sim/recording",
        "rsstp_sim",
        body,
        "rsstp_sim/truth",
        "rsstp_replay/reader",
    ]


READING = """
import sys
from rsstp_replay import open_recording

for name in sys.argv[1:]:
    with open_recording(name) as recording:
        recording.steps(truth=True)
        recording.memory()
        recording.events()
        recording.model_at(recording.n_steps)
        recording.model_versions()
        recording.ground_truth()
audits = sorted(m for m in sys.modules if m.startswith("rsstp_replay.audits"))
print(",".join(audits))
"""


def test_reading_a_recording_never_imports_the_audits() -> None:
    """The reader returns what the file holds: its steps (with their true classes), memory,
    events and models; judging them is the audits' business, imported only by who asks."""
    recordings = Path(__file__).parents[1] / "recordings"
    names = [
        str(recordings / "two-joint-30-learner.mcap"),
        str(recordings / "rover-one-way-random.mcap"),
    ]
    env = dict(os.environ, PYTHONPATH=str(SRC))
    done = subprocess.run(
        [sys.executable, "-c", READING, *names], capture_output=True, text=True, env=env, check=True
    )
    assert done.stdout.strip() == ""
