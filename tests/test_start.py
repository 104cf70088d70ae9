"""A Ctrl-C at any moment of either command, start-up included, is one line, never a
traceback (the console scripts start in ``rsstp_cli.start``, before the packages load).

The first few hundredths of a second are Python's own start-up, before any of this project's
code runs (its ``site`` and the console script's ``import re``): a Ctrl-C there gets Python's
default, which no program can change, so the delays here start after it."""

from __future__ import annotations

import os
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
