"""Fuzz scenario files and recordings with a long budget; report cases tried and failures.

    PYTHONPATH=src:tests python bench/fuzz.py [--scenarios 5000] [--recordings 5000]
        [--deep 1000] [--rewrites 500] [--outputs 500]

The strategies and the properties are the test suite's (``tests/fuzzing.py``); the default
test run tries 80 fixed cases of each, this tries many more, random ones, and does not stop
at the first failure: every case that breaks a property is counted and the first few of each
kind are printed. Exit 1 when any case failed. Here a case over 10 s is a failure (a stall on
the machine this runs on); in the suite that bound is only a hang guard.

The categories: scenario files (any TOML value at any key, integer extremes among them);
damaged recordings (bytes flipped, cut, overwritten...); deep nesting (TOML and JSON inputs of
every command line nested up to 5,000 deep); semantic rewrites (a ground-truth value of a real
recording changed, the file still well-formed: ``check --physics`` must not pass it); output
faults (every command that writes, into a read-only folder or past a file-size limit).

The recordings mutated are real ones of several chunks, model versions and events: a
three-joint splitter run of 300 steps (chunks of 8 KiB) and a two-joint-30 learner run of
400 steps.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import fuzzing  # noqa: E402 (the test suite's folder goes on the path first)
from rsstp_sim import load_scenario, make_strategy  # noqa: E402
from rsstp_sim.recording import record  # noqa: E402

SHOWN = 3
"""Examples printed for each kind of failure."""
STALL = fuzzing.STALL_SECONDS
"""A case over this is a stall here (the suite's bound is only a hang guard)."""


class Tally:
    """Cases tried and failures found by kind (a failure's text up to its first digit)."""

    def __init__(self, name: str, budget: int) -> None:
        self.name = name
        self.budget = budget
        self.cases = 0
        self.failures: Counter[str] = Counter()
        self.examples: dict[str, list[tuple[str, object]]] = {}
        self.began = time.perf_counter()

    def note(self, case: object, failure: str | None) -> None:
        self.cases += 1
        if failure is None:
            return
        kind = failure.split(":")[0][:80]
        self.failures[kind] += 1
        shown = self.examples.setdefault(kind, [])
        if len(shown) < SHOWN:
            shown.append((failure, case))

    def report(self) -> None:
        seconds = time.perf_counter() - self.began
        failed = sum(self.failures.values())
        print(
            f"{self.name}: {self.cases:,} cases in {seconds:.0f} s, "
            f"{failed:,} failed ({len(self.failures)} kinds)"
        )
        for kind, count in self.failures.most_common():
            print(f"  {count:,} x {kind}")
            for failure, case in self.examples[kind]:
                print(f"      {failure[:300]}\n      case: {str(case)[:300]}")


def explore(
    tally: Tally, strategy: st.SearchStrategy[object], check: Callable[[object], str | None]
) -> None:
    """Run ``check`` on ``tally``'s budget of random cases (none for a budget of 0), noting
    each outcome."""
    if tally.budget == 0:
        return

    @settings(
        max_examples=tally.budget,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )
    @given(case=strategy)
    def run(case: object) -> None:
        tally.note(case, check(case))

    run()


def reference_recordings(folder: Path) -> list[fuzzing.Written]:
    two = folder / "two-joint-learner.mcap"
    record(two, load_scenario("two-joint-30"), make_strategy("learner"), steps=400, seed=5)
    return [fuzzing.splitter_run(folder), fuzzing.Written.read(two)]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenarios", type=int, default=5_000, help="scenario cases (0: none)")
    parser.add_argument("--recordings", type=int, default=5_000, help="recording cases (0: none)")
    parser.add_argument("--deep", type=int, default=1_000, help="deep nesting cases (0: none)")
    parser.add_argument("--rewrites", type=int, default=500, help="semantic rewrites (0: none)")
    parser.add_argument("--outputs", type=int, default=500, help="output faults (0: none)")
    args = parser.parse_args()
    budgets = (args.scenarios, args.recordings, args.deep, args.rewrites, args.outputs)
    if min(budgets) < 0:
        parser.error("every budget takes a number of cases >= 0")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        scenarios = Tally("scenario files", args.scenarios)
        texts = fuzzing.scenario_texts()
        explore(scenarios, texts, lambda text: fuzzing.check_scenario(text, folder, seconds=STALL))
        scenarios.report()

        recordings = Tally("damaged recordings", args.recordings)
        references = reference_recordings(folder)
        cases = st.tuples(st.sampled_from(range(len(references))), fuzzing.recording_mutations())
        explore(
            recordings,
            cases,
            lambda case: fuzzing.check_recording(
                case[1], references[case[0]], folder, seconds=STALL
            ),
        )
        recordings.report()

        deep = Tally("deep nesting", args.deep)
        explore(deep, fuzzing.deep_texts(), lambda case: fuzzing.check_deep(case, folder))
        deep.report()

        walk = folder / "walk.mcap"
        record(walk, load_scenario("three-joint"), make_strategy("random"), steps=400, seed=2,
               chunk_size=8_192)  # fmt: skip
        rewrites = Tally("semantic rewrites", args.rewrites)
        explore(
            rewrites,
            fuzzing.semantic_rewrites(),
            lambda case: fuzzing.check_rewrite(case, walk, 400, folder, seconds=STALL),
        )
        rewrites.report()

        outputs = Tally("output faults", args.outputs)
        explore(
            outputs,
            fuzzing.output_faults(),
            lambda case: fuzzing.check_output_fault(case, walk, folder),
        )
        outputs.report()
    tallies = (scenarios, recordings, deep, rewrites, outputs)
    print(f"total: {sum(t.cases for t in tallies):,} cases, "
          f"{sum(sum(t.failures.values()) for t in tallies):,} failed")  # fmt: skip
    return 1 if any(t.failures for t in tallies) else 0


if __name__ == "__main__":
    raise SystemExit(main())
