"""What the commands print reads right: a noun agrees with its number (``1 state``, ``2
states``, never ``1 states`` or ``step(s)``) and a number of 1,000 or more has its thousands
separators. Every command runs on real recordings, and every line it prints is checked.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import pytest

from rsstp_cli.replay import main as replay_main
from rsstp_cli.sim import main as sim_main
from rsstp_sim import load_scenario, make_strategy
from rsstp_sim.recording import record
from rsstp_sim.words import counted

_NOUNS = (
    "step|state|transition|model version|version|event|entry|entries|entity|entities|pose|"
    "class|classes|run|row|column|line|log line|action|obstacle|joint|message|chunk|byte"
)
_ONE_PLURAL = re.compile(
    rf"(?<![\d.,])\b1 (?:{_NOUNS})s\b|(?<![\d.,])\b1 (?:entries|entities|classes)\b"
)
_MANY_SINGULAR = re.compile(
    r"(?<![\d.,])\b(?:0|[2-9]|\d{2,}) (?:step|state|transition|event|entry)\b(?! \d)"
)
_OPTIONAL_S = re.compile(r"\w\(s\)")
_NO_SEPARATOR = re.compile(r"(?<![\w.,/:\-#'\"])\d{4,}(?![\w.,/:'\"]|\.\d)")
"""A number of four digits or more standing alone (not in a path, a hash, a version, a time)."""


def problems(text: str) -> list[str]:
    """The lines of ``text`` that break the rules above, each with what broke."""
    found = []
    for line in text.splitlines():
        for rule, pattern in (
            ("1 with a plural", _ONE_PLURAL),
            ("a plural number with a singular", _MANY_SINGULAR),
            ("(s)", _OPTIONAL_S),
            ("no thousands separator", _NO_SEPARATOR),
        ):
            match = pattern.search(line)
            if match is not None:
                found.append(f"{rule}: {match.group()!r} in {line!r}")
    return found


def test_the_check_finds_what_it_looks_for() -> None:
    assert problems("model: 1 states, 2 transitions") != []
    assert problems("kept 20000 steps") != []
    assert problems("no contradiction in 3 step(s)") != []
    assert problems("sub-memories of 1 entries") != []
    assert problems("a 2 state model") != []
    good = "steps 0..20,000: 1 state, 1,000 steps, version 0.1.0, run.mcap, 0.25 s, sha 1234abcd"
    assert problems(good) == []
    assert problems(f"{counted(1, 'entry', 'entries')}, {counted(12345, 'step')}") == []


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Recordings with one step, with thousands, and with many model versions."""
    found = tmp_path_factory.mktemp("words")
    record(found / "one.mcap", load_scenario("thesis-roulette"), make_strategy("script"),
           steps=1, seed=0)  # fmt: skip
    record(found / "many.mcap", load_scenario("three-joint"), make_strategy("random"),
           steps=12_000, seed=1)  # fmt: skip
    record(found / "roulette.mcap", load_scenario("thesis-roulette"),
           make_strategy("roulette"), steps=30, seed=0)  # fmt: skip
    return found


def _commands(folder: Path) -> list[tuple[Callable[[list[str]], int], list[str]]]:
    out = folder / "out"
    out.mkdir(exist_ok=True)
    commands: list[tuple[Callable[[list[str]], int], list[str]]] = [
        (sim_main, ["scenarios"]),
        (sim_main, ["strategies"]),
        (sim_main, ["run", "thesis-roulette", "--strategy", "script", "--steps", "1"]),
        (sim_main, ["run", "three-joint", "--steps", "12000", "--quiet"]),
        (sim_main, ["graph", "--matrix", "[[[0]]]", "-o", str(out / "m.dot"), "--force"]),
        (
            sim_main,
            [
                "record",
                "thesis-roulette",
                "--steps",
                "1",
                "-o",
                str(out / "r.mcap"),
                "--force",
                "--quiet",
            ],
        ),  # fmt: skip
        (sim_main, ["truth", "thesis-roulette"]),
    ]
    for name in ("one", "many", "roulette"):
        path = str(folder / f"{name}.mcap")
        commands += [
            (replay_main, ["info", path]),
            (replay_main, ["check", path]),
            (replay_main, ["audit", path, "--quiet"]),
            (replay_main, ["audit", path, "--truth", "--quiet"]),
            (replay_main, ["compare", path, "0", "1"]),
            (replay_main, ["table", path, "-o", str(out / "t.csv"), "--force"]),
            (replay_main, ["events", path, "-o", str(out / "e.parquet"), "--force"]),
            (replay_main, ["view", path, "--save", str(out / "v.rrd"), "--force", "--quiet"]),
            (replay_main, ["export", "--foxglove", path, "-o", str(out / "f.mcap"), "--force"]),
            (replay_main, ["graph", path, "--step", "1", "-o", str(out / "g.dot"), "--force"]),
        ]
    return commands


@pytest.mark.slow
def test_every_command_prints_counts_that_read_right(
    folder: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    found = []
    for main, argv in _commands(folder):
        code = main(argv)
        captured = capsys.readouterr()
        assert code == 0, (argv, captured.err)
        found += [f"{' '.join(argv[:2])}: {p}" for p in problems(captured.out + captured.err)]
    assert found == [], "\n".join(found)
