"""The walk of a sweep run's scenario through the code: where it stops, and how often it goes
back to a file it has already left.

    PYTHONPATH=src python bench/walk.py                      # thesis-algo, the random strategy
    PYTHONPATH=src python bench/walk.py --scenario rover-room --strategy learner --list

A one-run sweep (the scenario, a strategy, 300 steps) is planned from its sweep file
(:func:`rsstp_sweep.load_sweep`) and executed as a worker does it
(:func:`rsstp_sweep.execute.execute_run`: record, then audit with the truth), in this process,
under :func:`sys.setprofile`. Every call of a function of this project's packages (``src/``)
that is handed a scenario object (an argument that is a scenario of any body, the one the
sweep plans with, the worker's and the reader's; not the scenario's own properties) is a
*visit* of that function's file. A *stop* is a run of consecutive visits to one file; a
*return* is a stop at a file the walk has stopped at before (it left the file and came back).
The same is counted by floor (a package, or one of its subpackages: the sweep, the run, a
body, the recorder, the ground truth, the replay side's reader). Target (issue 31): the walk
goes down through the floors without coming back.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path
from typing import Any

from rsstp_sim.arm.scenario import Scenario
from rsstp_sim.rover import RoverScenario
from rsstp_sweep import load_sweep
from rsstp_sweep.execute import execute_run

SRC = Path(__file__).resolve().parents[1] / "src"
SCENARIO_TYPES = (Scenario, RoverScenario)


def walk(scenario: str, strategy: str, steps: int) -> list[tuple[str, str]]:
    """The (file, function) of every call handed a scenario, in order."""
    visits: list[tuple[str, str]] = []
    src = str(SRC)

    def profile(frame: Any, event: str, arg: Any) -> None:
        if event != "call":
            return
        code = frame.f_code
        if not code.co_filename.startswith(src):
            return
        n = code.co_argcount + code.co_kwonlyargcount
        values = frame.f_locals
        for name in code.co_varnames[:n]:
            if name == "self":  # the scenario answering about itself (a property) is no stop
                continue
            if isinstance(values.get(name), SCENARIO_TYPES):
                where = Path(code.co_filename).relative_to(SRC).as_posix()
                visits.append((where, code.co_qualname))
                return

    with tempfile.TemporaryDirectory() as folder:
        sweep_file = Path(folder) / "sweep.toml"
        sweep_file.write_text(
            f'scenarios = ["{scenario}"]\nseeds = 1\nsteps = {steps}\n\n'
            f'[[strategy]]\nname = "{strategy}"\n',
            encoding="utf-8",
        )
        output = Path(folder) / "out"
        output.mkdir()
        sys.setprofile(profile)
        try:
            sweep = load_sweep(sweep_file)
            row = execute_run(sweep.runs[0], str(output))
        finally:
            sys.setprofile(None)
        if row["status"] != "done":
            raise SystemExit(f"the run failed: {row['error']}")
    return visits


def stops_of(visits: list[tuple[str, str]]) -> list[tuple[str, list[str]]]:
    """Consecutive visits to one file, as (file, the functions called there in turn)."""
    stops: list[tuple[str, list[str]]] = []
    for where, function in visits:
        if stops and stops[-1][0] == where:
            if stops[-1][1][-1] != function:
                stops[-1][1].append(function)
        else:
            stops.append((where, [function]))
    return stops


def floor_of(where: str) -> str:
    """The floor of a file: its package's subpackage (``rsstp_sim/arm``), or the package for a
    module at its top (``rsstp_sim``)."""
    parts = where.split("/")
    return "/".join(parts[:2]) if len(parts) > 2 else parts[0]


def report(stops: list[tuple[str, list[str]]], what: str, *, listed: bool) -> None:
    seen: set[str] = set()
    returns: dict[str, int] = {}
    for index, (where, functions) in enumerate(stops):
        back = where in seen
        seen.add(where)
        if back:
            returns[where] = returns.get(where, 0) + 1
        if listed:
            mark = "  (back)" if back else ""
            print(f"{index + 1:3d}  {where}: {', '.join(functions)}{mark}")
    print(f"by {what}: {len(stops)} stops in {len(seen)} {what}s, {sum(returns.values())} returns")
    for where, count in sorted(returns.items(), key=lambda item: -item[1]):
        print(f"  back to {where}: {count} time{'s' * (count != 1)}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="thesis-algo")
    parser.add_argument("--strategy", default="random")
    parser.add_argument("--steps", type=int, default=300)
    parser.add_argument("--list", action="store_true", help="print every stop")
    args = parser.parse_args()
    visits = walk(args.scenario, args.strategy, args.steps)
    print(f"{args.scenario} ({args.strategy}, {args.steps} steps)")
    report(stops_of(visits), "file", listed=args.list)
    report(stops_of([(floor_of(where), f) for where, f in visits]), "floor", listed=args.list)


if __name__ == "__main__":
    main()
