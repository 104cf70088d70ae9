"""Progress bars: on a terminal's stderr for long commands, never when piped or --quiet."""

from __future__ import annotations

import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest

from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[1]
REFERENCE = ROOT / "recordings" / "two-joint-30-learner.mcap"


def on_a_terminal(*command: str) -> tuple[int, str]:
    """Run ``command`` with stderr on a pseudo-terminal; its exit code and what it wrote
    (read while it runs: a closed terminal's unread output is lost)."""
    leader, follower = pty.openpty()
    # 24 rows of 100 columns, as a terminal has (a new pseudo-terminal has none).
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=follower)
    os.close(follower)
    written = b""
    while True:
        try:
            chunk = os.read(leader, 1 << 16)
        except OSError:  # the other side is closed: everything was read
            break
        if not chunk:
            break
        written += chunk
    os.close(leader)
    return process.wait(timeout=HANG_S), written.decode(errors="replace")


COMMANDS = [
    pytest.param(("rsstp_cli.sim", "run", "thesis-roulette", "--steps", "140000"), id="run",
                 marks=pytest.mark.slow),
    pytest.param(("rsstp_cli.sim", "record", "one-joint-10", "--steps", "9000", "-o",
                  "{tmp}/run.mcap", "--force"), id="record"),
    pytest.param(("rsstp_cli.replay", "audit", str(REFERENCE), "--truth"), id="audit",
                 marks=pytest.mark.slow),
    pytest.param(("rsstp_cli.sim", "sweep", str(ROOT / "tests/sweep/tiny-sweep.toml"), "-o",
                  "{tmp}/sweep", "--workers", "1"), id="sweep", marks=pytest.mark.slow),
]  # fmt: skip


@pytest.mark.parametrize("command", COMMANDS)
def test_a_bar_on_a_terminal_and_nothing_when_piped_or_quiet(
    command: tuple[str, ...], tmp_path: Path
) -> None:
    program, *args = (part.format(tmp=tmp_path) for part in command)
    code, shown = on_a_terminal(sys.executable, "-m", program, *args)
    assert code == 0
    assert "%|" in shown  # tqdm's bar
    code, quiet = on_a_terminal(sys.executable, "-m", program, *args, "--quiet")
    assert code == 0 and quiet == ""
    piped = subprocess.run(
        [sys.executable, "-m", program, *args], capture_output=True, text=True, timeout=HANG_S
    )
    assert piped.returncode == 0 and piped.stderr == ""
