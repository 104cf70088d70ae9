"""The JSON Schemas are written from the record classes: the checked-in files are exactly the
generated text (a recording registers their bytes, so a difference is a changed contract)."""

from __future__ import annotations

import doctest
import shutil
from pathlib import Path

import pytest

from rsstp_format import schema_text, schemas

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "schemas"


@pytest.mark.parametrize("name", schemas.SCHEMA_NAMES)
def test_the_checked_in_schema_is_the_generated_one(name: str) -> None:
    generated = schema_text.schema_text(name).encode("utf-8")
    assert generated == (SCHEMA_DIR / f"{name}.json").read_bytes(), (
        f"schemas/{name}.json differs from the record classes: run "
        "python -m rsstp_format.schema_text (and see schemas/README.md, Versions)"
    )
    assert generated == schemas.schema_bytes(name)


def test_check_finds_a_stale_file_and_writing_mends_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    for name in schemas.SCHEMA_NAMES:
        shutil.copy(SCHEMA_DIR / f"{name}.json", tmp_path)
    assert schema_text.main(["--check", str(tmp_path)]) == 0
    assert capsys.readouterr().out == ""

    stale = tmp_path / "rsstp.Model.json"
    stale.write_bytes(stale.read_bytes().replace(b"sorted (never reused)", b"sorted"))
    (tmp_path / "rsstp.Event.json").unlink()
    assert schema_text.main(["--check", str(tmp_path)]) == 1
    assert capsys.readouterr().out.splitlines() == [
        f"{tmp_path / 'rsstp.Model.json'}: differs from the records",
        f"{tmp_path / 'rsstp.Event.json'}: differs from the records",
    ]
    assert not (tmp_path / "rsstp.Event.json").exists()  # --check writes nothing

    assert schema_text.main([str(tmp_path)]) == 0
    capsys.readouterr()
    for name in schemas.SCHEMA_NAMES:
        assert (tmp_path / f"{name}.json").read_bytes() == (
            SCHEMA_DIR / f"{name}.json"
        ).read_bytes()


def test_the_default_directory_is_the_packaged_schemas() -> None:
    assert schema_text.main(["--check"]) == 0


def test_docstring_examples_run() -> None:
    result = doctest.testmod(schema_text)
    assert result.attempted > 0 and result.failed == 0
