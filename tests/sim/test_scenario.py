"""Scenario files: built-ins, loading by path or name, and every validation error."""

from __future__ import annotations

import hashlib
import re
import subprocess
import sys
from collections.abc import Callable
from importlib import resources
from pathlib import Path

import pytest

from builtin_worlds import builtins_of
from rsstp_sim import scenario as scenario_module
from rsstp_sim.arm import geometry
from rsstp_sim.arm.world import World
from rsstp_sim.bodies import body_of, make_world
from rsstp_sim.errors import ScenarioError
from rsstp_sim.scenario import Obstacle, builtin_scenarios, load_scenario, parse_scenario
from waiting import HANG_S

BUILTINS = tuple(builtin_scenarios())
THESIS_BUILTINS = (
    "one-joint-10",
    "thesis-algo",
    "thesis-obstacles",
    "thesis-roulette",
    "three-joint",
)

Mutation = Callable[[dict], None]


def _set(path: str, value: object) -> Mutation:
    """A mutation setting ``data[a][b]...`` (``obstacles.0.radius`` style path)."""

    def mutate(data: dict) -> None:
        *parents, last = path.split(".")
        target: dict | list = data
        for key in parents:
            target = target[int(key)] if isinstance(target, list) else target[key]
        target[int(last) if isinstance(target, list) else last] = value  # type: ignore[index]

    return mutate


def _delete(path: str) -> Mutation:
    def mutate(data: dict) -> None:
        *parents, last = path.split(".")
        target = data
        for key in parents:
            target = target[int(key)] if isinstance(target, list) else target[key]
        del target[last]

    return mutate


# -- built-ins --------------------------------------------------------------------------------


def test_builtin_names_and_descriptions() -> None:
    names = builtin_scenarios()
    assert set(THESIS_BUILTINS) <= set(names)
    assert list(names) == sorted(names)
    assert all(description for description in names.values())


@pytest.mark.parametrize("name", builtins_of("arm"))
def test_every_builtin_loads_and_its_start_pose_is_valid(name: str) -> None:
    scenario = load_scenario(name)
    text = resources.files("rsstp_sim.scenarios").joinpath(f"{name}.toml").read_text("utf-8")
    assert scenario.name == name
    assert scenario.origin == name
    assert scenario.description == builtin_scenarios()[name]
    assert scenario.source == text
    assert scenario.sha256 == hashlib.sha256(text.encode("utf-8")).hexdigest()
    assert geometry.pose_blocker(scenario, scenario.initial_deg) is None
    assert World(scenario).angles_deg == scenario.initial_deg


def test_three_joint_builtin_contents() -> None:
    scenario = load_scenario("three-joint")
    assert scenario.lengths == (3.0, 2.0, 1.0)
    assert scenario.initial_deg == (330, 3, 357)
    assert scenario.step_deg == 5
    assert scenario.actions == (0, 1, 2, 3, 4, 5)
    assert scenario.obstacles == (Obstacle((1.5, 1.0), 0.5), Obstacle((1.5, -1.5), 0.5))
    assert scenario.feedback_target_deg == (330, 3, 357)
    assert scenario.feedback_mode == "bool"
    assert scenario.collision == "swept"
    assert scenario.n_joints == 3
    assert scenario.total_length == 6.0


def test_roulette_builtin_has_one_action() -> None:
    assert load_scenario("thesis-roulette").actions == (0,)


# -- loading ----------------------------------------------------------------------------------


def test_load_by_path_str_and_path(write_scenario, scenario_text, scenario_data) -> None:
    text = scenario_text(scenario_data)
    path = write_scenario(text)
    for name_or_path in (path, str(path)):
        scenario = load_scenario(name_or_path)
        assert scenario.origin == str(path)
        assert scenario.name == "two-links"
        assert scenario.source == text


def test_name_defaults_to_file_stem(write_scenario, scenario_text, scenario_data) -> None:
    del scenario_data["name"], scenario_data["description"]
    scenario = load_scenario(write_scenario(scenario_text(scenario_data), "my-arm.toml"))
    assert scenario.name == "my-arm"
    assert scenario.description == ""


def test_unknown_name_lists_the_builtins() -> None:
    known = re.escape(", ".join(BUILTINS))
    with pytest.raises(
        ScenarioError,
        match=rf"^no-such-arm: no such scenario file, and not a built-in scenario \({known}\)$",
    ):
        load_scenario("no-such-arm")


def test_unreadable_file_names_the_file(tmp_path: Path) -> None:
    path = tmp_path / "latin1.toml"
    path.write_bytes(b'name = "caf\xe9"\n')
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(path))}: cannot read scenario file"):
        load_scenario(path)


def test_sha256_is_of_the_file_text(write_scenario, scenario_text, scenario_data) -> None:
    text = scenario_text(scenario_data)
    first = load_scenario(write_scenario(text, "a.toml"))
    assert first.sha256 == hashlib.sha256(text.encode("utf-8")).hexdigest()
    # A comment changes nothing in the scenario but does change the file, hence the hash.
    second = load_scenario(write_scenario("# a comment\n" + text, "b.toml"))
    assert second.lengths == first.lengths and second.obstacles == first.obstacles
    assert second.sha256 != first.sha256


def test_defaults(scenario_text) -> None:
    scenario = parse_scenario(
        scenario_text({"arm": {"lengths": [1.5, 1], "initial_deg": [10, 20], "step_deg": 3}})
    )
    assert scenario.lengths == (1.5, 1.0)
    assert all(isinstance(v, float) for v in scenario.lengths)
    assert scenario.actions == (0, 1, 2, 3)
    assert scenario.obstacles == ()
    assert scenario.feedback_mode == "bool"
    assert scenario.tolerance == 1e-6
    assert scenario.collision == "swept"
    assert scenario.origin == "<string>"
    assert scenario.name == "<string>"
    # Feedback defaults to the start pose.
    assert scenario.feedback_target_deg == (10, 20)
    tips = geometry.joint_positions([10, 20], [1.5, 1.0])[1:]
    assert scenario.feedback_points == tuple(map(tuple, tips.tolist()))


def test_initial_and_target_angles_are_taken_modulo_360(scenario_text, scenario_data) -> None:
    scenario_data["arm"]["initial_deg"] = [-10, 450]
    scenario_data["feedback"]["target_deg"] = [720, -270]
    scenario = parse_scenario(scenario_text(scenario_data))
    assert scenario.initial_deg == (350, 90)
    assert scenario.feedback_target_deg == (0, 90)
    assert (
        scenario.feedback_points
        == parse_scenario(
            scenario_text({**scenario_data, "feedback": {"target_deg": [0, 90]}})
        ).feedback_points
    )


def test_actions_subset_is_sorted(scenario_text, scenario_data) -> None:
    scenario_data["arm"]["actions"] = [3, 0]
    assert parse_scenario(scenario_text(scenario_data)).actions == (0, 3)


def test_feedback_points_instead_of_target(scenario_text, scenario_data) -> None:
    scenario_data["feedback"] = {"points": [[1, 2], [3.5, -4]], "mode": "float", "tolerance": 0}
    scenario = parse_scenario(scenario_text(scenario_data))
    assert scenario.feedback_points == ((1.0, 2.0), (3.5, -4.0))
    assert scenario.feedback_target_deg is None
    assert scenario.feedback_mode == "float"
    assert scenario.tolerance == 0.0


def test_endpoint_collision_mode(scenario_text, scenario_data) -> None:
    scenario_data["motion"]["collision"] = "endpoint"
    assert parse_scenario(scenario_text(scenario_data)).collision == "endpoint"


def test_seven_links_are_allowed(scenario_text) -> None:
    text = scenario_text({"arm": {"lengths": [1.0] * 7, "initial_deg": [10] * 7, "step_deg": 1}})
    assert parse_scenario(text).n_joints == 7


def test_base_joint_may_start_at_180(scenario_text) -> None:
    text = scenario_text({"arm": {"lengths": [1.0, 1.0], "initial_deg": [180, 90], "step_deg": 1}})
    assert parse_scenario(text).initial_deg == (180, 90)


# -- errors -----------------------------------------------------------------------------------

LENGTH = r"found .?{} items?.?$"  # the count of items found; the quoting is not the point

INVALID: list[tuple[str, Mutation, str]] = [
    # missing keys
    ("no-arm", _delete("arm"), r"expected one body table, \[arm\] or \[rover\]; found none$"),
    ("no-lengths", _delete("arm.lengths"), r"arm\.lengths: expected an array, missing$"),
    ("no-initial", _delete("arm.initial_deg"), r"arm\.initial_deg: expected an array, missing$"),
    ("no-step", _delete("arm.step_deg"), r"arm\.step_deg: expected an integer, missing$"),
    (
        "no-center",
        _delete("obstacles.0.center"),
        r"obstacles\[0\]\.center: expected an array, missing$",
    ),
    (
        "no-radius",
        _delete("obstacles.0.radius"),
        r"obstacles\[0\]\.radius: expected a number, missing$",
    ),
    # wrong types
    ("arm-not-table", _set("arm", 3), r"\[arm\]: expected a table, found 3$"),
    ("feedback-not-table", _set("feedback", "x"), r"\[feedback\]: expected a table, found 'x'$"),
    ("motion-not-table", _set("motion", [1]), r"\[motion\]: expected a table, found \[1\]$"),
    (
        "lengths-not-array",
        _set("arm.lengths", 2.0),
        r"arm\.lengths: expected an array, found 2\.0$",
    ),
    (
        "length-string",
        _set("arm.lengths", [2.0, "1"]),
        r"arm\.lengths\[1\]: expected a number, found '1'$",
    ),
    (
        "length-bool",
        _set("arm.lengths", [True, 1.0]),
        r"arm\.lengths\[0\]: expected a number, found True$",
    ),
    (
        "initial-float",
        _set("arm.initial_deg", [0, 90.0]),
        r"arm\.initial_deg\[1\]: expected an integer, found 90\.0$",
    ),
    (
        "initial-bool",
        _set("arm.initial_deg", [True, 90]),
        r"arm\.initial_deg\[0\]: expected an integer, found True$",
    ),
    ("step-bool", _set("arm.step_deg", True), r"arm\.step_deg: expected an integer, found True$"),
    ("step-float", _set("arm.step_deg", 5.0), r"arm\.step_deg: expected an integer, found 5\.0$"),
    (
        "action-bool",
        _set("arm.actions", [0, True]),
        r"arm\.actions\[1\]: expected an integer, found True$",
    ),
    (
        "target-bool",
        _set("feedback.target_deg", [0, False]),
        r"feedback\.target_deg\[1\]: expected an integer, found False$",
    ),
    (
        "obstacles-not-array",
        _set("obstacles", 3),
        r"obstacles: expected an array of tables \[\[obstacles\]\], found 3$",
    ),
    (
        "obstacle-not-table",
        _set("obstacles", [1]),
        r"obstacles\[0\]: expected a table with center and radius, found 1$",
    ),
    (
        "center-string",
        _set("obstacles.0.center", [1.0, "y"]),
        r"obstacles\[0\]\.center\[1\]: expected a number, found 'y'$",
    ),
    (
        "radius-string",
        _set("obstacles.0.radius", "big"),
        r"obstacles\[0\]\.radius: expected a number, found 'big'$",
    ),
    (
        "tolerance-bool",
        _set("feedback.tolerance", True),
        r"feedback\.tolerance: expected a number, found True$",
    ),
    ("name-int", _set("name", 3), r"name: expected a string, found 3$"),
    ("description-list", _set("description", ["x"]), r"description: expected a string, found"),
    (
        "nan-length",
        _set("arm.lengths", [float("nan"), 1.0]),
        r"arm\.lengths\[0\]: expected a finite number, found nan$",
    ),
    (
        "inf-radius",
        _set("obstacles.0.radius", float("inf")),
        r"obstacles\[0\]\.radius: expected a finite number, found inf$",
    ),
    # wrong lengths
    (
        "lengths-empty",
        _set("arm.lengths", []),
        r"arm\.lengths: expected a non-empty array, found \[\]$",
    ),
    (
        "initial-short",
        _set("arm.initial_deg", [0]),
        r"arm\.initial_deg: expected an array of 2 \(one per joint\), " + LENGTH.format(1),
    ),
    (
        "initial-long",
        _set("arm.initial_deg", [0, 90, 0]),
        r"arm\.initial_deg: expected an array of 2 \(one per joint\), " + LENGTH.format(3),
    ),
    (
        "target-short",
        _set("feedback.target_deg", [0]),
        r"feedback\.target_deg: expected an array of 2 \(one per joint\), " + LENGTH.format(1),
    ),
    (
        "points-long",
        _set("feedback", {"points": [[0, 0], [1, 1], [2, 2]]}),
        r"feedback\.points: expected an array of 2 \(one per joint\), " + LENGTH.format(3),
    ),
    (
        "point-not-pair",
        _set("feedback", {"points": [[0, 0], [1, 1, 1]]}),
        r"feedback\.points\[1\]: expected a point \[x, y\], found \[1, 1, 1\]$",
    ),
    (
        "center-not-pair",
        _set("obstacles.0.center", [1.0]),
        r"obstacles\[0\]\.center: expected a point \[x, y\], found \[1\.0\]$",
    ),
    ("actions-empty", _set("arm.actions", []), r"arm\.actions: expected a non-empty array"),
    (
        "too-many-links",
        lambda data: data.update(
            arm={"lengths": [1.0] * 8, "initial_deg": [10] * 8, "step_deg": 5}, feedback={}
        ),
        r"arm\.lengths: expected at most 7 links, " + LENGTH.format(8),
    ),
    # non-positive sizes
    (
        "length-zero",
        _set("arm.lengths", [2.0, 0]),
        r"arm\.lengths\[1\]: expected a number > 0, found 0$",
    ),
    (
        "length-negative",
        _set("arm.lengths", [-2.0, 1.0]),
        r"arm\.lengths\[0\]: expected a number > 0, found -2\.0$",
    ),
    (
        "radius-zero",
        _set("obstacles.0.radius", 0.0),
        r"obstacles\[0\]\.radius: expected a number > 0, found 0\.0$",
    ),
    (
        "radius-negative",
        _set("obstacles.0.radius", -0.5),
        r"obstacles\[0\]\.radius: expected a number > 0, found -0\.5$",
    ),
    (
        "tolerance-negative",
        _set("feedback.tolerance", -1e-3),
        r"feedback\.tolerance: expected a number >= 0, found -0\.001$",
    ),
    # invalid start poses
    (
        "start-in-obstacle",
        _set("obstacles.0", {"center": [1.0, 0.1], "radius": 0.2}),
        r"arm\.initial_deg: the start pose \[0, 90\] is invalid \(link 0 meets obstacle 0\)$",
    ),
    (
        "start-touching-obstacle",
        _set("obstacles.0", {"center": [2.0, 1.5], "radius": 0.5}),
        r"arm\.initial_deg: the start pose \[0, 90\] is invalid \(link 1 meets obstacle 0\)$",
    ),
    (
        "start-folded",
        _set("arm.initial_deg", [0, 180]),
        r"arm\.initial_deg: the start pose \[0, 180\] is invalid "
        r"\(joint 1 would fold back onto link 0\)$",
    ),
    (
        "start-folded-modulo",
        _set("arm.initial_deg", [0, -180]),
        r"arm\.initial_deg: the start pose \[0, 180\] is invalid \(joint 1 would fold",
    ),
    (
        "start-links-cross",
        lambda data: data.update(
            arm={"lengths": [2.0, 1.0, 2.0], "initial_deg": [0, 120, 120], "step_deg": 5},
            feedback={},
        ),
        r"arm\.initial_deg: the start pose \[0, 120, 120\] is invalid \(links 0 and 2 intersect\)$",
    ),
    # unknown keys
    (
        "unknown-top",
        _set("colour", "red"),
        r"colour: unknown key \(allowed: arm, description, feedback, motion, name, obstacles\)$",
    ),
    (
        "unknown-arm",
        _set("arm.speed", 1),
        r"arm\.speed: unknown key \(allowed: actions, initial_deg, lengths, step_deg\)$",
    ),
    (
        "unknown-obstacle",
        _set("obstacles.0.colour", "red"),
        r"obstacles\[0\]\.colour: unknown key \(allowed: center, radius\)$",
    ),
    (
        "unknown-feedback",
        _set("feedback.target", [0, 90]),
        r"feedback\.target: unknown key \(allowed: mode, points, target_deg, tolerance\)$",
    ),
    (
        "unknown-motion",
        _set("motion.mode", "swept"),
        r"motion\.mode: unknown key \(allowed: collision\)$",
    ),
    # feedback and motion
    (
        "target-and-points",
        _set("feedback.points", [[2, 0], [2, 1]]),
        r"feedback: give either target_deg or points, not both$",
    ),
    (
        "bad-mode",
        _set("feedback.mode", "fuzzy"),
        r'feedback\.mode: expected "bool" or "float", found \'fuzzy\'$',
    ),
    (
        "mode-not-string",
        _set("feedback.mode", 1),
        r'feedback\.mode: expected "bool" or "float", found 1$',
    ),
    (
        "bad-collision",
        _set("motion.collision", "none"),
        r'motion\.collision: expected "swept" or "endpoint", found \'none\'$',
    ),
    # step and actions
    (
        "step-zero",
        _set("arm.step_deg", 0),
        r"arm\.step_deg: expected an integer in 1\.\.359, found 0$",
    ),
    (
        "step-360",
        _set("arm.step_deg", 360),
        r"arm\.step_deg: expected an integer in 1\.\.359, found 360$",
    ),
    (
        "step-negative",
        _set("arm.step_deg", -5),
        r"arm\.step_deg: expected an integer in 1\.\.359, found -5$",
    ),
    (
        "action-too-large",
        _set("arm.actions", [0, 4]),
        r"arm\.actions\[1\]: expected an integer in 0\.\.3, found 4$",
    ),
    (
        "action-negative",
        _set("arm.actions", [-1]),
        r"arm\.actions\[0\]: expected an integer in 0\.\.3, found -1$",
    ),
    (
        "action-duplicated",
        _set("arm.actions", [1, 2, 1]),
        r"arm\.actions: expected distinct actions, found \[1, 2, 1\]$",
    ),
    (
        "too-many-obstacles",
        _set("obstacles", [{"center": [9.0, float(k)], "radius": 0.1} for k in range(1_001)]),
        r"obstacles: expected at most 1,000 \(each step measures every joint's distance to "
        r"each\), found 1,001$",
    ),
]


@pytest.mark.parametrize(
    ("mutate", "message"), [case[1:] for case in INVALID], ids=[case[0] for case in INVALID]
)
def test_invalid_file_names_file_key_and_expectation(
    mutate: Mutation, message: str, scenario_data, scenario_text, write_scenario
) -> None:
    mutate(scenario_data)
    path = write_scenario(scenario_text(scenario_data))
    with pytest.raises(ScenarioError, match=rf"^{re.escape(str(path))}: {message}"):
        load_scenario(path)


START_CASES = [case for case in INVALID if case[0].startswith("start-")]


@pytest.mark.parametrize(
    ("mutate", "message"),
    [case[1:] for case in START_CASES],
    ids=[case[0] for case in START_CASES],
)
def test_a_bad_start_pose_is_refused_where_the_world_is_built(
    mutate: Mutation, message: str, scenario_data, scenario_text, write_scenario
) -> None:
    """Only parsed (a sweep's plan, its workers, the reader), a scenario whose arm cannot
    stand at its start is refused with the same line by its world, its ground truth's table
    and the body's check."""
    from rsstp_sim.truth import compute_truth

    mutate(scenario_data)
    path = write_scenario(scenario_text(scenario_data))
    scenario = load_scenario(path, check_start=False)
    assert parse_scenario(scenario.source, origin=str(path), check_start=False) == scenario
    for build in (make_world, body_of(scenario).check_start, compute_truth):
        with pytest.raises(ScenarioError, match=rf"^{re.escape(str(path))}: {message}"):
            build(scenario)


def test_invalid_cases_start_from_a_valid_scenario(scenario_data, scenario_text) -> None:
    assert parse_scenario(scenario_text(scenario_data)).name == "two-links"


def test_toml_syntax_error_names_the_file(write_scenario) -> None:
    path = write_scenario("[arm\nlengths = [1.0]\n")
    with pytest.raises(
        ScenarioError, match=rf"^{re.escape(str(path))}: TOML syntax error: .*line 1"
    ):
        load_scenario(path)


def test_parse_error_names_the_given_origin(scenario_text, scenario_data) -> None:
    scenario_data["arm"]["step_deg"] = 0
    with pytest.raises(ScenarioError, match=r"^mine\.toml: arm\.step_deg: expected an integer in"):
        parse_scenario(scenario_text(scenario_data), origin="mine.toml")
    with pytest.raises(ScenarioError, match=r"^<string>: arm\.step_deg"):
        parse_scenario(scenario_text(scenario_data))


def test_a_huge_scenario_file_is_refused_before_it_is_parsed(
    write_scenario, scenario_text, scenario_data, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A 10 MB scenario (150,000 obstacles) is refused by its size at once, not parsed."""
    obstacle = "\n[[obstacles]]\ncenter = [50.0, 50.0]\nradius = 0.5\n"
    path = write_scenario(scenario_text(scenario_data) + obstacle * 250_000)
    parsed: list[str] = []
    monkeypatch.setattr(scenario_module, "parse_scenario", lambda text, **_: parsed.append(text))
    with pytest.raises(
        ScenarioError, match=r"bytes is too large for a scenario file \(at most 1,048,576"
    ):
        load_scenario(path)
    assert parsed == []


def test_many_obstacles_run_with_a_one_line_warning(tmp_path: Path) -> None:
    obstacles = "".join(f"[[obstacles]]\ncenter = [9.0, {k}.0]\nradius = 0.1\n" for k in range(150))
    scenario = tmp_path / "crowded.toml"
    scenario.write_text(
        "[arm]\nlengths = [1.0, 1.0]\ninitial_deg = [0, 0]\nstep_deg = 10\n" + obstacles
    )
    done = subprocess.run(
        [sys.executable, "-m", "rsstp_cli.sim", "run", str(scenario), "--steps", "10"],
        capture_output=True, text=True, timeout=HANG_S,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr.startswith("rsstp-sim: warning: 150 obstacles: every step measures")
    assert len(done.stderr.splitlines()) == 1
