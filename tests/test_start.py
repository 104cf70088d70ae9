"""A Ctrl-C at any moment of either command, start-up included, is one line, never a
traceback (the console scripts start in ``rsstp_cli.start``, before the packages load).

The first few hundredths of a second are Python's own start-up, before any of this project's
code runs (its ``site`` and the console script's ``import re``): a Ctrl-C there gets Python's
default, which no program can change, so the delays here start after it."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def _script(name: str) -> str:
    found = shutil.which(name, path=str(BIN))
    if found is None:
        pytest.skip(f"the {name} console script is not installed beside {sys.executable}")
    return found


@pytest.mark.parametrize("delay_s", [0.06, 0.1, 0.15, 0.3, 0.6])
@pytest.mark.parametrize(
    "command",
    [
        ["rsstp-sim", "run", "thesis-roulette", "--steps", "3000000", "--quiet"],
        [  # the truth computed afresh: longer than the longest delay, however fast the audit
            "rsstp-replay",
            "audit",
            "--truth",
            "--no-cache",
            str(ROOT / "recordings" / "three-joint-random.mcap"),
        ],
    ],
    ids=["rsstp-sim run", "rsstp-replay audit"],
)
def test_ctrl_c_at_start_up_is_one_line(command: list[str], delay_s: float) -> None:
    process = subprocess.Popen(
        [_script(command[0]), *command[1:]],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    time.sleep(delay_s)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert "Traceback" not in err, err
    if process.returncode == -signal.SIGINT:  # before Python set its handler: killed silently
        assert err == ""
        return
    assert process.returncode == 130, err
    assert err == f"{command[0]}: interrupted\n"
