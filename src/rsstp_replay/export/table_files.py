"""Table files: a table written whole as Parquet or CSV, and read back with its types.

:func:`write_table` writes one whole (a failed write leaves what was there), as Parquet or
CSV by the suffix; :func:`write_table_parts` writes one that comes in parts (a long steps
table while it is decoded) to Parquet, a row group a part, and is the one home of writing
Parquet. Parquet keeps the index (as a column named after it) and every dtype.
CSV cannot say what a column's type is, so a CSV table has a *dtype sidecar* beside it,
``OUT.csv.dtypes.json``::

    {
      "format": "rsstp-replay table dtypes",
      "version": 1,
      "index": "step",
      "dtypes": {"step": "int64", "action": "Int64", "blocked_kind": "category", ...},
      "categories": {"blocked_kind": ["fold", "obstacle", "links"]}
    }

``dtypes`` names every column of the CSV in its order, with its pandas dtype (``str`` for
text); ``index`` is the column that is the table's index (``null``: the index is the row
number, not written); ``categories`` gives the categories of each ``category`` column, in
order. A missing value is an empty field (text columns never have one). A table whose
dtypes CSV and the sidecar cannot carry (dates, ordered categoricals, missing text, ...) is
refused with a hint to write Parquet.

:func:`read_table` reads either back with the same index and dtypes
(``read_table(path).equals(table)``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable
from concurrent.futures import Future, ThreadPoolExecutor, wait
from contextlib import suppress
from pathlib import Path
from typing import Any

import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_replay.errors import TableError
from rsstp_sim.errors import OutputError
from rsstp_sim.files import written_whole

__all__ = [
    "SIDECAR_SUFFIX",
    "TABLE_FORMATS",
    "read_table",
    "sidecar_path",
    "write_table",
    "write_table_parts",
]

TABLE_FORMATS = (".parquet", ".csv")
"""The suffixes of the table files :func:`write_table` writes and :func:`read_table` reads."""

SIDECAR_SUFFIX = ".dtypes.json"
"""Added to a CSV table's name for its dtype sidecar."""

_FORMAT = "rsstp-replay table dtypes"
_VERSION = 1
_PARQUET_HINT = "write .parquet instead, which keeps every type"
# Dtypes that CSV carries as text and read_csv parses back exactly (with the sidecar).
_NEVER_MISSING = {"bool", *(f"{sign}int{bits}" for sign in ("", "u") for bits in (8, 16, 32, 64))}
_PLAIN = _NEVER_MISSING | {
    "float32",
    "float64",
    "boolean",
    *(f"{sign}Int{bits}" for sign in ("", "U") for bits in (8, 16, 32, 64)),
    "Float32",
    "Float64",
}


def sidecar_path(path: str | os.PathLike[str]) -> Path:
    """The dtype sidecar of the CSV table at ``path``: ``PATH.dtypes.json``."""
    out = Path(path)
    return out.with_name(out.name + SIDECAR_SUFFIX)


def _format_of(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix not in TABLE_FORMATS:
        raise TableError(
            f"{path}: unknown table format {path.suffix or '(no suffix)'!r}: expected "
            f"{' or '.join(TABLE_FORMATS)}"
        )
    return suffix


def write_table(table: pd.DataFrame, path: str | os.PathLike[str]) -> list[Path]:
    """Write ``table`` to ``path`` whole, as Parquet or CSV by the suffix (a CSV with its
    dtype sidecar, see the module docstring); returns the files written.

    A named index is written as a column of its name; an unnamed one must be the row
    number (``0 .. n - 1``) and is not written. Raises :class:`~rsstp_replay.errors.
    TableError` for a table a file cannot give back as it is (and
    :class:`~rsstp_sim.errors.OutputError` when the write fails: the old files stay).
    """
    out = Path(path)
    fmt = _format_of(out)
    index = _index_name(table, out)
    if fmt == ".parquet":
        write_table_parts([table], out)  # one part: the same file pq.write_table writes
        return [out]
    sidecar = sidecar_path(out)
    dtypes = _sidecar(table, index, out)
    with written_whole(out) as side:
        table.to_csv(side, index=index is not None)
        try:  # renamed into place just before the CSV is
            with written_whole(sidecar) as meta:
                meta.write_text(json.dumps(dtypes, indent=2) + "\n")
        except OutputError:
            side.unlink(missing_ok=True)
            raise
    return [out, sidecar]


def write_table_parts(parts: Iterable[pd.DataFrame], path: str | os.PathLike[str]) -> pd.DataFrame:
    """Write the table made of ``parts`` (consecutive row ranges of one table, the same
    columns and dtypes) to ``path`` as Parquet, a row group per part, each written on a
    second thread while the next part is made: read back, the same table as
    :func:`write_table` of their concatenation. Returns the first part's empty head (the
    columns and the index). An error from ``parts`` or from the write leaves no file, and
    what was at ``path`` as it was."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = Path(path)
    if _format_of(out) != ".parquet":
        raise TableError(f"{out}: a table written in parts goes to Parquet")
    each = iter(parts)
    first = next(each, None)
    if first is None:
        raise TableError(f"{out}: no part to write")
    keep_index = _index_name(first, out) is not None
    with written_whole(out) as side, ThreadPoolExecutor(1, "rsstp-parquet") as thread:
        arrow = pa.Table.from_pandas(first, preserve_index=keep_index)
        schema = arrow.schema
        writer = pq.ParquetWriter(side, schema)
        pending: Future[None] = thread.submit(writer.write_table, arrow)
        try:
            for part in each:
                arrow = pa.Table.from_pandas(part, schema=schema, preserve_index=keep_index)
                pending.result()
                pending = thread.submit(writer.write_table, arrow)
            pending.result()
        except BaseException:
            pending.cancel()
            wait([pending])
            with suppress(Exception):  # (the error that stopped the write is the one to say)
                writer.close()
            side.unlink(missing_ok=True)
            raise
        writer.close()
    return first.iloc[:0]


def _index_name(table: pd.DataFrame, out: Path) -> str | None:
    index = table.index
    if isinstance(index, pd.MultiIndex):
        if out.suffix.lower() == ".parquet":
            raise TableError(f"{out}: a table with a MultiIndex: reset_index() it first")
        raise TableError(f"{out}: a table with a MultiIndex cannot go to CSV: {_PARQUET_HINT}")
    names = [str(name) for name in table.columns]
    if len(set(names)) != len(names) or not all(isinstance(c, str) for c in table.columns):
        raise TableError(f"{out}: the column names must be distinct text, found {names}")
    if index.name is None:
        if not index.equals(pd.RangeIndex(len(table))):
            raise TableError(
                f"{out}: the index is unnamed and is not the row number: name it "
                "(table.index.name = ...) or reset_index(drop=True) it"
            )
        return None
    name = index.name
    if not isinstance(name, str) or name in names:
        raise TableError(f"{out}: the index name {name!r} must be text and not a column's")
    return name


def _sidecar(table: pd.DataFrame, index: str | None, out: Path) -> dict[str, Any]:
    """The sidecar of ``table`` for CSV, or :class:`TableError` with the Parquet hint."""
    columns: list[tuple[str, pd.Series]] = []
    if index is not None:
        columns.append((index, table.index.to_series()))
    columns += [(str(name), table[name]) for name in table.columns]
    dtypes: dict[str, str] = {}
    categories: dict[str, list[str]] = {}
    for name, column in columns:
        dtype = column.dtype
        if isinstance(dtype, pd.CategoricalDtype):
            values = dtype.categories
            if dtype.ordered or pd.api.types.infer_dtype(values, skipna=False) != "string":
                raise TableError(
                    f"{out}: column {name!r} is an ordered or non-text categorical, which CSV "
                    f"cannot keep: {_PARQUET_HINT}"
                )
            dtypes[name] = "category"
            categories[name] = [str(v) for v in values]
        elif str(dtype) in _PLAIN:
            dtypes[name] = str(dtype)
        elif pd.api.types.infer_dtype(column, skipna=False) in {"string", "empty"}:
            dtypes[name] = "str"  # text, without a missing value (or no rows)
        else:
            kind = pd.api.types.infer_dtype(column, skipna=False)
            found = f"{dtype} ({kind})" if str(dtype) != kind else str(dtype)
            raise TableError(
                f"{out}: column {name!r} has dtype {found}, which CSV cannot keep (text with "
                f"a missing value cannot be told from empty text): {_PARQUET_HINT}"
            )
    return {
        "format": _FORMAT,
        "version": _VERSION,
        "index": index,
        "dtypes": dtypes,
        "categories": categories,
    }


def read_table(path: str | os.PathLike[str]) -> pd.DataFrame:
    """A table written by :func:`write_table` (or ``rsstp-replay table``), with its index
    and dtypes: Parquet as it is, CSV through its dtype sidecar. An integer index that is
    ``0 .. n - 1`` comes back as a ``RangeIndex``.

    Raises :class:`~rsstp_replay.errors.TableError` for a missing file, a CSV without its
    sidecar, or a sidecar that does not describe the CSV.
    """
    source = Path(path)
    fmt = _format_of(source)
    if not source.is_file():
        raise TableError(f"{source}: no such table file")
    if fmt == ".parquet":
        table = _read_parquet(source)
    else:
        table = _read_csv(source)
    index = table.index
    if (
        not isinstance(index, pd.MultiIndex | pd.RangeIndex)
        and pd.api.types.is_integer_dtype(index.dtype)
        and index.equals(pd.RangeIndex(len(index)))
    ):
        table.index = pd.RangeIndex(len(index), name=index.name)
    return table


def _read_parquet(source: Path) -> pd.DataFrame:
    import pyarrow.parquet as pq

    try:
        table: pd.DataFrame = pd.read_parquet(source)
        meta = pq.read_schema(source).pandas_metadata or {}
    except (OSError, ValueError) as exc:
        raise TableError(f"{source}: not a readable Parquet table: {exc}") from None
    # pandas 2.2 gives a nullable index back as float64: its dtype is in pandas' metadata.
    dtypes = {c.get("field_name"): c.get("numpy_type") for c in meta.get("columns", ())}
    wanted = (
        dtypes.get(table.index.name) if table.index.name in meta.get("index_columns", ()) else None
    )
    if wanted is not None and wanted != str(table.index.dtype) and wanted in _PLAIN:
        table.index = table.index.astype(wanted)
    return table


def _read_csv(source: Path) -> pd.DataFrame:
    sidecar = sidecar_path(source)
    if not sidecar.is_file():
        raise TableError(
            f"{source}: no dtype sidecar {sidecar.name} beside it, so its types cannot be "
            "restored: write it with rsstp-replay table (which writes the sidecar), or write "
            ".parquet, which keeps every type"
        )
    index, dtypes, categories = _read_sidecar(sidecar)
    try:
        header = list(pd.read_csv(source, nrows=0).columns)
    except (OSError, ValueError) as exc:
        raise TableError(f"{source}: not a readable CSV table: {exc}") from None
    if header != list(dtypes):
        raise TableError(
            f"{source}: its columns {header} are not those its sidecar {sidecar.name} "
            f"describes {list(dtypes)}"
        )
    parse: dict[str, Any] = {}
    missing: dict[str, list[str]] = {}
    for name, dtype in dtypes.items():
        if dtype == "str":
            parse[name] = str  # never missing: an empty field is empty text
            continue
        parse[name] = pd.CategoricalDtype(categories[name]) if dtype == "category" else dtype
        missing[name] = [""]
    # An index column that cannot be missing is read as the index; pandas 2.2 fails on an
    # index column with missing values of its own, so such an index is set afterwards.
    later = index in missing and dtypes[index] not in _NEVER_MISSING
    if index is not None and not later:
        missing.pop(index, None)
    options: dict[str, Any] = {
        "keep_default_na": False,
        "na_values": missing,
        "index_col": None if later else index,
    }
    if pd.__version__.startswith("2."):  # pandas 3 reads floats exactly by default
        options["float_precision"] = "round_trip"
    try:
        table: pd.DataFrame = pd.read_csv(source, dtype=parse, **options)
    except (OSError, ValueError) as exc:
        raise TableError(f"{source}: does not read as its sidecar describes: {exc}") from None
    return table.set_index(index) if later else table


def _read_sidecar(sidecar: Path) -> tuple[str | None, dict[str, str], dict[str, list[str]]]:
    try:
        meta = json.loads(sidecar.read_text())
    except (OSError, ValueError) as exc:
        raise TableError(f"{sidecar}: not a dtype sidecar: {exc}") from None
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT:
        raise TableError(f'{sidecar}: not a dtype sidecar (no "format": {_FORMAT!r})')
    if meta.get("version") != _VERSION:
        raise TableError(
            f"{sidecar}: dtype sidecar version {meta.get('version')!r}: this reader knows "
            f"version {_VERSION}"
        )
    index, dtypes, categories = meta.get("index"), meta.get("dtypes"), meta.get("categories")
    if not (
        (index is None or isinstance(index, str))
        and isinstance(dtypes, dict)
        and all(isinstance(v, str) for v in dtypes.values())
        and isinstance(categories, dict)
        and all(
            isinstance(v, list) and all(isinstance(c, str) for c in v) for v in categories.values()
        )
    ):
        raise TableError(
            f'{sidecar}: expected "index" (a column name or null), "dtypes" (column -> '
            'dtype) and "categories" (column -> list of text)'
        )
    for name, dtype in dtypes.items():
        if dtype == "category" and name not in categories:
            raise TableError(f"{sidecar}: category column {name!r} has no categories")
        if dtype not in _PLAIN | {"category", "str"}:
            raise TableError(f"{sidecar}: column {name!r}: unknown dtype {dtype!r}")
    if index is not None and index not in dtypes:
        raise TableError(f"{sidecar}: the index {index!r} is not one of its columns")
    return index, dtypes, categories
