"""Table files: Parquet, and CSV with its dtype sidecar, read back by
:func:`rsstp_replay.read_table` with the same index and dtypes; what CSV cannot keep is
refused with a hint to write Parquet, and a failed write leaves the old files."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest

from rsstp_replay import TableError, read_table, write_table
from rsstp_replay.errors import CorruptRecording
from rsstp_replay.export.table_files import write_table_parts
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


def _mixed(rows: int) -> pd.DataFrame:
    """Every kind of column a steps table has, missing values included, indexed by step."""
    return pd.DataFrame(
        {
            "action": pd.array([None, *range(1, rows)], dtype="Int64"),
            "kind": pd.Categorical(
                [["fold", None, "links"][k % 3] for k in range(rows)],
                categories=["fold", "obstacle", "links"],
            ),
            "flag": [k % 2 == 0 for k in range(rows)],
            "x": [k / 7 for k in range(rows)],
        },
        index=pd.RangeIndex(rows, name="step"),
    )


@pytest.mark.parametrize("size", [1, 4, 10, 11])
def test_a_table_written_in_parts_reads_back_whole(tmp_path: Path, size: int) -> None:
    table = _mixed(10)
    parts = [table.iloc[a : a + size] for a in range(0, len(table), size)]
    out = tmp_path / "t.parquet"
    head = write_table_parts(iter(parts), out)
    assert list(head.columns) == list(table.columns) and head.index.name == "step"
    assert read_table(out).equals(table)
    assert pq.ParquetFile(out).metadata.num_row_groups == len(parts)


@pytest.mark.parametrize(
    "error", [CorruptRecording("run.mcap: step 8: broken"), KeyboardInterrupt()], ids=repr
)
def test_a_part_that_fails_leaves_the_old_table(tmp_path: Path, error: BaseException) -> None:
    table = _mixed(10)
    out = tmp_path / "t.parquet"
    out.write_bytes(b"old")

    def parts() -> Iterator[pd.DataFrame]:
        yield table.iloc[:4]
        yield table.iloc[4:8]
        raise error

    with pytest.raises(type(error)):
        write_table_parts(parts(), out)
    assert out.read_bytes() == b"old"
    assert [p.name for p in tmp_path.iterdir()] == ["t.parquet"]  # no side file left


def test_parts_that_do_not_match_the_first_leave_no_table(tmp_path: Path) -> None:
    table = _mixed(6)
    other = table.iloc[3:].assign(x=["a", "b", "c"])  # text where the first part had floats
    out = tmp_path / "t.parquet"
    with pytest.raises((TypeError, ValueError)):
        write_table_parts(iter([table.iloc[:3], other]), out)
    assert list(tmp_path.iterdir()) == []


def test_parts_go_to_parquet_only(tmp_path: Path) -> None:
    with pytest.raises(TableError, match=r"t\.csv: a table written in parts goes to Parquet"):
        write_table_parts(iter([_mixed(2)]), tmp_path / "t.csv")
    with pytest.raises(TableError, match=r"t\.parquet: no part to write"):
        write_table_parts(iter([]), tmp_path / "t.parquet")
    (tmp_path / "d.parquet").mkdir()
    with pytest.raises(OutputError, match=r"d\.parquet: "):
        write_table_parts(iter([_mixed(2)]), tmp_path / "d.parquet")
