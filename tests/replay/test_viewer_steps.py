"""The steps table the viewer keeps while it logs (``viewer._narrowed``): narrower, the same
values, and the same ``.rrd``."""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path

import pandas as pd
import pytest
from rerun.chunk import RrdReader

from rsstp_replay import viewer
from rsstp_replay.reader.recording import open_recording
from rsstp_replay.viewer import view

LEARNER = Path(__file__).parents[2] / "recordings" / "two-joint-30-learner.mcap"
REFERENCE = Path(__file__).parents[2] / "recordings" / "three-joint-random.mcap"


@pytest.mark.parametrize("path", [LEARNER, REFERENCE], ids=["learner", "reference"])
def test_the_kept_table_has_every_value_in_columns_no_wider(path: Path) -> None:
    with open_recording(path) as recording:
        steps = recording.steps()
    kept = viewer._narrowed(steps)
    assert list(kept.columns) == [c for c in steps.columns if c not in viewer._UNREAD_COLUMNS]
    assert kept.index.equals(steps.index)
    for name in kept.columns:
        pd.testing.assert_series_equal(kept[name], steps[name], check_dtype=False)
        if pd.api.types.is_integer_dtype(steps[name].dtype):
            assert kept[name].dtype.itemsize <= steps[name].dtype.itemsize, name
    # The reader's int64 ids and nullable indices are narrowed (so the test sees the dtypes
    # change, not a table passed through).
    assert kept["internal_state"].dtype.itemsize < 8
    assert kept["action"].dtype == pd.Int8Dtype()


def _rows(path: Path) -> dict[str, list[str]]:
    """Every row of every entity of an ``.rrd`` (row ids left out), sorted: what it shows,
    however Rerun cut it into chunks."""
    found: dict[str, list[str]] = defaultdict(list)
    for chunk in RrdReader(path).stream().to_chunks():
        batch = chunk.to_record_batch()
        names = [n for n in batch.schema.names if n != "rerun.controls.RowId"]
        columns = {n: batch.column(n).to_pylist() for n in names}
        where = ("static " if chunk.is_static else "") + chunk.entity_path
        found[where] += [repr([(n, columns[n][i]) for n in names]) for i in range(len(batch))]
    return {where: sorted(rows) for where, rows in found.items()}


def test_the_rrd_is_the_same_as_from_the_whole_table(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Viewed from the narrowed table or the reader's own, every entity has the same rows
    (an overview with thinned series too); the recording's name aside (it says the path)."""
    monkeypatch.setattr(viewer, "OVERVIEW_MAX_STEPS", 2_000)
    monkeypatch.setattr(viewer.plots_part, "SERIES_MAX_ROWS", 500)
    files = {}
    for name, narrowed in (("narrow", viewer._narrowed), ("whole", lambda steps: steps)):
        monkeypatch.setattr(viewer, "_narrowed", narrowed)
        files[name] = tmp_path / f"{name}.rrd"
        with open_recording(LEARNER) as recording:
            result = view(
                recording, save=files[name], spawn=False, serve_web=False, start=None, end=None
            )
        assert result.summary.every > 1 and result.summary.thinned
    narrow, whole = _rows(files["narrow"]), _rows(files["whole"])
    assert narrow.keys() == whole.keys()
    for where in whole:
        if where != "static /__properties":
            assert narrow[where] == whole[where], where
    assert sum(map(len, whole.values())) > 1_000
    assert len(narrow["/log/audit"]) == len(whole["/log/audit"]) > 0
