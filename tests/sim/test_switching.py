"""While a helper thread compresses or reads chunks, the switch interval is short, and the one
before comes back when the last helper is done (from any number of overlapping helpers)."""

from __future__ import annotations

import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from rsstp_replay.reader._container import open_container
from rsstp_sim import RandomStrategy, load_scenario
from rsstp_sim.recording.recorder import Recorder
from rsstp_sim.switching import SWITCH_INTERVAL, sooner_switches


@pytest.fixture
def interval() -> Iterator[float]:
    """A switch interval of its own for the test (5 ms, Python's default), put back after."""
    before = sys.getswitchinterval()
    sys.setswitchinterval(0.005)
    yield 0.005
    sys.setswitchinterval(before)


def test_the_interval_is_short_in_the_block_and_as_before_after(interval: float) -> None:
    with sooner_switches():
        assert sys.getswitchinterval() == pytest.approx(SWITCH_INTERVAL)
    assert sys.getswitchinterval() == pytest.approx(interval)


def test_a_shorter_interval_is_kept(interval: float) -> None:
    sys.setswitchinterval(SWITCH_INTERVAL / 4)
    with sooner_switches():
        assert sys.getswitchinterval() == pytest.approx(SWITCH_INTERVAL / 4)
    assert sys.getswitchinterval() == pytest.approx(SWITCH_INTERVAL / 4)


def test_overlapping_helpers_put_it_back_when_the_last_is_done(interval: float) -> None:
    """Two threads' blocks overlap, the first to start ending first."""
    first_in, second_in, first_out = threading.Event(), threading.Event(), threading.Event()
    seen: list[float] = []

    def first() -> None:
        with sooner_switches():
            first_in.set()
            second_in.wait()
        first_out.set()

    def second() -> None:
        first_in.wait()
        with sooner_switches():
            second_in.set()
            first_out.wait()
            seen.append(sys.getswitchinterval())  # the first is out, this one still in

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert seen == [pytest.approx(SWITCH_INTERVAL)]
    assert sys.getswitchinterval() == pytest.approx(interval)


@pytest.mark.slow
def test_a_recording_and_a_reading_hold_it_short_while_their_thread_works(
    tmp_path: Path, interval: float
) -> None:
    path = tmp_path / "run.mcap"
    recorder = Recorder(
        path, load_scenario("three-joint"), RandomStrategy(), seed=1, chunk_size=1024
    )
    during: list[float] = []
    recorder.run(8192, progress=lambda done: during.append(sys.getswitchinterval()))
    assert during == [pytest.approx(SWITCH_INTERVAL)] * 2  # chunks were handed over by then
    assert sys.getswitchinterval() == pytest.approx(interval)

    container = open_container(path)
    assert len(container.chunks) > 100
    chunks = container.chunks_data(container.chunks)
    next(chunks)
    assert sys.getswitchinterval() == pytest.approx(SWITCH_INTERVAL)
    chunks.close()
    assert sys.getswitchinterval() == pytest.approx(interval)
