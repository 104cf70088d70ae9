"""The viewer's phase timeline: a strategy's phase notes as a series per phase, read back from
the ``.rrd`` with Rerun's own reader."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar

from test_viewer import Rrd

from rsstp_replay.reader.recording import open_recording
from rsstp_replay.viewer import view
from rsstp_sim import AgentView, StrategyBase, load_scenario
from rsstp_sim.recording import record

SCHEDULE = {1: "explore", 11: "identify", 31: "explore"}


class Phased(StrategyBase):
    name: ClassVar[str] = "phased"

    def choose_action(self, agent: AgentView) -> int:
        return agent.actions[0]

    def refine(self, agent: AgentView) -> None:
        if agent.step in SCHEDULE:
            agent.enter(SCHEDULE[agent.step])


def phase_rows(
    path: Path, start: int | None, end: int | None, out: Path
) -> list[tuple[int, list[float]]]:
    with open_recording(path) as recording:
        view(recording, save=out, spawn=False, serve_web=False, start=start, end=end)
    rrd = Rrd(out)
    names = rrd.static["plots/strategy/phase"][0].to_record_batch()
    assert names.column("SeriesLines:names").to_pylist() == [["explore", "identify"]]
    return rrd.column("plots/strategy/phase", "Scalars:scalars")


def expected(steps: list[int]) -> list[tuple[int, list[float]]]:
    """One-hot rows (explore, identify) at ``steps``, from the schedule walked step by step."""
    rows = []
    for step in steps:
        phase = None
        for at in range(step + 1):
            phase = SCHEDULE.get(at, phase)
        rows.append((step, [float(phase == "explore"), float(phase == "identify")]))
    return rows


def test_the_phase_timeline_has_a_row_at_each_change(tmp_path: Path) -> None:
    path = tmp_path / "phased.mcap"
    record(path, load_scenario("three-joint"), Phased(), steps=40, seed=0)
    assert phase_rows(path, None, None, tmp_path / "all.rrd") == expected([0, 1, 11, 31, 40])
    assert phase_rows(path, 20, 35, tmp_path / "part.rrd") == expected([20, 31, 35])
