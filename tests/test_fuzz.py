"""Fuzzing, a short budget in the default run (``bench/fuzz.py`` runs a long one): any
scenario file is a scenario or one line; any damage to a recording is read as what was
written, or refused in one line (see ``tests/fuzzing.py`` for the properties)."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings

from fuzzing import (
    Mutation,
    Written,
    check_recording,
    check_scenario,
    recording_mutations,
    scenario_texts,
    splitter_run,
)

SHORT = settings(
    max_examples=80,
    deadline=None,
    database=None,
    derandomize=True,  # the same cases in every CI run; bench/fuzz.py explores
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


@SHORT
@given(text=scenario_texts())
def test_any_scenario_file_is_a_scenario_or_one_line(text: str, tmp_path: Path) -> None:
    assert check_scenario(text, tmp_path) is None


@pytest.fixture(scope="module")
def reference(tmp_path_factory: pytest.TempPathFactory) -> Written:
    return splitter_run(tmp_path_factory.mktemp("fuzz"))


# Found by bench/fuzz.py (2026-11-25): an attachment record whose data length no read() can
# take (OverflowError) ended in a traceback.
_HUGE_ATTACHMENT = [
    Mutation(kind="truncate", where=0.3127605217994334, size=414, data=b"d\x83\xc4y"),
    Mutation(kind="overwrite", where=0.6314287784805704, size=190, data=b"["),
    Mutation(kind="flip", where=0.02339802904654054, size=4095, data=b"5\xc1"),
]


@SHORT
@given(mutations=recording_mutations())
@example(mutations=_HUGE_ATTACHMENT)
def test_damage_to_a_recording_never_returns_what_was_not_written(
    mutations: list[Mutation], reference: Written, tmp_path: Path
) -> None:
    assert check_recording(mutations, reference, tmp_path) is None
