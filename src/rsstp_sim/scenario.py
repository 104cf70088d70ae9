"""Scenarios: a body in its world, loaded from TOML.

A scenario file is part of the public contract. Its body's table (``[arm]``, or another
registered body's) picks the body (:mod:`rsstp_sim.bodies`), whose parser checks every key at
the boundary; a bad file raises :class:`~rsstp_sim.errors.ScenarioError` whose message names
the file, the key path and what was expected. Each body's keys are its own scenario module's
(the arm's: :mod:`rsstp_sim.arm.scenario`). Whether the body can stand at its start pose is
the body's geometry (:meth:`~rsstp_sim.interface.Body.check_start`), checked when a world is
built; :func:`load_scenario` and :func:`parse_scenario` check it too, unless asked only to
parse (``check_start=False``: a sweep's plan, its workers and the reader, whose worlds check
it where they are built).

Built-in scenarios ship as package data and can be named instead of a path.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from rsstp_sim.bodies import BODIES, AnyScenario, body_named
from rsstp_sim.errors import ScenarioError
from rsstp_sim.files import irregular
from rsstp_sim.nesting import too_deep

__all__ = [
    "AnyScenario",
    "Obstacle",
    "builtin_scenarios",
    "load_scenario",
    "parse_scenario",
]

MAX_OBSTACLES = 1_000
"""Most obstacles a scenario may have: every step measures each joint's distance to every
obstacle and records them, so a step's time and its record grow with their number (about
1,000 three-joint steps a second at this bound, against 25,000 with two obstacles)."""
MANY_OBSTACLES = 100
"""Above this many obstacles the command lines warn that steps slow down."""
MAX_MAGNITUDE = 1e12
"""The largest size of any number of a scenario (length, coordinate, radius, tolerance): the
geometry squares and sums them in float64, which must stay finite with room to spare."""
MAX_SCENARIO_BYTES = 1 << 20
"""Largest scenario file read (a thousand obstacles take about 50 KB)."""


@dataclass(frozen=True, slots=True)
class Obstacle:
    """A circular obstacle: a closed disk (touching it counts as meeting it)."""

    center: tuple[float, float]
    radius: float


def builtin_scenarios() -> dict[str, str]:
    """Names of the built-in scenarios with their one-line descriptions, sorted by name."""
    out: dict[str, str] = {}
    for entry in sorted(resources.files("rsstp_sim.scenarios").iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".toml"):
            name = entry.name.removesuffix(".toml")
            data = tomllib.loads(entry.read_text(encoding="utf-8"))
            out[name] = str(data.get("description", ""))
    return out


def load_scenario(name_or_path: str | Path, *, check_start: bool = True) -> AnyScenario:
    """Load a built-in scenario by name, or a scenario file by path; ``check_start``: see
    :func:`parse_scenario`."""
    text_name = str(name_or_path)
    if isinstance(name_or_path, str) and text_name in builtin_scenarios():
        resource = resources.files("rsstp_sim.scenarios").joinpath(f"{text_name}.toml")
        text = resource.read_text(encoding="utf-8")
        return parse_scenario(text, origin=text_name, check_start=check_start)
    path = Path(name_or_path)
    if not path.exists():
        known = ", ".join(builtin_scenarios())
        raise ScenarioError(
            f"{text_name}: no such scenario file, and not a built-in scenario ({known})"
        )
    kind = irregular(path)
    if kind is not None:
        raise ScenarioError(f"{path}: {kind}, not a scenario file (only regular files are read)")
    try:
        size = path.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ScenarioError(
                f"{path}: {size:,} bytes is too large for a scenario file (at most "
                f"{MAX_SCENARIO_BYTES:,}; {MAX_OBSTACLES:,} obstacles take about 50 KB)"
            )
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f"{path}: cannot read scenario file: {exc}") from None
    return parse_scenario(text, origin=str(path), check_start=check_start)


def parse_scenario(text: str, *, origin: str = "<string>", check_start: bool = True) -> AnyScenario:
    """Parse and validate a scenario from TOML text; ``origin`` names it in errors.
    ``check_start=False`` only parses: the body's start pose is then checked where its world
    is built (:meth:`~rsstp_sim.interface.Body.check_start`)."""
    deep = too_deep(text)
    if deep is not None:
        raise ScenarioError(f"{origin}: {deep}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{origin}: TOML syntax error: {exc}") from None
    present = [name for name in BODIES if name in data]
    if len(present) != 1:
        tables = " or ".join(f"[{name}]" for name in BODIES)
        found = "none" if not present else " and ".join(f"[{name}]" for name in present)
        raise ScenarioError(f"{origin}: expected one body table, {tables}; found {found}")
    body = body_named(present[0])
    scenario: AnyScenario = body.parse(data, text, origin)
    if check_start:
        body.check_start(scenario)
    return scenario
