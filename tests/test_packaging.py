"""What a user installing the package relies on: the wheel that ``pip install`` gets.

The wheel is built once per session (``python -m build --wheel``, as CI builds it) from a copy
of the source tree, and read as an installer reads it: its METADATA, entry_points.txt, RECORD
and files. Each is checked against something computed here from the source, not against the
configuration it was built from.
"""

from __future__ import annotations

import ast
import base64
import configparser
import email.parser
import email.policy
import hashlib
import os
import re
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass
from email.message import Message
from importlib import metadata
from pathlib import Path

import pytest

import rsstp_sim
from waiting import HANG_S

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PACKAGES = sorted(path.name for path in SRC.iterdir() if (path / "__init__.py").is_file())
"""The import packages in the source tree."""

SHIPPED_DATA = ("py.typed", "scenarios/*.toml", "schemas/*.json")
"""What the packages read at run time besides their modules: the scenarios ``rsstp-sim``
lists and loads by name, the JSON Schemas every recording registers, and the typing marker."""


@dataclass(frozen=True)
class Wheel:
    path: Path
    files: dict[str, bytes]
    """Every file in the wheel by its path in the archive."""
    dist_info: str
    """The ``name-version.dist-info`` folder."""

    def text(self, name: str) -> str:
        return self.files[f"{self.dist_info}/{name}"].decode()

    @property
    def metadata(self) -> Message:
        return email.parser.Parser(policy=email.policy.compat32).parsestr(self.text("METADATA"))


def source_files(package: str) -> dict[str, Path]:
    """The files of ``package`` in the source tree (symbolic links followed, as a build
    follows them), by their path in a wheel; compiled files left out."""
    found: dict[str, Path] = {}
    for folder, dirs, names in os.walk(SRC / package, followlinks=True):
        dirs[:] = [name for name in dirs if name != "__pycache__"]
        for name in names:
            path = Path(folder) / name
            if path.suffix != ".pyc":
                found[path.relative_to(SRC).as_posix()] = path
    return found


def build_wheel(out: Path, scratch: Path) -> Path:
    """Build the wheel of a copy of the source tree (the shared checkout is left alone: a build
    writes ``build/`` and an egg-info next to the sources)."""
    source = scratch / "source"
    source.mkdir()
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy2(ROOT / name, source / name)
    shutil.copytree(SRC, source / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    done = subprocess.run(
        [sys.executable, "-m", "build", "--wheel", "--outdir", str(out), str(source)],
        capture_output=True,
        text=True,
        timeout=HANG_S,
    )
    assert done.returncode == 0, f"the wheel does not build:\n{done.stdout}\n{done.stderr}"
    (wheel,) = out.glob("*.whl")
    return wheel


@pytest.fixture(scope="session")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Wheel:
    path = build_wheel(tmp_path_factory.mktemp("dist"), tmp_path_factory.mktemp("build"))
    with zipfile.ZipFile(path) as archive:
        files = {name: archive.read(name) for name in archive.namelist() if not name.endswith("/")}
    (dist_info,) = {name.split("/")[0] for name in files if ".dist-info/" in name}
    return Wheel(path, files, dist_info)


def normalized(name: str) -> str:
    """A distribution name as PEP 503 compares them."""
    return re.sub(r"[-_.]+", "-", name).lower()


def runtime_requirements(wheel: Wheel) -> dict[str, str]:
    """The wheel's Requires-Dist outside any extra: normalized name -> the requirement."""
    found = {}
    for requirement in wheel.metadata.get_all("Requires-Dist") or []:
        if "extra ==" in requirement.partition(";")[2]:
            continue
        name = re.match(r"[A-Za-z0-9][A-Za-z0-9._-]*", requirement)
        assert name is not None, requirement
        found[normalized(name.group())] = requirement
    return found


# -- name, version, Python -------------------------------------------------------------------


def test_the_wheel_is_the_distribution_the_code_runs_from(wheel: Wheel) -> None:
    meta = wheel.metadata
    name, version = meta["Name"], meta["Version"]
    # The tests import the installed distribution; the wheel must be that one, at that version.
    assert set(metadata.packages_distributions()["rsstp_sim"]) == {name}
    assert version == rsstp_sim.__version__ == metadata.version(name)
    # Pure Python: one wheel for every platform, named as pip expects.
    assert wheel.path.name == f"{normalized(name).replace('-', '_')}-{version}-py3-none-any.whl"
    assert wheel.dist_info == f"{normalized(name).replace('-', '_')}-{version}.dist-info"
    tags = email.parser.Parser().parsestr(wheel.text("WHEEL"))
    assert tags["Root-Is-Purelib"] == "true" and tags["Tag"] == "py3-none-any"


def test_requires_python_is_a_floor_the_source_and_this_interpreter_meet(wheel: Wheel) -> None:
    floor = re.fullmatch(r">=\s*3\.(\d+)", wheel.metadata["Requires-Python"])
    assert floor is not None, wheel.metadata["Requires-Python"]
    minor = int(floor.group(1))
    assert sys.version_info >= (3, minor)
    # Nothing in the source needs a newer grammar than the floor says.
    for path in SRC.rglob("*.py"):
        ast.parse(path.read_text(encoding="utf-8"), str(path), feature_version=(3, minor))


def test_the_description_is_the_readme(wheel: Wheel) -> None:
    meta = wheel.metadata
    assert meta["Description-Content-Type"] == "text/markdown"
    assert str(meta.get_payload()).strip() == (ROOT / "README.md").read_text().strip()


def test_the_licence_is_the_file_shipped(wheel: Wheel) -> None:
    text = (ROOT / "LICENSE").read_text()
    # The expression the metadata declares is the licence the text is.
    assert text.splitlines()[0] == f"{wheel.metadata['License-Expression']} License"
    assert wheel.metadata.get_all("License-File") == ["LICENSE"]
    assert wheel.files[f"{wheel.dist_info}/licenses/LICENSE"] == (ROOT / "LICENSE").read_bytes()


# -- the commands ----------------------------------------------------------------------------


def console_scripts(wheel: Wheel) -> dict[str, str]:
    entry_points = configparser.ConfigParser(delimiters=("=",))
    entry_points.read_string(wheel.text("entry_points.txt"))
    return dict(entry_points["console_scripts"])


def test_the_wheel_installs_both_commands(wheel: Wheel) -> None:
    assert console_scripts(wheel) == {
        "rsstp-sim": "rsstp_cli.start:rsstp_sim",
        "rsstp-replay": "rsstp_cli.start:rsstp_replay",
    }


@pytest.mark.parametrize("command", ["rsstp-sim", "rsstp-replay"])
def test_each_command_is_the_one_it_is_named_after(wheel: Wheel, command: str) -> None:
    # Run the entry point as the installed script runs it: import, call, exit with its result.
    module, _, function = console_scripts(wheel)[command].partition(":")
    script = (
        "import sys, importlib; sys.argv[0] = 'script'; "
        f"sys.exit(getattr(importlib.import_module({module!r}), {function!r})())"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, "--version"], capture_output=True, text=True, timeout=HANG_S
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == f"{command} {wheel.metadata['Version']}"


@pytest.mark.parametrize(
    ("program", "name"), [("rsstp_cli.sim", "rsstp-sim"), ("rsstp_cli.replay", "rsstp-replay")]
)
def test_both_commands_print_the_installed_version(program: str, name: str) -> None:
    done = subprocess.run(
        [sys.executable, "-m", program, "--version"], capture_output=True, text=True, timeout=HANG_S
    )
    assert done.returncode == 0
    assert done.stdout.strip() == f"{name} {metadata.version('rsstp')}"


# -- the files -------------------------------------------------------------------------------


def test_the_wheel_holds_every_package_with_its_data_and_nothing_else(wheel: Wheel) -> None:
    packaged = {name for name in wheel.files if not name.startswith(wheel.dist_info + "/")}
    assert {name.split("/")[0] for name in packaged} == set(PACKAGES)
    matched = dict.fromkeys(SHIPPED_DATA, 0)
    for package in PACKAGES:
        source = source_files(package)
        needed = {name for name in source if name.endswith(".py")}
        for pattern in SHIPPED_DATA:
            data = {path.relative_to(SRC).as_posix() for path in (SRC / package).glob(pattern)}
            matched[pattern] += len(data)
            needed |= data
        assert f"{package}/py.typed" in needed, f"{package} has no py.typed"
        inside = {name for name in packaged if name.startswith(package + "/")}
        assert needed <= inside, f"missing from the wheel: {sorted(needed - inside)}"
        assert inside <= set(source), f"not in the source: {sorted(inside - set(source))}"
        for name in inside:
            assert wheel.files[name] == source[name].read_bytes(), f"{name} differs"
    # A pattern that matched nothing (a dangling link, a renamed folder) checked nothing.
    assert all(matched.values()), matched


def test_the_record_lists_every_file_with_its_hash_and_size(wheel: Wheel) -> None:
    record = f"{wheel.dist_info}/RECORD"
    rows = {}
    for line in wheel.text("RECORD").splitlines():
        path, digest, size = line.rsplit(",", 2)
        rows[path] = (digest, size)
    assert set(rows) == set(wheel.files)
    assert rows.pop(record) == ("", "")
    for path, (digest, size) in rows.items():
        data = wheel.files[path]
        expected = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
        assert (digest, size) == (f"sha256={expected}", str(len(data))), path


# -- dependencies ----------------------------------------------------------------------------


def third_party_imports() -> dict[str, set[str]]:
    """Every top-level module the packages import from outside the standard library and
    themselves (any import, anywhere in a module): module -> the files importing it."""
    found: dict[str, set[str]] = {}
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names = [node.module]
            else:
                continue
            for name in names:
                top = name.split(".")[0]
                if top not in sys.stdlib_module_names and top not in PACKAGES:
                    found.setdefault(top, set()).add(path.relative_to(SRC).as_posix())
    return found


def test_every_third_party_import_is_a_requirement_of_the_wheel(wheel: Wheel) -> None:
    """By the distribution that provides the module here (``rerun`` is ``rerun-sdk``), or by
    the module's own name when nothing installed provides it."""
    required = runtime_requirements(wheel)
    provided = metadata.packages_distributions()
    imported = third_party_imports()
    assert "numpy" in imported  # the walk sees imports at all
    for module, files in sorted(imported.items()):
        distributions = {normalized(name) for name in provided.get(module, [module])}
        assert distributions & set(required), (
            f"{module} is imported ({', '.join(sorted(files))}) but no Requires-Dist of the "
            f"wheel provides it (looked for {sorted(distributions)})"
        )
