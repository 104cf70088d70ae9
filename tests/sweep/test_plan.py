"""Sweep files: expanded into runs in file order, and every mistake caught before any work."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rsstp_sweep import SweepError, load_sweep, parse_sweep
from scenarios import sweep_toml

BASE = sweep_toml(steps=100, seeds=3)


def test_runs_are_scenario_by_strategy_by_seed_in_file_order() -> None:
    sweep = parse_sweep(BASE)
    assert sweep.seeds == (0, 1, 2)
    assert len(sweep.runs) == 2 * 2 * 3
    first = sweep.runs[0]
    assert (first.scenario, first.strategy, first.seed, first.steps) == (
        "thesis-roulette",
        "learner",
        0,
        100,
    )
    assert [run.seed for run in sweep.runs[:3]] == [0, 1, 2]
    script = sweep.runs[3]
    assert script.strategy == "script" and dict(script.params) == {"actions": [0]}
    assert script.name.startswith("thesis-roulette__script-") and script.name.endswith("__seed0")
    assert len({run.name for run in sweep.runs}) == len(sweep.runs)


def test_a_grid_sweeps_every_combination_and_params_stay_fixed() -> None:
    sweep = parse_sweep(
        """
steps = 10
seeds = [5]
scenarios = ["one-joint-10"]
[[strategy]]
name = "script"
grid = { actions = [[0], [1], [0, 1]] }
"""
    )
    assert [dict(run.params) for run in sweep.runs] == [
        {"actions": [0]},
        {"actions": [1]},
        {"actions": [0, 1]},
    ]
    assert len({run.name for run in sweep.runs}) == 3


def test_a_scenario_file_is_read_relative_to_the_sweep_file(tmp_path: Path) -> None:
    arms = tmp_path / "arms"
    arms.mkdir()
    scenario = Path("src/rsstp_sim/scenarios/thesis-roulette.toml").read_text()
    (arms / "mine.toml").write_text(scenario.replace('name = "thesis-roulette"', 'name = "mine"'))
    (tmp_path / "sweep.toml").write_text(BASE.replace('"one-joint-10"', '"arms/mine.toml"'))
    sweep = load_sweep(tmp_path / "sweep.toml")
    run = sweep.runs[-1]
    assert run.scenario == "arms/mine.toml" and run.name.startswith("mine__")
    assert 'name = "mine"' in run.scenario_source


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("steps = 100", "steps = -1"), r"steps: expected an integer >= 0, got -1"),
        (("seeds = 3", "seeds = 0"), r"seeds: expected a count >= 1"),
        (("seeds = 3", "seeds = [1, 1]"), r"seeds: a seed is listed twice"),
        (('"one-joint-10"', '"no-such"'), r"no-such: no such scenario file"),
        (('"one-joint-10"', '"missing.toml"'), r"missing.toml: no such scenario file"),
        (('name = "learner"', 'name = "nope"'), r"strategy\[0\]: .*nope"),
        (("actions = [0]", "actions = [7]"), r"strategy 'script'.*actions \[7\]"),
        (("params = {", "parms = {"), r"strategy\[1\]: unknown key 'parms'"),
        (("steps = 100", "steps = 100\nstep = 3"), r"unknown key 'step'"),
        (('"thesis-roulette", ', '"one-joint-10", '), r"two scenarios are named 'one-joint-10'"),
        (("steps = 100", "steps = [100"), r"TOML syntax error"),
    ],
)
def test_a_bad_sweep_is_one_error_naming_the_key(change: tuple[str, str], message: str) -> None:
    old, new = change
    assert old in BASE
    with pytest.raises(SweepError, match=message):
        parse_sweep(BASE.replace(old, new), origin="sweep.toml")


def test_checking_a_sweep_builds_no_world(monkeypatch: pytest.MonkeyPatch) -> None:
    # Each strategy is checked against each scenario before any run, without building its
    # world (a table of every pose, seconds for a large arm): the workers build it once each.
    import rsstp_sim.bodies as bodies
    import rsstp_sim.runner as runner

    def refuse(*_args: object, **_kwargs: object) -> object:
        raise AssertionError("a world was built")

    monkeypatch.setattr(bodies, "make_world", refuse)
    monkeypatch.setattr(runner, "make_world", refuse)
    assert len(parse_sweep(BASE).runs) == 12
    with pytest.raises(SweepError, match=r"strategy 'script'.*actions \[7\]"):
        parse_sweep(BASE.replace("actions = [0]", "actions = [7]"), origin="sweep.toml")


def test_a_start_pose_the_arm_cannot_take_is_refused_before_any_run(tmp_path: Path) -> None:
    """The plan only parses the scenarios; their start poses are checked where the world is
    built (each worker), and once for all before the cluster starts, with the line the plan
    gave when it checked them."""
    from rsstp_sweep import run_sweep
    from rsstp_sweep.plan import check_starts

    scenario = Path("src/rsstp_sim/scenarios/thesis-roulette.toml").read_text()
    blocked = scenario.replace('name = "thesis-roulette"', 'name = "blocked"')
    blocked += "\n[[obstacles]]\ncenter = [1.0, 0.0]\nradius = 0.2\n"
    (tmp_path / "blocked.toml").write_text(blocked)
    (tmp_path / "sweep.toml").write_text(BASE.replace('"one-joint-10"', '"blocked.toml"'))
    sweep = load_sweep(tmp_path / "sweep.toml")
    line = (
        rf"^{re.escape(str(tmp_path / 'sweep.toml'))}: scenarios: "
        rf"{re.escape(str(tmp_path / 'blocked.toml'))}: arm\.initial_deg: the start pose "
        r"\[\d+\] is invalid \(link 0 meets obstacle 0\)$"
    )
    with pytest.raises(SweepError, match=line):
        check_starts(sweep)
    with pytest.raises(SweepError, match=line):
        run_sweep(sweep, str(tmp_path / "out"))
    assert not (tmp_path / "out").exists()


def test_a_missing_sweep_file_is_named(tmp_path: Path) -> None:
    with pytest.raises(SweepError, match=r"nothere.toml: no such sweep file"):
        load_sweep(tmp_path / "nothere.toml")


def test_the_documented_sweep_file_is_valid(tmp_path: Path) -> None:
    """docs/sweeps.md's example sweep checks, with docs/scenarios.md's scenario file beside it:
    every scenario x strategy (a grid's every value) x seed."""
    docs = Path(__file__).resolve().parents[2] / "docs"
    for page, name in (("sweeps.md", "grid-sweep.toml"), ("scenarios.md", "my-arm.toml")):
        block = re.search(
            f"```toml file={re.escape(name)}\n(.*?)```", (docs / page).read_text(), re.S
        )
        assert block is not None
        (tmp_path / name).write_text(block[1])
    sweep = load_sweep(tmp_path / "grid-sweep.toml")
    assert len(sweep.runs) == 3 * (1 + 1 + 2) * 2
    assert {run.params.get("horizon") for run in sweep.runs if run.strategy == "splitter"} == {
        4,
        16,
    }
