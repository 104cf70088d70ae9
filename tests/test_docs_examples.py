"""Every example of the README and of ``docs/`` runs as written, in order, in one fresh folder
(``pytest -m slow``, as CI runs it: the examples take about 2 minutes).

The pages are read in the order the README links them (the README first); a page of ``docs/``
that the README does not link fails. Within a page, each fenced block is taken as a reader
takes it:

- ``sh``: its lines run in ``bash -e`` in the folder, the project's commands on ``PATH`` (as
  after ``source .venv/bin/activate``). A command that fails by design says so as a reader
  would see it (``... || echo "exit status $?"``).
- ``python``: runs in a fresh interpreter in the folder.
- ``text output``: what the block before it printed (its stdout and stderr, as a terminal shows
  them), line for line; ``...`` stands for any text, as in doctest's ELLIPSIS.
- ``file=NAME`` (any language): the block is a file the reader writes; it is written to NAME.
  A GitHub Actions workflow (``file=.github/workflows/...``) is then run as its runner would:
  each ``run:`` step in order, in ``bash -e``; ``actions/checkout`` and
  ``actions/setup-python`` are this checkout and this interpreter, and the install step must be
  the README's; ``actions/upload-artifact`` must find what it uploads.
- ``sh setup``: the README's two commands. The folder's ``.venv/bin`` holds this interpreter's
  programs, so the commands run as written, except their setup (``python3 -m venv .venv``,
  ``.venv/bin/pip install ...``) and the suite itself (``.venv/bin/python -m pytest``): those
  ``.ci/run`` runs, taking both commands whole from the README, on a fresh machine.
- ``norun=WHY``: not run here, for one of the reasons in :data:`NOT_RUN` (a native window, a
  server that runs until Ctrl-C, a cluster).
- any other block (``toml``, ``json``, ``text`` without ``output``) is read, not run.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
CI_RUN = (ROOT / ".ci" / "run").read_text()
BIN = Path(sys.executable).parent
HANG_GUARD_S = 900
"""Only a hang: no example is asserted to be fast."""

NOT_RUN = {
    "display": "opens a native window: these machines have none",
    "server": "serves until Ctrl-C",
    "cluster": "needs a SLURM or Kubernetes cluster",
}
SETUP = ("python3 -m venv .venv", ".venv/bin/pip install ", ".venv/bin/python -m pytest")
PROGRAMS = ("python", "python3", "rsstp-sim", "rsstp-replay", "rerun", "activate")
FENCE = re.compile(r"^(?P<indent> *)```(?P<info>[^`]*)$")


@dataclass(frozen=True)
class Block:
    page: str
    line: int
    language: str
    flags: dict[str, str]
    text: str

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"


def _blocks(path: Path) -> list[Block]:
    blocks: list[Block] = []
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        opening = FENCE.match(lines[i])
        if opening is None:
            i += 1
            continue
        words = opening["info"].split()
        indent, start = len(opening["indent"]), i + 1
        i += 1
        while not lines[i].strip().startswith("```"):
            i += 1
        body = "\n".join(line[indent:] for line in lines[start:i]) + "\n"
        flags = dict(word.partition("=")[::2] for word in words[1:])
        blocks.append(Block(path.relative_to(ROOT).as_posix(), start, words[0], flags, body))
        i += 1
    return blocks


LINKED = [
    ROOT / page
    for page in dict.fromkeys(re.findall(r"\]\((docs/[\w-]+\.md)\)", README.read_text()))
]
REFERENCE = README.read_text().partition("\n## Reference\n")[2]
ORDER = [ROOT / page for page in dict.fromkeys(re.findall(r"\]\((docs/[\w-]+\.md)\)", REFERENCE))]
"""The pages in the order the README's Reference lists them: a reader's order."""
PAGES = [README, *(page for page in ORDER if page.exists())]
BLOCKS = [block for page in PAGES for block in _blocks(page)]


def test_every_page_the_readme_links_is_there_and_in_its_reference() -> None:
    assert [page for page in LINKED if not page.exists()] == []
    assert set(LINKED) == set(ORDER)


def test_every_page_of_docs_is_linked_from_the_readme() -> None:
    linked = {page.relative_to(ROOT).as_posix() for page in PAGES}
    on_disk = {page.relative_to(ROOT).as_posix() for page in (ROOT / "docs").glob("*.md")}
    assert on_disk - linked == set()


def test_the_readme_is_a_front_door() -> None:
    assert len(README.read_text().splitlines()) <= 200


def test_every_block_is_taken_one_way() -> None:
    for block in BLOCKS:
        unknown = set(block.flags) - {"file", "norun", "output", "setup"}
        assert not unknown, f"{block.name}: unknown flags {unknown}"
        if "norun" in block.flags:
            assert block.flags["norun"] in NOT_RUN, f"{block.name}: no reason to leave it out"
        if "output" in block.flags:
            assert block.language == "text", block.name


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The reader's fresh folder, with ``.venv/bin`` holding this interpreter's programs."""
    found = tmp_path_factory.mktemp("reader")
    venv_bin = found / ".venv" / "bin"
    venv_bin.mkdir(parents=True)
    for program in PROGRAMS:
        if (BIN / program).exists():
            (venv_bin / program).symlink_to(BIN / program)
    return found


@pytest.fixture(scope="module")
def printed() -> dict[str, str]:
    """What each block that ran printed, by block name."""
    return {}


def _env() -> dict[str, str]:
    return {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}", "COLUMNS": "100"}


def _run(command: list[str], folder: Path, what: str) -> str:
    done = subprocess.run(
        command,
        cwd=folder,
        env=_env(),
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        timeout=HANG_GUARD_S,
        check=False,
    )
    assert done.returncode == 0, f"{what} exited {done.returncode}:\n{done.stdout}"
    return done.stdout


def _without_setup(block: Block) -> str:
    """The README's two commands less their setup, which ``.ci/run`` runs on a fresh machine."""
    kept = [part for part in block.text.strip().split(" && ") if not part.startswith(SETUP)]
    return " && ".join(kept) + "\n"


def test_ci_runs_the_readmes_two_commands_as_written() -> None:
    """``.ci/run`` takes both commands from the README (``.ci/readme_command.py``), setup and
    all: the setup this test leaves out is run there."""
    setup = [block.text.strip() for block in BLOCKS if "setup" in block.flags]
    assert len(setup) == 2 and SETUP[2] in setup[1]
    for number, command in enumerate(setup, start=1):
        printed = subprocess.run(
            [sys.executable, str(ROOT / ".ci" / "readme_command.py"), str(number)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        assert printed.strip() == command
        assert f"readme_command.py {number}" in CI_RUN


def _run_workflow(block: Block, folder: Path) -> str:
    workflow = yaml.safe_load(block.text)
    out = []
    for job in workflow["jobs"].values():
        for step in job["steps"]:
            uses = step.get("uses", "")
            if uses.startswith(("actions/checkout@", "actions/setup-python@")):
                continue
            if uses.startswith("actions/upload-artifact@"):
                for pattern in str(step["with"]["path"]).split():
                    assert list(folder.glob(pattern)), f"{block.name}: nothing at {pattern}"
                continue
            assert not uses, f"{block.name}: a step this test cannot run: {uses}"
            script = step["run"]
            if "pip install" in script:
                assert script.strip() == "python -m pip install -e .", block.name
                continue
            out.append(_run(["bash", "-e", "-c", script], folder, f"{block.name} {step}"))
    return "".join(out)


@pytest.mark.slow  # the chain of examples takes about 2 minutes: CI runs it (-m slow)
@pytest.mark.parametrize("index", range(len(BLOCKS)), ids=[b.name for b in BLOCKS])
def test_example(index: int, folder: Path, printed: dict[str, str]) -> None:
    block = BLOCKS[index]
    if "file" in block.flags:
        target = folder / block.flags["file"]
        assert not target.exists(), f"{block.name}: {target.name} was made by an earlier example"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(block.text)
        if block.flags["file"].startswith(".github/workflows/"):
            printed[block.name] = _run_workflow(block, folder)
    elif "output" in block.flags:
        earlier = [b for b in BLOCKS[:index] if b.page == block.page and b.name in printed]
        assert earlier, f"{block.name}: an output block with no example before it"
        _assert_printed(block, printed[earlier[-1].name])
    elif "norun" in block.flags:
        pass
    elif block.language == "sh":
        script = _without_setup(block) if "setup" in block.flags else block.text
        command = ["bash", "-e", "-o", "pipefail", "-c", script]
        printed[block.name] = _run(command, folder, block.name)
    elif block.language == "python":
        code = textwrap.dedent(block.text)
        printed[block.name] = _run([sys.executable, "-c", code], folder, block.name)


def _assert_printed(block: Block, found: str) -> None:
    """``found`` matches the block's text line for line; ``...`` is any text."""
    expected = [line.rstrip() for line in block.text.strip("\n").splitlines()]
    pattern = "\n".join(".*?".join(map(re.escape, line.split("..."))) for line in expected)
    actual = "\n".join(line.rstrip() for line in found.strip("\n").splitlines())
    assert re.fullmatch(pattern, actual, flags=re.S), (
        f"{block.name}: the docs show\n{block.text}\nthe example printed\n{found}"
    )
