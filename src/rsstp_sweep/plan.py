"""A sweep file, checked and expanded into runs.

A sweep file is TOML::

    steps = 2000
    seeds = [0, 1, 2]              # or a count: seeds = 12 means 0..11
    scenarios = ["thesis-roulette", "one-joint-10", "my-arm.toml"]
    [[strategy]]
    name = "learner"
    [[strategy]]
    name = "script"
    params = { actions = [0] }     # fixed parameters: a list here is one value
    grid = { actions = [[0], [0, 1]] }  # swept: one run per value, every combination

A run is one scenario x one strategy (with one combination of its grid) x one seed. Scenario
files are read relative to the sweep file, here, before anything runs: the workers receive the
scenario's text, so they need not see the file. Everything a run needs is checked here (the
scenario parses, the strategy builds with its parameters and accepts the scenario), but for
the body's start pose, which needs its geometry and is checked where the world is built: by
each worker, and once for all by :func:`check_starts`, which
:func:`~rsstp_sweep.engine.run_sweep` calls before the cluster starts. So a bad sweep is one
error before any work starts.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rsstp_sim.errors import RsstpError
from rsstp_sim.nesting import too_deep
from rsstp_sim.runner import check_strategy
from rsstp_sim.scenario import AnyScenario, load_scenario, parse_scenario
from rsstp_sim.strategies import make_strategy
from rsstp_sweep.errors import SweepError

__all__ = ["Run", "Sweep", "SweepError", "check_starts", "load_sweep", "parse_sweep"]

_TOP_LEVEL = frozenset({"steps", "seeds", "scenarios", "strategy"})
_STRATEGY_KEYS = frozenset({"name", "params", "grid"})
_MAX_RUNS = 100_000


@dataclass(frozen=True, slots=True)
class Run:
    """One run of a sweep: everything a worker needs, and its file name in the output.

    ``params`` are the parameters as the sweep gives them; ``strategy_name`` and
    ``recorded_params`` (every parameter, defaults included) are what its recording names."""

    name: str
    scenario: str
    scenario_source: str
    scenario_origin: str
    scenario_sha256: str
    strategy: str
    strategy_name: str
    params: Mapping[str, Any]
    recorded_params: Mapping[str, Any]
    seed: int
    steps: int

    @property
    def params_json(self) -> str:
        return json.dumps(dict(self.params), sort_keys=True)

    @property
    def recording(self) -> str:
        """The recording's file name in the output directory."""
        return f"{self.name}.mcap"


@dataclass(frozen=True, slots=True)
class Sweep:
    """A checked sweep: its text (kept with the results) and its runs, in file order."""

    source: str
    origin: str
    steps: int
    seeds: tuple[int, ...]
    runs: tuple[Run, ...]


def load_sweep(path: str | Path) -> Sweep:
    """Read and check a sweep file (see the module docstring)."""
    file = Path(path)
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SweepError(f"{file}: no such sweep file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SweepError(f"{file}: cannot read the sweep file: {exc}") from None
    return parse_sweep(text, origin=str(file), base=file.parent)


def parse_sweep(text: str, *, origin: str = "<string>", base: Path | None = None) -> Sweep:
    """Check a sweep from TOML text; scenario files are relative to ``base``."""
    deep = too_deep(text)
    if deep is not None:
        raise SweepError(f"{origin}: {deep}")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SweepError(f"{origin}: TOML syntax error: {exc}") from None
    unknown = sorted(set(data) - _TOP_LEVEL)
    if unknown:
        raise SweepError(
            f"{origin}: unknown key {unknown[0]!r} (expected {', '.join(sorted(_TOP_LEVEL))})"
        )
    steps = data.get("steps")
    if isinstance(steps, bool) or not isinstance(steps, int) or steps < 0:
        raise SweepError(f"{origin}: steps: expected an integer >= 0, got {steps!r}")
    seeds = _seeds(origin, data.get("seeds"))
    scenarios = _scenarios(origin, data.get("scenarios"), base or Path.cwd())
    strategies = _strategies(origin, data.get("strategy"))
    runs = [
        _run(scenario, given, name, params, seed, steps)
        for given, scenario in scenarios
        for name, params in strategies
        for seed in seeds
    ]
    names = [run.name for run in runs]
    if len(set(names)) != len(names):
        twice = next(name for name in names if names.count(name) > 1)
        raise SweepError(f"{origin}: two runs would write {twice}.mcap: rename a scenario")
    if len(runs) > _MAX_RUNS:
        raise SweepError(f"{origin}: {len(runs):,} runs; at most {_MAX_RUNS:,} in one sweep")
    for given, scenario in scenarios:  # each strategy must accept each scenario
        for name, params in strategies:
            try:
                check_strategy(
                    make_strategy(name, params),
                    scenario.actions,
                    float_feedback=scenario.feedback_mode == "float",
                )
            except RsstpError as exc:
                raise SweepError(
                    f"{origin}: scenario {given!r}, strategy {name!r}: {exc}"
                ) from None
    return Sweep(text, origin, steps, seeds, tuple(runs))


def check_starts(sweep: Sweep) -> None:
    """Raise :class:`SweepError` when a scenario's body cannot stand at its start pose (its
    world refuses to be built): what each of its runs' workers would find, told once before
    any run."""
    seen: set[tuple[str, str]] = set()
    for run in sweep.runs:
        key = (run.scenario_source, run.scenario_origin)
        if key not in seen:
            seen.add(key)
            try:
                parse_scenario(run.scenario_source, origin=run.scenario_origin)
            except RsstpError as exc:
                raise SweepError(f"{sweep.origin}: scenarios: {exc}") from None


def _seeds(origin: str, value: object) -> tuple[int, ...]:
    if isinstance(value, int) and not isinstance(value, bool) and value >= 1:
        return tuple(range(value))
    if (
        isinstance(value, list)
        and value
        and all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in value)
    ):
        if len(set(value)) != len(value):
            raise SweepError(f"{origin}: seeds: a seed is listed twice in {value}")
        return tuple(value)
    raise SweepError(
        f"{origin}: seeds: expected a count >= 1 or a list of integers >= 0, got {value!r}"
    )


def _scenarios(origin: str, value: object, base: Path) -> list[tuple[str, AnyScenario]]:
    if not isinstance(value, list) or not value or not all(isinstance(s, str) for s in value):
        raise SweepError(f"{origin}: scenarios: expected a list of names or files, got {value!r}")
    loaded: list[tuple[str, AnyScenario]] = []
    for given in value:
        path = base / given
        try:
            scenario = load_scenario(path if given.endswith(".toml") else given, check_start=False)
        except RsstpError as exc:
            raise SweepError(f"{origin}: scenarios: {exc}") from None
        loaded.append((given, scenario))
    names = [scenario.name for _, scenario in loaded]
    for name in names:
        if names.count(name) > 1:
            raise SweepError(f"{origin}: scenarios: two scenarios are named {name!r}")
    return loaded


def _strategies(origin: str, value: object) -> list[tuple[str, dict[str, Any]]]:
    if not isinstance(value, list) or not value:
        raise SweepError(f"{origin}: expected at least one [[strategy]] table")
    expanded: list[tuple[str, dict[str, Any]]] = []
    for index, table in enumerate(value):
        where = f"{origin}: strategy[{index}]"
        if not isinstance(table, dict):
            raise SweepError(f"{where}: expected a table, got {table!r}")
        unknown = sorted(set(table) - _STRATEGY_KEYS)
        if unknown:
            raise SweepError(f"{where}: unknown key {unknown[0]!r} (expected name, params, grid)")
        name = table.get("name")
        if not isinstance(name, str) or not name:
            raise SweepError(f"{where}.name: expected a strategy name, got {name!r}")
        params = table.get("params", {})
        grid = table.get("grid", {})
        if not isinstance(params, dict):
            raise SweepError(f"{where}.params: expected a table, got {params!r}")
        if not isinstance(grid, dict):
            raise SweepError(f"{where}.grid: expected a table, got {grid!r}")
        for key, values in grid.items():
            if not isinstance(values, list) or not values:
                raise SweepError(
                    f"{where}.grid.{key}: expected a non-empty list of values, got {values!r}"
                )
            if key in params:
                raise SweepError(f"{where}.grid.{key}: also in params; give it in one of them")
        for combination in itertools.product(*grid.values()):
            each = {**params, **dict(zip(grid, combination, strict=True))}
            try:
                make_strategy(name, each)
            except RsstpError as exc:
                raise SweepError(f"{where}: {exc}") from None
            expanded.append((name, each))
    seen = set()
    for name, params in expanded:
        key = (name, json.dumps(params, sort_keys=True))
        if key in seen:
            raise SweepError(f"{origin}: strategy {name!r} with {params} is listed twice")
        seen.add(key)
    return expanded


def _run(
    scenario: AnyScenario, given: str, strategy: str, params: dict[str, Any], seed: int, steps: int
) -> Run:
    built = make_strategy(strategy, params)  # its name and full parameters, as recorded
    label = _file_safe(strategy.rsplit(":", 1)[-1])
    if params:
        digest = hashlib.sha256(json.dumps(params, sort_keys=True).encode()).hexdigest()[:8]
        label = f"{label}-{digest}"
    return Run(
        name=f"{_file_safe(scenario.name)}__{label}__seed{seed}",
        scenario=given,
        scenario_source=scenario.source,
        scenario_origin=scenario.origin,
        scenario_sha256=scenario.sha256,
        strategy=strategy,
        strategy_name=built.name,
        params=params,
        recorded_params=json.loads(json.dumps(dict(built.params()))),
        seed=seed,
        steps=steps,
    )


def _file_safe(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", text).strip("-") or "x"
