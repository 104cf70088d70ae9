"""The rover body: its scenario files, its moves against shapely, its truth, its runs."""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys
from importlib import resources
from pathlib import Path

import gymnasium
import numpy as np
import pandas as pd
import pytest
import shapely

from builtin_worlds import builtins_of
from rsstp_format.schemas import SCHEMA_VERSION, STEP_NS
from rsstp_replay import errors, open_recording
from rsstp_sim import Runner, make_strategy, palette
from rsstp_sim.bodies import body_of, make_world
from rsstp_sim.errors import ActionError, ScenarioError
from rsstp_sim.recording.env_wrapper import RecordMcap
from rsstp_sim.recording.recorder import record
from rsstp_sim.rover import RoverScenario, RoverWorld
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.truth import compute_truth
from waiting import HANG_S

sys.path.insert(0, str(Path(__file__).parents[1] / "replay"))
from test_corrupt import rewrite  # noqa: E402

SRC = Path(__file__).resolve().parents[2] / "src"

ROOM = """
[rover]
room = [6, 4]
start = [0, 0]
"""


def _random_rover(rng: random.Random) -> str:
    """A small room with random walls, doors and obstacles, and the start cell kept clear."""
    width, height = rng.randint(3, 7), rng.randint(3, 6)
    turn = rng.choice([45, 90])
    lines = [
        "[rover]",
        f"room = [{width}, {height}]",
        "start = [0, 0]",
        f"turn_deg = {turn}",
        f"heading_deg = {turn * rng.randrange(360 // turn)}",
        f"radius = {rng.uniform(0.0, 0.45)!r}",
    ]
    for _ in range(rng.randint(0, 3)):
        x, y = rng.uniform(1.2, width), rng.uniform(1.2, height)
        lines += [
            "[[obstacles]]",
            f"center = [{x!r}, {y!r}]",
            f"radius = {rng.uniform(0.05, 0.9)!r}",
        ]
    for kind in ("walls", "doors"):
        for _ in range(rng.randint(0, 2)):
            a = [rng.uniform(1.1, width), rng.uniform(1.1, height)]
            b = [rng.uniform(1.1, width), rng.uniform(1.1, height)]
            lines += [f"[[{kind}]]", f"from = {a!r}", f"to = {b!r}"]
            if kind == "doors":
                lines.append(f"toward = [{rng.uniform(-1, 1)!r}, {rng.uniform(-1, 1)!r}]")
    fx, fy = rng.randrange(width) + 0.5, rng.randrange(height) + 0.5
    lines += ["[feedback]", f"center = [{fx!r}, {fy!r}]"]
    return "\n".join(lines) + "\n"


def _reference_move(s: RoverScenario, x: int, y: int, heading: int, action: int):
    """Where ``action`` takes the robot, and what blocks it, by shapely: written from the
    module's docstring, one pose and one move at a time."""
    if action in (2, 3):
        return (x, y, (heading + (1 if action == 2 else -1)) % s.headings), None
    angle = math.radians(heading * s.turn_deg)
    dx, dy = round(math.cos(angle)), round(math.sin(angle))
    if action == 1:
        dx, dy = -dx, -dy
    tx, ty = x + dx, y + dy
    for edge, out in ((0, tx >= s.room[0]), (2, tx < 0), (1, ty >= s.room[1]), (3, ty < 0)):
        if out:
            return (x, y, heading), ("room", edge)
    path = shapely.LineString([(x + 0.5, y + 0.5), (tx + 0.5, ty + 0.5)])
    for j, obstacle in enumerate(s.obstacles):
        if path.distance(shapely.Point(obstacle.center)) <= obstacle.radius + s.robot_radius:
            return (x, y, heading), ("obstacle", 0, j)
    for w, wall in enumerate(s.walls):
        if path.distance(shapely.LineString([wall.start, wall.end])) <= s.robot_radius:
            return (x, y, heading), ("wall", w)
    for d, door in enumerate(s.doors):
        along = dx * door.toward[0] + dy * door.toward[1] > 0
        if (
            not along
            and path.distance(shapely.LineString([door.start, door.end])) <= s.robot_radius
        ):
            return (x, y, heading), ("door", d)
    return (tx, ty, heading), None


@pytest.mark.parametrize("seed", range(12))
def test_every_move_of_random_rooms_agrees_with_shapely(seed: int) -> None:
    rng = random.Random(seed)
    while True:
        try:
            scenario = parse_scenario(_random_rover(rng))
            break
        except ScenarioError:  # the start cell drawn under something: draw again
            continue
    assert isinstance(scenario, RoverScenario)
    world = RoverWorld(scenario)
    width, height = scenario.room
    checked = 0
    for code in range(width * height * scenario.headings):
        x, y, heading = code % width, code // width % height, code // (width * height)
        for k, action in enumerate(scenario.actions):
            (tx, ty, th), blocker = _reference_move(scenario, x, y, heading, action)
            got = int(world.table.next_code[code, k])
            assert got == tx + width * (ty + height * th), (code, action)
            found = world.blocker_of(int(world.table.blocker[code, k]))
            if blocker is None:
                assert found is None, (code, action, found)
            else:
                assert found is not None
                assert (found.kind, found.indices) == (blocker[0], tuple(blocker[1:]))
            checked += 1
    assert checked == width * height * scenario.headings * len(scenario.actions)


def test_a_step_moves_turns_and_is_blocked_as_the_room_says() -> None:
    world = make_world(parse_scenario(ROOM))
    assert world.current.cell == (0, 0) and world.current.heading_deg == 0
    assert world.move(0) is None and world.current.cell == (1, 0)
    assert world.move(3) is None and world.current.heading_deg == 270  # turned right: south
    blocker = world.move(0)
    assert blocker is not None and blocker.kind == "room" and world.current.cell == (1, 0)
    assert blocker.describe() == "the robot would leave the room by its south edge"
    assert world.move(1) is None and world.current.cell == (1, 1)  # back: north
    with pytest.raises(
        ActionError, match=r"action 4 is not one of the scenario's actions: 0 \(forward\)"
    ):
        world.move(4)
    world.reset()
    assert world.current.cell == (0, 0) and world.sensation  # feedback defaults to the start cell


def test_the_one_way_door_lets_the_robot_through_and_never_back() -> None:
    scenario = load_scenario("rover-one-way")
    truth = compute_truth(scenario)
    names = truth.value_names
    assert names == ("cell_x", "cell_y", "heading_deg")
    beyond = truth.pose_values[:, 0] >= 16  # the second room, past the door at x = 16
    assert beyond.any() and (~beyond).any()
    # Every pose of the second room is reached from the start; none leads back.
    after = truth.class_of([20, 8, 0])
    reached = truth.classes_reached_from(after)
    assert not reached[truth.true_class[~beyond]].any()
    assert reached[truth.true_class[beyond]].all()
    # And the door is crossed only eastward: the same move west is blocked by it.
    world = RoverWorld(scenario)
    x, y, heading = 16, 7, 180  # just past the door, facing west
    code = x + 33 * (y + 16 * (heading // 90))
    k = scenario.actions.index(0)
    blocker = world.blocker_of(int(world.table.blocker[code, k]))
    assert blocker is not None and blocker.kind == "door"


@pytest.mark.parametrize("name", builtins_of("rover"))
def test_the_built_in_rover_worlds_have_thousands_of_classes(name: str) -> None:
    truth = compute_truth(load_scenario(name))
    assert truth.n_classes >= 2_000
    assert truth.n_sensed == 1  # one sensed pose: the learner's landmark (docs/scenarios.md)
    assert body_of(load_scenario(name)).warnings(load_scenario(name)) == []


def test_a_random_walk_runs_and_its_sensations_are_the_regions() -> None:
    scenario = load_scenario("rover-room")
    runner = Runner(scenario, make_strategy("random"), seed=3)
    summary = runner.run(20_000)
    assert summary.steps == 20_000
    world = RoverWorld(scenario)
    cx, cy = scenario.feedback_center
    for code in np.flatnonzero(world.table.sensation)[:10].tolist():
        pose = world.pose(code)
        px, py = pose.position
        assert math.hypot(px - cx, py - cy) <= scenario.feedback_radius


_SMALL = "[rover]\nroom = [3, 3]\nstart = [0, 0]\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "[rover]\nroom = [9223372036854775807, 3]\nstart = [0, 0]\n",
            r"rover\.room\[0\]: expected an integer in 1\.\.1000, found 9223372036854775807$",
        ),
        (
            _SMALL + "[[walls]]\nfrom = [1e308, 0]\nto = [0, 1]\n",
            r"walls\[0\]\.from\[0\]: expected a number in \[-1e\+06, 1e\+06\], found 1e\+308$",
        ),
        (_SMALL + "radius = 1e308\n", r"rover\.radius: expected a number in \[0, 0\.4999\]"),
        (
            "[rover]\nroom = [0, 3]\nstart = [0, 0]\n",
            r"rover\.room\[0\]: expected an integer in 1\.\.1000, found 0$",
        ),
        (
            "[rover]\nroom = [3, 3]\nstart = [3, 0]\n",
            r"rover\.start\[0\]: expected an integer in 0\.\.2, found 3$",
        ),
        (
            _SMALL + "turn_deg = 30\n",
            r"rover\.turn_deg: expected 45 or 90, found 30$",
        ),
        (_SMALL + "wheels = 4\n", r"rover\.wheels: unknown key"),
        (
            _SMALL + "[[obstacles]]\ncenter = [0.5, 0.5]\nradius = 0.2\n",
            r"rover\.start: the robot at cell \[0, 0\] touches a wall, a door or an obstacle$",
        ),
        (
            _SMALL + "[[doors]]\nfrom = [1, 0]\nto = [1, 3]\ntoward = [0, 0]\n",
            r"doors\[0\]\.toward: expected a direction other than \[0, 0\]",
        ),
        (
            _SMALL + "[arm]\nlengths = [1.0]\n",
            r"expected one body table, \[arm\] or \[rover\]; found \[arm\] and \[rover\]$",
        ),
    ],
)
def test_a_bad_rover_file_is_one_line_naming_the_key(text: str, message: str) -> None:
    with pytest.raises(ScenarioError, match=r"^bad\.toml: " + message):
        parse_scenario(text, origin="bad.toml")


def test_a_rover_that_cannot_stand_at_its_start_is_refused_where_its_world_is_built() -> None:
    text = _SMALL + "[[obstacles]]\ncenter = [0.5, 0.5]\nradius = 0.2\n"
    scenario = parse_scenario(text, origin="bad.toml", check_start=False)  # only parsed
    message = r"^bad\.toml: rover\.start: the robot at cell \[0, 0\] touches a wall, a door"
    for build in (make_world, body_of(scenario).check_start, compute_truth):
        with pytest.raises(ScenarioError, match=message):
            build(scenario)


def _sim(*args: str) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    return subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=HANG_S,
        check=False,
    )


def test_run_and_truth_take_a_rover_scenario(tmp_path: Path) -> None:
    truth = compute_truth(load_scenario("rover-two-rooms"))
    done = _sim("truth", "rover-two-rooms")
    assert done.returncode == 0, done.stderr
    assert f"minimal model: {truth.n_classes:,} states" in done.stdout
    done = _sim("run", "rover-room", "--strategy", "random", "--steps", "5000", "--quiet")
    assert done.returncode == 0, done.stderr
    runner = Runner(load_scenario("rover-room"), make_strategy("random"), seed=0)
    assert runner.run(5000).to_text() in done.stdout


def test_gymnasium_makes_the_rover_and_its_frames_show_it(tmp_path: Path) -> None:
    env = gymnasium.make("rsstp/Rover-v0", scenario="rover-one-way", render_mode="rgb_array")
    observation, info = env.reset(seed=0)
    scenario = load_scenario("rover-one-way")
    assert isinstance(scenario, RoverScenario)
    assert info["cell"] == scenario.start and info["heading_deg"] == 0 and observation == 0
    frame = env.render()
    assert frame.shape == (400, 400, 3) and frame.dtype == np.uint8
    robot = (np.abs(frame.astype(int) - palette.ARM).sum(axis=2) == 0).sum()
    assert robot > 20  # the robot is drawn
    _, _, _, _, info = env.step(0)
    assert info["cell"] == (scenario.start[0] + 1, scenario.start[1]) and not info["blocked"]
    walk = [3, 0, 0, 0, 0, 0, 0, 0, 0, 0]  # right (south), then forward into the south edge
    for action in walk:
        _, _, _, _, info = env.step(action)
    assert (
        info["blocked"] and info["blocked_by"] == "the robot would leave the room by its south edge"
    )
    env.close()


def test_a_gymnasium_rover_run_is_recorded_as_the_runner_records_it(tmp_path: Path) -> None:
    env = RecordMcap(gymnasium.make("rsstp/Rover-v0", scenario="rover-two-rooms"), tmp_path)
    env.reset(seed=0)
    rng = np.random.default_rng(7)
    actions = rng.integers(0, 4, size=300).tolist()
    for action in actions:
        env.step(action)
    env.close()
    [path] = env.recordings
    with open_recording(path) as recording:
        steps = recording.steps()
    assert steps["action"].iloc[1:].tolist() == actions
    walked = _walk(load_scenario("rover-two-rooms"), actions)  # type: ignore[arg-type]
    assert steps[["cell_x", "cell_y", "heading_deg"]].to_numpy().tolist() == [
        list(w[:3]) for w in walked
    ]


# -- a rover's recording ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def rover_recording(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("rover") / "walk.mcap"
    record(path, load_scenario("rover-two-rooms"), make_strategy("random"), steps=4000, seed=5)
    return path


def _walk(scenario: RoverScenario, actions: list[int]) -> list[tuple[int, int, int, str | None]]:
    """Cell, heading and blocker kind after each action, by :func:`_reference_move` (shapely),
    from the start: step 0 first."""
    x, y = scenario.start
    heading = scenario.start_heading
    out: list[tuple[int, int, int, str | None]] = [(x, y, heading * scenario.turn_deg, None)]
    for action in actions:
        (x, y, heading), blocker = _reference_move(scenario, x, y, heading, action)
        out.append((x, y, heading * scenario.turn_deg, None if blocker is None else blocker[0]))
    return out


def test_a_rover_recording_reads_back_as_the_world_walked_it(rover_recording: Path) -> None:
    scenario = load_scenario("rover-two-rooms")
    assert isinstance(scenario, RoverScenario)
    with open_recording(rover_recording) as recording:
        assert recording.scenario == scenario
        assert recording.schema_versions["rsstp.RoverStep"] == SCHEMA_VERSION
        steps = recording.steps()
        events = recording.events()
    actions = steps["action"].iloc[1:].astype(int).tolist()
    walked = _walk(scenario, actions)
    assert steps[["cell_x", "cell_y", "heading_deg"]].to_numpy().tolist() == [
        list(w[:3]) for w in walked
    ]
    kinds = [None if pd.isna(k) else k for k in steps["blocked_kind"]]
    assert kinds == [w[3] for w in walked]
    assert (steps["x"] == steps["cell_x"] + 0.5).all() and (
        steps["y"] == steps["cell_y"] + 0.5
    ).all()
    assert set(kinds) >= {None, "room"}
    blocked = events.loc[events["kind"] == "blocked", "step"].tolist()
    assert blocked == [t for t, w in enumerate(walked) if w[3] is not None]


def test_the_commands_audit_table_and_check_a_rover_recording(
    rover_recording: Path, tmp_path: Path
) -> None:
    from rsstp_cli.replay import main

    assert main(["check", str(rover_recording), "--physics"]) == 0
    assert main(["audit", "--truth", "--json", str(rover_recording)]) == 0
    table = tmp_path / "steps.parquet"
    assert main(["table", str(rover_recording), "--truth", "-o", str(table)]) == 0
    frame = pd.read_parquet(table)
    truth = compute_truth(load_scenario("rover-two-rooms"))
    expected = truth.classes_of(frame[["cell_x", "cell_y", "heading_deg"]].to_numpy())
    assert frame["true_class"].tolist() == expected.tolist()


def test_a_rover_step_moved_by_hand_is_named_by_the_physics_check(
    rover_recording: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from rsstp_cli.replay import main

    def moved(topic: str, log_time: int, data: bytes) -> bytes:
        if topic == "/rsstp/step" and log_time == 700 * STEP_NS:
            value = json.loads(data)
            value["truth"]["heading_deg"] = (value["truth"]["heading_deg"] + 90) % 360
            return json.dumps(value, separators=(",", ":")).encode()
        return data

    bad = rewrite(rover_recording, tmp_path / "moved.mcap", message=moved)
    capsys.readouterr()
    assert main(["check", str(bad), "--physics"]) == 1
    out = capsys.readouterr().out
    assert "physics: broken at step 700, truth.heading_deg: recorded" in out


def test_a_rover_scenario_under_an_arm_message_is_refused_in_one_line(
    rover_recording: Path, tmp_path: Path
) -> None:
    arm = (resources.files("rsstp_sim.scenarios") / "two-joint-30.toml").read_bytes()
    bad = rewrite(rover_recording, tmp_path / "swapped.mcap", attachment=lambda data: arm)
    with pytest.raises(errors.CorruptRecording, match=r"hashes to"):
        open_recording(bad)


@pytest.mark.slow
def test_a_sweep_runs_rover_worlds_and_each_recording_is_the_one_record_writes(
    tmp_path: Path,
) -> None:
    (tmp_path / "rover.toml").write_text(
        'steps = 500\nseeds = 2\nscenarios = ["rover-one-way"]\n[[strategy]]\nname = "random"\n'
    )
    out = tmp_path / "out"
    done = _sim("sweep", str(tmp_path / "rover.toml"), "-o", str(out), "--workers", "2", "--quiet")
    assert done.returncode == 0, done.stderr
    runs = pd.read_parquet(out / "runs.parquet")
    assert list(runs["status"]) == ["done", "done"]
    assert (runs["minimal_states"] == compute_truth(load_scenario("rover-one-way")).n_classes).all()
    for row in runs.itertuples():
        alone = tmp_path / f"{row.run}.mcap"
        record(
            alone, load_scenario("rover-one-way"), make_strategy("random"), steps=500, seed=row.seed
        )
        assert alone.read_bytes() == (out / row.recording).read_bytes()
