"""Shared fixtures: scenario TOML text from plain dicts, and scenario files in ``tmp_path``."""

from __future__ import annotations

import copy
import os
import signal
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path

import pytest

from scenarios import toml_text

ScenarioText = Callable[[Mapping[str, object]], str]
WriteScenario = Callable[..., Path]

VALID_SCENARIO: dict[str, object] = {
    "name": "two-links",
    "description": "two links, one obstacle out of the way",
    "arm": {"lengths": [2.0, 1.0], "initial_deg": [0, 90], "step_deg": 5},
    "obstacles": [{"center": [-2.0, -2.0], "radius": 0.5}],
    "feedback": {"target_deg": [0, 90], "mode": "bool", "tolerance": 1e-6},
    "motion": {"collision": "swept"},
}
"""A valid two-link scenario; tests copy it and break one key at a time."""

THIN_OBSTACLE_TOML = """
[arm]
lengths = [2.0]
initial_deg = [0]
step_deg = 90
[[obstacles]]
center = [1.4, 1.4]
radius = 0.1
[motion]
collision = "{mode}"
"""
"""One link of length 2 at 0 degrees turning by 90; a thin disk on the diagonal in between.
The end pose is free, the swept motion is not: ``.format(mode="swept"|"endpoint")``."""


@pytest.fixture(scope="session")
def scenario_text() -> ScenarioText:
    """Turns a scenario dict (as in :data:`VALID_SCENARIO`) into TOML text."""
    return toml_text


@pytest.fixture
def scenario_data() -> dict[str, object]:
    """A fresh deep copy of :data:`VALID_SCENARIO`, free to mutate."""
    return copy.deepcopy(VALID_SCENARIO)


@pytest.fixture
def write_scenario(tmp_path: Path) -> WriteScenario:
    """Writes TOML text to a file in ``tmp_path`` and returns its path."""

    def write(text: str, name: str = "scenario.toml") -> Path:
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        return path

    return write


@pytest.fixture(scope="session")
def truth_cache_home(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The XDG cache folder every test (and every command a test runs) uses: the truth cache
    goes there, never into the user's own ``~/.cache``."""
    return tmp_path_factory.mktemp("xdg-cache")


@pytest.fixture(scope="session", autouse=True)
def _isolated_truth_cache(truth_cache_home: Path) -> Iterator[None]:
    """Session-wide, so that module fixtures that run commands (a sweep) are inside it too."""
    before = os.environ.get("XDG_CACHE_HOME")
    os.environ["XDG_CACHE_HOME"] = str(truth_cache_home)
    yield
    if before is None:
        del os.environ["XDG_CACHE_HOME"]
    else:
        os.environ["XDG_CACHE_HOME"] = before


@pytest.fixture(scope="session", autouse=True)
def _ctrl_c_at_its_default() -> Iterator[None]:
    """Every command a test starts gets SIGINT at its default, as from a terminal's
    foreground, also when the suite itself was started with SIGINT ignored (which a shell
    does to a job it puts in the background without job control, and a child inherits): the
    Ctrl-C tests test the commands, not how the suite was started."""
    before = signal.getsignal(signal.SIGINT)
    if before is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    if before is signal.SIG_IGN:
        signal.signal(signal.SIGINT, before)


@pytest.fixture
def unwritable_directory(tmp_path: Path) -> Iterator[Path]:
    """A directory this user cannot create files in: a 0o500 one for an ordinary user; for
    root, who may write anywhere permissions say no, procfs's ``/proc/1`` (the kernel refuses
    new files there to everyone)."""
    directory = tmp_path / "read-only"
    directory.mkdir()
    directory.chmod(0o500)
    try:
        if os.access(directory, os.W_OK):
            proc = Path("/proc/1")
            if not proc.is_dir() or os.access(proc, os.W_OK):
                pytest.fail("no directory here refuses new files to this user (root without /proc)")
            yield proc
        else:
            yield directory
    finally:
        directory.chmod(0o700)


ALLOWED_SKIPS: tuple[str, ...] = ()
"""Skip reasons (substrings) that CI accepts; .ci/run prints them. Every other skip in CI
(``RSSTP_FAIL_ON_SKIP=1``) fails the run: a test that never runs does not exist."""


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    if os.environ.get("RSSTP_FAIL_ON_SKIP") != "1":
        return
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    skipped = reporter.stats.get("skipped", []) if reporter is not None else []
    unexpected = [
        report
        for report in skipped
        if not any(allowed in str(report.longrepr) for allowed in ALLOWED_SKIPS)
    ]
    for report in unexpected:
        reporter.write_line(f"skipped in CI (not allowed): {report.nodeid}: {report.longrepr}")
    if unexpected:
        session.exitstatus = pytest.ExitCode.TESTS_FAILED
