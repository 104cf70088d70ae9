"""The learner's index of its confirmed transitions, kept edit by edit, against a recount."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_sim.runner import Runner
from rsstp_sim.scenario import load_scenario, parse_scenario
from rsstp_sim.strategies._learner_hypothesis import Hypothesis
from rsstp_sim.strategies._learner_incoming import Incoming
from rsstp_sim.strategies.learner import LearnerStrategy
from rsstp_sim.transition_system import TransitionSystem

Counts = list[list[int]]


def recount(
    rows: list[list[int]], alive: set[int]
) -> tuple[dict[int, set[tuple[int, int]]], Counts, Counts, list[int], Counts, Counts]:
    """What :class:`Incoming` keeps, counted from scratch in plain Python: the transitions into
    each state, ``back`` and ``known`` by pair of columns, the open columns of each state, and
    the squares (``a < b``) confirmed and closed."""
    width = len(rows[0]) if rows else 0
    into: dict[int, set[tuple[int, int]]] = {}
    back = [[0] * width for _ in range(width)]
    known = [[0] * width for _ in range(width)]
    for s, row in enumerate(rows):
        for a, t in enumerate(row):
            if t < 0:
                continue
            into.setdefault(t, set()).add((s, a))
            if t == s:
                continue
            for b, u in enumerate(rows[t]):
                if u >= 0:
                    known[a][b] += 1
                    back[a][b] += u == s
    opened = [sum(t < 0 for t in row) if s in alive else 0 for s, row in enumerate(rows)]
    squares = [[0] * width for _ in range(width)]
    closed = [[0] * width for _ in range(width)]
    for row in rows:
        for a in range(width):
            for b in range(a + 1, width):
                r, q = row[a], row[b]
                if r < 0 or q < 0 or rows[r][b] < 0 or rows[q][a] < 0:
                    continue
                squares[a][b] += 1
                closed[a][b] += rows[r][b] == rows[q][a]
    return into, back, known, opened, squares, closed


def assert_kept(incoming: Incoming, next_: np.ndarray, alive: set[int], n: int) -> None:
    rows = next_[:n].tolist()
    into, back, known, opened, squares, closed = recount(rows, alive)
    kept = {t: set(incoming.predecessors(t)) for t in range(n)}
    assert {t: v for t, v in kept.items() if v} == into
    assert incoming.back == back
    assert incoming.known == known
    assert incoming.open[:n].tolist() == opened
    assert incoming.squares == squares
    assert incoming.closed == closed


@settings(max_examples=200, deadline=None)
@given(
    st.integers(1, 7).flatmap(
        lambda n: st.tuples(
            st.just(n),
            st.integers(1, 4),
            st.lists(
                st.tuples(st.integers(0, n - 1), st.integers(0, 3), st.integers(-1, n - 1)),
                max_size=60,
            ),
            st.sets(st.integers(0, n - 1)),
        )
    )
)
def test_the_index_follows_every_edit(
    case: tuple[int, int, list[tuple[int, int, int]], set[int]],
) -> None:
    n, width, edits, alive = case
    next_ = np.full((n, width), -1, dtype=np.int64)
    incoming = Incoming(width, n)
    for s in alive:
        incoming.open_row(s, next_[s])
    for s, k, t in edits:
        incoming.set(next_, s, k % width, t)
        assert_kept(incoming, next_, alive, n)
    for s in sorted(alive):
        for k in range(width):
            incoming.set(next_, s, k, -1)
        incoming.close_row(s)
        alive = alive - {s}
        assert_kept(incoming, next_, alive, n)


def _inverses_by_recount(h: Hypothesis) -> dict[int, int]:
    """:meth:`Hypothesis.inverses` as the learner first wrote it: a recount over every state."""
    states = np.flatnonzero(h.alive)
    inverse: dict[int, int] = {}
    for ka, a in enumerate(h.actions):
        t = h.next[states, ka]
        moved = (t >= 0) & (t != states)
        sources, targets = states[moved], t[moved]
        best, best_count = -1, 0
        for kb in range(len(h.actions)):
            again = h.next[targets, kb]
            count = int(np.count_nonzero(again == sources))
            if count > best_count and 2 * count >= np.count_nonzero(again >= 0):
                best, best_count = kb, count
        if best >= 0:
            inverse[a] = h.actions[best]
    return inverse


def test_the_index_is_kept_through_a_whole_run() -> None:
    # Confirmations, new states, counterexamples, merges: at every hundredth step of whole runs
    # (boolean and float) the index equals a recount, and the inverses read from it equal
    # those of a recount over every state.
    two_joint = load_scenario("two-joint-30")
    twin = two_joint.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n', 1)
    for scenario in (two_joint, parse_scenario(twin)):
        learner = LearnerStrategy()
        runner = Runner(scenario, learner, seed=1)
        checked = 0
        while not learner.done and runner.step_index < 50_000:
            runner.step()
            if runner.step_index % 100 or learner._learning is None:
                continue
            h = learner._learning.h
            n = int(np.flatnonzero(h.alive).max()) + 1
            assert_kept(h.incoming, h.next, set(h.states()), n)
            assert h.inverses() == _inverses_by_recount(h)
            checked += 1
        assert learner.done and checked > 10


def test_the_states_by_feel_are_kept_through_a_whole_run() -> None:
    # With float feedback the learner finds the states agreeing with what it sensed and felt
    # by an index of their feels, kept as states come, are felt, merge and go: at every
    # fiftieth step it equals a scan of every state.
    scenario = load_scenario("two-joint-30")
    twin = parse_scenario(scenario.source.replace("[feedback]\n", '[feedback]\nmode = "float"\n'))
    learner = LearnerStrategy()
    runner = Runner(twin, learner, seed=2)
    while not learner.done and runner.step_index < 50_000:
        runner.step()
        if runner.step_index % 50 or learner._learning is None:
            continue
        h = learner._learning.h
        states = np.flatnonzero(h.alive)
        feels = {float(f) for f in h.feel[states]} | {0.0, 0.5, float(runner.memory.last_feedback)}
        for felt in h.also_felt.values():
            feels |= felt
        for feel in sorted(f for f in feels if f == f):
            for sensation in (False, True):
                expected = states[h.agree(states, sensation, feel)].tolist()
                assert h.matching(sensation, feel) == expected
    assert learner.done


@settings(max_examples=100, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.sampled_from(["create", "merge", "feel"]),
            st.integers(0, 30),
            st.integers(0, 30),
            st.sampled_from([0.25, 0.5, 0.75, float("nan")]),
        ),
        max_size=80,
    )  # fmt: skip
)
def test_the_states_by_feel_follow_new_states_feels_and_merges(
    edits: list[tuple[str, int, int, float]],
) -> None:
    actions = (0, 1)
    h = Hypothesis(TransitionSystem.universal(actions), actions, landmark=0, feels=True)
    for kind, i, j, feel in edits:
        states = h.states()
        s, t = states[i % len(states)], states[j % len(states)]
        if kind == "create":
            h.create(s, actions[j % 2], bool(j % 3 == 0), (), feel)
        elif kind == "merge" and s != t:
            h.merge(s, t)
        elif kind == "feel":
            h.set_feel(s, feel)
        alive = np.flatnonzero(h.alive)
        for felt in (0.25, 0.5, 0.75):
            for sensation in (False, True):
                expected = alive[h.agree(alive, sensation, felt)].tolist()
                assert h.matching(sensation, felt) == expected
        # The feel is shared when the felt states are twice the values felt, 16 states at least.
        felt_states = [int(s) for s in alive if h.feel[s] == h.feel[s]]
        values = {float(h.feel[s]) for s in felt_states}
        values |= {v for s in felt_states for v in h.also_felt.get(s, ())}
        shared = len(felt_states) >= 16 and len(felt_states) >= 2 * len(values)
        assert h.feel_shared() == shared


@pytest.mark.parametrize(
    ("values", "states", "shared"),
    [(1, 15, False), (1, 16, True), (8, 16, True), (9, 17, False), (20, 20, False)],
)
def test_the_feel_is_shared_when_states_outnumber_the_values_felt_twice(
    values: int, states: int, shared: bool
) -> None:
    # ``states`` states (the landmark among them) felt as ``values`` values in turn.
    actions = (0, 1)
    h = Hypothesis(TransitionSystem.universal(actions), actions, landmark=0, feels=True)
    h.set_feel(0, 0.0)
    for i in range(1, states):
        h.create(0, actions[i % 2], False, (), (i % values) / values)
    assert len(h.states()) == states
    assert h.feel_shared() == shared
