"""The truth cache: a scenario's truth computed once, read back equal, never trusted damaged."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from rsstp_sim import parse_scenario
from rsstp_sim.truth import compute_truth
from rsstp_sim.truth.cache import cache_info, load_truth, truth_cache_dir, truth_key
from scenarios import arm_toml

WORLD = arm_toml([2.0, 1.0], [0, 0], 30, [((0.0, 2.5), 0.5)], name="cached")


@pytest.fixture
def cache_home(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    return tmp_path / "xdg" / "rsstp" / "truth"


def entries(folder: Path) -> list[Path]:
    return sorted(folder.glob("*.npz")) if folder.is_dir() else []


def test_a_truth_is_kept_once_and_read_back_equal(cache_home: Path) -> None:
    scenario = parse_scenario(WORLD)
    assert truth_cache_dir() == cache_home
    first = load_truth(scenario)
    (entry,) = entries(cache_home)
    assert entry.name == f"{truth_key(scenario)}.npz"
    stamp = entry.stat().st_mtime_ns
    again = load_truth(scenario)
    assert again == compute_truth(scenario) == first
    assert entry.stat().st_mtime_ns == stamp  # read, not written again
    assert not [p for p in cache_home.iterdir() if p.suffix != ".npz"]  # no side file left


def test_the_key_is_the_world_not_its_name_or_comments(cache_home: Path) -> None:
    renamed = parse_scenario(WORLD.replace('name = "cached"', 'name = "other"') + "# note\n")
    moved = parse_scenario(WORLD.replace("radius = 0.5", "radius = 0.25"))
    assert truth_key(renamed) == truth_key(parse_scenario(WORLD))
    assert truth_key(moved) != truth_key(parse_scenario(WORLD))
    load_truth(parse_scenario(WORLD))
    truth = load_truth(renamed)
    assert truth.scenario_name == "other"
    assert len(entries(cache_home)) == 1


@pytest.mark.parametrize("damage", ["truncate", "flip", "foreign", "other-key", "not-a-zip"])
def test_a_damaged_or_foreign_entry_is_computed_again(cache_home: Path, damage: str) -> None:
    scenario = parse_scenario(WORLD)
    expected = compute_truth(scenario)
    load_truth(scenario)
    (entry,) = entries(cache_home)
    data = entry.read_bytes()
    if damage == "truncate":
        entry.write_bytes(data[: len(data) // 2])
    elif damage == "flip":
        with zipfile.ZipFile(entry) as archive:
            arrays = {name: archive.read(name) for name in archive.namelist()}
        target = arrays["class_next.npy"]
        arrays["class_next.npy"] = target[:-1] + bytes([target[-1] ^ 1])
        with zipfile.ZipFile(entry, "w") as archive:
            for name, content in arrays.items():
                archive.writestr(name, content)
    elif damage == "foreign":
        np.savez(entry, class_next=np.zeros((3, 3)))
    elif damage == "other-key":
        other = parse_scenario(WORLD.replace("radius = 0.5", "radius = 0.25"))
        load_truth(other)
        (entry / ".." / f"{truth_key(other)}.npz").resolve().replace(entry)
    else:
        entry.write_text("not an archive")
    found = load_truth(scenario)
    assert found == expected
    assert load_truth(scenario) == expected  # the entry was replaced by a sound one


def test_no_cache_neither_reads_nor_writes(cache_home: Path) -> None:
    scenario = parse_scenario(WORLD)
    assert load_truth(scenario, cache=False) == compute_truth(scenario)
    assert not entries(cache_home)


def test_an_unwritable_cache_folder_computes_and_keeps_nothing(
    cache_home: Path, unwritable_directory: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(unwritable_directory))
    scenario = parse_scenario(WORLD)
    assert load_truth(scenario) == compute_truth(scenario)
    assert not cache_info().writable


def test_cache_info_on_the_command_line(cache_home: Path, tmp_path: Path) -> None:
    scenario_file = tmp_path / "world.toml"
    scenario_file.write_text(WORLD)
    env = {**os.environ}
    run = [sys.executable, "-m", "rsstp_cli.sim", "truth"]
    subprocess.run([*run, str(scenario_file)], check=True, capture_output=True, env=env)
    done = subprocess.run(
        [*run, "--cache-info", "--json"], check=True, capture_output=True, text=True, env=env
    )
    info = json.loads(done.stdout)
    (entry,) = entries(cache_home)
    assert info == {
        "path": str(cache_home),
        "writable": True,
        "entries": 1,
        "bytes": entry.stat().st_size,
    }
    text = subprocess.run(
        [*run, "--cache-info"], check=True, capture_output=True, text=True, env=env
    ).stdout
    assert text.strip() == f"truth cache: {cache_home}: 1 entry, {entry.stat().st_size:,} bytes"
    subprocess.run(
        [*run, str(scenario_file), "--no-cache"], check=True, capture_output=True, env=env
    )
    assert len(entries(cache_home)) == 1
