"""Time the consistency audit and Memory.append on long random-walk memories.

    PYTHONPATH=src python bench/consistency.py [STEPS ...]   (default: 100000 1000000)

The hidden system is a deterministic ring of 30 positions; three actions move by +1, -1 and +3
positions; the sensation is on at position 0. Memories:

- ``aliased``: internal state = position mod 5 (six positions per state): contradictions exist;
- ``consistent``: internal state = position: no contradiction;
- ``periodic``: one action only, one internal state: the memory repeats itself, so common
  prefixes are as long as the memory (the suffix sorting's worst case: log2(T) doubling rounds).

Targets (2-core machine): 100,000 steps <= 1 s, 1,000,000 steps <= 15 s; append about 1 us.
"""

from __future__ import annotations

import sys
import time
import timeit

import numpy as np
import numpy.typing as npt

from rsstp_replay.audits import find_contradictions
from rsstp_sim.memory import Memory

RING = 30
MOVES = np.array([1, -1, 3])
GOAL = 0
ALIASING = 5


def random_walk(steps: int, *, seed: int) -> tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Actions (``-1`` first) and the hidden positions of a uniform random walk."""
    rng = np.random.default_rng(seed)
    actions = rng.integers(0, len(MOVES), steps + 1)
    actions[0] = -1
    positions = np.cumsum(np.r_[0, MOVES[actions[1:]]]) % RING
    return actions, positions


def record(
    actions: npt.NDArray[np.int64], states: npt.NDArray[np.int64], positions: npt.NDArray[np.int64]
) -> tuple[Memory, float]:
    """Fill a Memory step by step as a simulation would; returns it and seconds per append."""
    sensations = (positions == GOAL).tolist()
    state_list, action_list = states.tolist(), actions.tolist()
    memory = Memory()
    memory.reset(state_list[0], sensations[0], 1.0)
    append = memory.append
    start = time.perf_counter()
    for t in range(1, len(action_list)):
        append(action_list[t], state_list[t], sensations[t], 0.5)
    return memory, (time.perf_counter() - start) / max(len(action_list) - 1, 1)


def time_audit(actions: npt.ArrayLike, states: npt.ArrayLike, sensations: npt.ArrayLike) -> str:
    start = time.perf_counter()
    findings = find_contradictions(actions, states, sensations)
    seconds = time.perf_counter() - start
    verdict = (
        "consistent"
        if findings.consistent
        else f"{len(findings.contradictions)} state(s) contradicted from step "
        f"{findings.first_contradiction_step}"
    )
    return f"{seconds:7.3f} s  ({verdict})"


def main(argv: list[str]) -> None:
    sizes = [int(arg) for arg in argv] or [100_000, 1_000_000]
    memory = Memory()
    memory.reset(0, False, 0.0)
    calls = 1_000_000
    per_call = timeit.timeit(lambda: memory.append(1, 2, True, 0.5), number=calls) / calls
    print(f"Memory.append, repeated call:           {per_call * 1e9:6.0f} ns/call (target ~1000)")
    for steps in sizes:
        limit = 1.0 if steps <= 100_000 else 15.0
        actions, positions = random_walk(steps, seed=steps)
        aliased, per_step = record(actions, positions % ALIASING, positions)
        print(f"\n{steps:,} steps (target <= {limit:g} s)")
        print(f"  Memory.append while recording:        {per_step * 1e9:6.0f} ns/step")
        audit = time_audit(aliased.actions, aliased.internal_states, aliased.sensations)
        print(f"  aliased     find_contradictions  {audit}")
        print(
            f"  consistent  find_contradictions  {time_audit(actions, positions, positions == 0)}"
        )
        periodic = np.zeros(steps + 1, dtype=np.int64)
        periodic[0] = -1
        ring = np.arange(steps + 1) % RING
        one_state = np.zeros(steps + 1, dtype=np.int64)
        print(f"  periodic    find_contradictions  {time_audit(periodic, one_state, ring == 0)}")


if __name__ == "__main__":
    main(sys.argv[1:])
