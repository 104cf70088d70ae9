"""Table files: Parquet, and CSV with its dtype sidecar, read back by
:func:`rsstp_replay.read_table` with the same index and dtypes; what CSV cannot keep is
refused with a hint to write Parquet, and a failed write leaves the old files."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from rsstp_replay import TableError, read_table, write_table
from rsstp_sim.errors import OutputError


def test_text_survives_csv(tmp_path: Path) -> None:
    """Empty text, commas, quotes, new lines, and text that pandas would read as missing."""
    table = pd.DataFrame(
        {
            "text": pd.Series(["", "a,b", 'say "hi"', "two\nlines", "NA", "null"], dtype="str"),
            "kind": pd.Categorical(["x", None, "y", "x", "y", None], categories=["y", "x"]),
            "count": pd.array([1, None, 3, 4, None, 6], dtype="Int64"),
            "flag": pd.array([True, None, False, True, True, None], dtype="boolean"),
            "value": [0.1, float("nan"), 1e-300, -0.0, float("inf"), 2 / 3],
        }
    )
    out = tmp_path / "text.csv"
    write_table(table, out)
    assert read_table(out).equals(table)


@pytest.mark.parametrize(
    "index",
    [
        pd.Index(pd.array([3, None, 5], dtype="Int64"), name="k"),
        pd.Index(["b", "", "a"], dtype="str", name="k"),
        pd.RangeIndex(3, name="k"),
    ],
    ids=["nullable", "text", "range"],
)
def test_a_named_index_reads_back(tmp_path: Path, index: pd.Index) -> None:
    table = pd.DataFrame({"a": [1.5, 2.5, 3.5]}, index=index)
    for suffix in (".csv", ".parquet"):
        write_table(table, tmp_path / f"t{suffix}")
        found = read_table(tmp_path / f"t{suffix}")
        assert found.equals(table) and found.index.dtype == table.index.dtype, suffix


def test_a_csv_without_its_sidecar_is_refused_with_a_hint(tmp_path: Path) -> None:
    out = tmp_path / "steps.csv"
    pd.DataFrame({"a": [1, 2]}).to_csv(out, index=False)
    with pytest.raises(
        TableError,
        match=r"steps\.csv: no dtype sidecar steps\.csv\.dtypes\.json beside it, so its types "
        r"cannot be restored: .* or write \.parquet, which keeps every type",
    ):
        read_table(out)


def test_a_sidecar_that_does_not_describe_the_csv_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "t.csv"
    write_table(pd.DataFrame({"a": [1, 2], "b": [0.5, 1.5]}), out)
    out.write_text("a,c\n1,2\n")
    with pytest.raises(TableError, match=r"t\.csv: its columns \['a', 'c'\] are not those its"):
        read_table(out)
    sidecar = tmp_path / "t.csv.dtypes.json"
    sidecar.write_text('{"format": "something else"}')
    with pytest.raises(TableError, match=r"t\.csv\.dtypes\.json: not a dtype sidecar"):
        read_table(out)


@pytest.mark.parametrize(
    ("column", "message"),
    [
        (pd.Series(pd.date_range("2026-01-01", periods=2)), r"'c' has dtype datetime64"),
        (pd.Series(["a", None], dtype="object"), r"'c' has dtype object \(mixed\)"),
        (pd.Series(pd.Categorical(["a", "b"], ordered=True)), r"'c' is an ordered or non-text"),
    ],
)
def test_what_csv_cannot_keep_is_refused_with_a_hint(
    tmp_path: Path, column: pd.Series, message: str
) -> None:
    out = tmp_path / "t.csv"
    with pytest.raises(TableError, match=f"{message}.*write .parquet instead"):
        write_table(pd.DataFrame({"c": column}), out)
    assert list(tmp_path.iterdir()) == []
    write_table(pd.DataFrame({"c": column}), tmp_path / "t.parquet")  # Parquet keeps it


def test_a_failed_sidecar_write_leaves_the_old_csv(tmp_path: Path) -> None:
    out = tmp_path / "t.csv"
    out.write_text("old\n")
    (tmp_path / "t.csv.dtypes.json").mkdir()  # cannot be replaced by a file
    with pytest.raises(OutputError, match=r"t\.csv\.dtypes\.json: "):
        write_table(pd.DataFrame({"a": [1]}), out)
    assert out.read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.csv", "t.csv.dtypes.json"]
