"""A Ctrl-C at any moment of either command, start-up included, is one line, never a
traceback (the console scripts start in ``rsstp_cli.start``, before the packages load).

The first moments are Python's own start-up, before any of this project's code runs (its
``site`` and the console script's ``import re``): a Ctrl-C there gets Python's default, which
no program can change. So each Ctrl-C here is sent at a moment seen from outside the process,
whatever the machine's speed: numpy's core (or a later package's extension) mapped into it
(``/proc/PID/maps``), which means ``rsstp_cli.start`` is importing the packages with its own
handler of SIGINT; or the progress bar of the command's long stage on its terminal, which
means the command itself is running."""

from __future__ import annotations

import fcntl
import os
import pty
import shutil
import signal
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest

from waiting import HANG_S, wait_until

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def _script(name: str) -> str:
    found = shutil.which(name, path=str(BIN))
    if found is None:
        pytest.skip(f"the {name} console script is not installed beside {sys.executable}")
    return found


SIM_RUN = ["rsstp-sim", "run", "thesis-roulette", "--steps", "3000000"]
AUDIT = [  # the truth computed afresh: its stage lasts, however fast the audit
    "rsstp-replay",
    "audit",
    "--truth",
    "--no-cache",
    str(ROOT / "recordings" / "three-joint-random.mcap"),
]
NUMPY = "numpy/_core/_multiarray_umath."  # the first extension either command loads


@pytest.mark.parametrize(
    ("command", "moment"),
    [
        (SIM_RUN, ("mapped", NUMPY)),
        (SIM_RUN, ("shown", "running")),
        (AUDIT, ("mapped", NUMPY)),
        (AUDIT, ("mapped", "pyarrow/lib.")),  # numpy done, pandas and the rest to come
        (AUDIT, ("shown", "comparing with the truth")),
    ],
    ids=[
        "rsstp-sim run, loading numpy",
        "rsstp-sim run, running",
        "rsstp-replay audit, loading numpy",
        "rsstp-replay audit, loading pyarrow",
        "rsstp-replay audit, comparing with the truth",
    ],
)
def test_ctrl_c_at_start_up_is_one_line(command: list[str], moment: tuple[str, str]) -> None:
    code, shown = _interrupted([_script(command[0]), *command[1:]], *moment)
    assert "Traceback" not in shown, shown
    assert code == 130, shown
    # One line; before it only the bar's redraws (carriage returns, no new line).
    assert shown.endswith(f"{command[0]}: interrupted\r\n") and shown.count("\n") == 1, shown


def _interrupted(command: list[str], seen: str, text: str) -> tuple[int, str]:
    """Run ``command`` with stderr on a pseudo-terminal (so that it draws its bar), send it
    SIGINT once ``text`` is ``seen`` (``"mapped"`` in its memory map, or ``"shown"`` on its
    terminal), and return its exit code and all it wrote there."""
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 100, 0, 0))
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=follower)
    os.close(follower)
    written = b""
    try:
        if seen == "mapped":
            maps = Path(f"/proc/{process.pid}/maps")
            wait_until(lambda: text in maps.read_text(errors="replace"), text, process=process)
        while seen == "shown" and text.encode() not in written:
            chunk = _read(leader)
            if not chunk:
                pytest.fail(f"{command[0]} ended before it showed {text!r}: {written!r}")
            written += chunk
        process.send_signal(signal.SIGINT)
        while chunk := _read(leader):
            written += chunk
        return process.wait(timeout=HANG_S), written.decode(errors="replace")
    finally:
        os.close(leader)
        if process.poll() is None:
            process.kill()
            process.wait()


def _read(leader: int) -> bytes:
    """What the command wrote next on its terminal; b"" once it is closed."""
    try:
        return os.read(leader, 1 << 16)
    except OSError:  # the other side is closed: everything was read
        return b""


# -- numpy's huge-page advice ---------------------------------------------------------------

DEFRAG_TEXTS = {  # the kernel's file: every choice, the chosen one in brackets
    "always": "[always] defer defer+madvise madvise never\n",
    "defer": "always [defer] defer+madvise madvise never\n",
    "defer+madvise": "always defer [defer+madvise] madvise never\n",
    "madvise": "always defer defer+madvise [madvise] never\n",
    "never": "always defer defer+madvise madvise [never]\n",
}


@pytest.mark.parametrize("chosen", sorted(DEFRAG_TEXTS))
def test_numpy_is_told_not_to_advise_huge_pages_where_a_fault_would_compact(chosen: str) -> None:
    from rsstp_cli.start import huge_page_advice

    stalls = chosen in ("madvise", "defer+madvise")  # the kernel's documented meanings
    assert huge_page_advice(DEFRAG_TEXTS[chosen], {}) == ("0" if stalls else None)
    # The user's own setting, either way, and a machine without the file, are left alone.
    for theirs in ("0", "1"):
        assert huge_page_advice(DEFRAG_TEXTS[chosen], {"NUMPY_MADVISE_HUGEPAGE": theirs}) is None
    assert huge_page_advice(None, {}) is None


@pytest.mark.parametrize("theirs", [None, "1"])
def test_a_command_runs_numpy_with_the_advice(tmp_path: Path, theirs: str | None) -> None:
    """End to end through the start of a command: numpy, imported after it, advises huge
    pages or not as the kernel's setting and the user's variable say."""
    defrag = Path("/sys/kernel/mm/transparent_hugepage/defrag")
    if not defrag.is_file():
        pytest.skip("no transparent huge pages on this machine")
    chosen = defrag.read_text().split("[")[1].split("]")[0]
    (tmp_path / "probe.py").write_text(
        "import numpy\n"
        "def main():\n"
        "    print(numpy._core.multiarray._get_madvise_hugepage())\n"
        "    return 0\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if theirs is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = theirs
    code = "from rsstp_cli.start import _start; raise SystemExit(_start('probe', 'probe'))"
    found = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        env={**env, "PYTHONPATH": str(tmp_path)},
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    advised = theirs == "1" or chosen not in ("madvise", "defer+madvise")
    assert found == str(advised)


def test_a_ctrl_c_inside_a_held_block_comes_when_the_block_has_ended() -> None:
    """What the command lines hold Ctrl-C over (the packages' imports, a progress bar's
    construction) finishes whole; the interrupt comes right after, and the handler before it
    is back."""
    import threading

    from rsstp_cli.start import ctrl_c_held

    before = signal.getsignal(signal.SIGINT)
    finished = []
    with pytest.raises(KeyboardInterrupt):
        with ctrl_c_held():
            os.kill(os.getpid(), signal.SIGINT)
            threading.Event().wait(0.01)  # the handler runs (between bytecodes) in here
            finished.append("the rest of the block")
    assert finished == ["the rest of the block"]
    assert signal.getsignal(signal.SIGINT) is before
    with ctrl_c_held():  # no Ctrl-C: nothing raised
        finished.append("again")
    assert finished[-1] == "again"
