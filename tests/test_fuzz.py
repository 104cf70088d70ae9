"""Fuzzing, a short budget in the default run (``bench/fuzz.py`` runs a long one): any
scenario file is a scenario or one line; any damage to a recording is read as what was
written, or refused in one line (see ``tests/fuzzing.py`` for the properties)."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings

from fuzzing import (
    Deep,
    Mutation,
    OutputFault,
    Rewrite,
    Written,
    check_deep,
    check_output_fault,
    check_recording,
    check_rewrite,
    check_scenario,
    deep_texts,
    output_faults,
    recording_mutations,
    scenario_texts,
    semantic_rewrites,
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


FEW = settings(SHORT, max_examples=20)


@FEW
@given(case=deep_texts())
@example(case=Deep(where="scenario", depth=3000, opener="["))
@example(case=Deep(where="matrix", depth=3000, opener="["))
def test_deep_nesting_is_one_line(case: Deep, tmp_path: Path) -> None:
    assert check_deep(case, tmp_path) is None


@pytest.fixture(scope="module")
def walk(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from rsstp_sim import load_scenario, make_strategy
    from rsstp_sim.recording import record

    path = tmp_path_factory.mktemp("fuzz-walk") / "walk.mcap"
    record(path, load_scenario("three-joint"), make_strategy("random"), steps=400, seed=2,
           chunk_size=8_192)  # fmt: skip
    return path


@FEW
@given(case=semantic_rewrites())
@example(case=Rewrite(where=0.5, field="truth.joint_positions.1.x", value=1e-12, nudge=True))
@example(case=Rewrite(where=0.3, field="agent.action", value=2**63, nudge=False))
# Found by bench/fuzz.py (2026-11-26): 1 for a feedback of 1.0 is the same value, not a change.
@example(case=Rewrite(where=0.08716464942245052, field="agent.feedback", value=1, nudge=False))
def test_a_rewritten_truth_never_passes_the_physics_check(
    case: Rewrite, walk: Path, tmp_path: Path
) -> None:
    assert check_rewrite(case, walk, 400, tmp_path) is None


@FEW
@given(case=output_faults())
@example(case=OutputFault(command="view", read_only=False, limit=8_192))
@example(case=OutputFault(command="table.parquet", read_only=True, limit=0))
# Found by bench/fuzz.py (2026-11-26): the Foxglove SDK's writer fails as it opens a file that
# takes no bytes, with its own RuntimeError, outside the block that turned it into one line.
@example(case=OutputFault(command="export", read_only=False, limit=249))
def test_an_output_that_cannot_be_written_is_one_line(
    case: OutputFault, walk: Path, tmp_path: Path
) -> None:
    assert check_output_fault(case, walk, tmp_path) is None
