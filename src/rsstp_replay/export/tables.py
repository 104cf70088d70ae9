"""The tables of a recording for pandas, one per channel (``rsstp-replay table FILE -o OUT
--what WHAT``):

- ``steps``: :meth:`~rsstp_replay.Recording.steps`, indexed by ``step`` (with ``--truth``,
  :func:`~rsstp_replay.audits.truth_table`);
- ``model``: :func:`model_table`, one row per transition of every model version;
- ``changes``: :func:`changes_table`, one row per operation on the model (what grows with the
  learning, where ``model`` grows with the versions times the model's size);
- ``events``: :meth:`~rsstp_replay.Recording.events`, one row per event;
- ``scenario``: :func:`scenario_table`, one row: the ``/rsstp/scenario`` message.

Their columns are named the same way for every scenario, so the tables of several recordings
concatenate. :mod:`rsstp_replay.export.table_files` writes them to Parquet or CSV and reads
them back with their types.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from itertools import chain
from typing import Any, Protocol

import numpy as np
import pandas as pd  # type: ignore[import-untyped,unused-ignore]

from rsstp_format.records import ModelRecord, ScenarioMessage
from rsstp_replay.errors import TableError
from rsstp_replay.reader import version_heads
from rsstp_replay.reader.recording import Recording

__all__ = ["TABLES", "changes_table", "model_table", "recording_table", "scenario_table"]

TABLES = ("steps", "model", "changes", "events", "scenario")
"""What ``rsstp-replay table --what`` writes (the channels of a recording)."""


class _Models(Protocol):
    def model_versions(self) -> Sequence[ModelRecord]: ...


class _Scenario(Protocol):
    @property
    def scenario_record(self) -> ScenarioMessage: ...


def model_table(source: _Models) -> pd.DataFrame:
    """Every model version's transitions, one row per transition (long form):

    - ``version`` (int64), ``step`` (int64, the step whose end it came into force at) and
      ``states`` (int64, how many states it has);
    - ``source``, ``action``, ``target`` (nullable Int64): one transition
      ``source -action-> target``, in the order of the model message. A version without
      transitions has one row with the three missing, so every version has a row.

    ``model.groupby("version")["source"].count()`` is the number of transitions of each
    version; ``model.loc[model["version"] == v]`` is version ``v``.
    """
    versions = source.model_versions()
    n = len(versions)
    counts = np.fromiter((len(r.transitions) for r in versions), np.int64, n)
    rows = np.maximum(counts, 1)
    total = int(counts.sum())
    has = np.repeat(counts > 0, rows)
    values = np.full((int(rows.sum()), 3), -1, np.int64)
    for k, name in enumerate(("source", "action", "target")):
        values[has, k] = np.fromiter(
            chain.from_iterable(getattr(r.transitions, name) for r in versions), np.int64, total
        )
    columns: dict[str, Any] = {
        name: np.repeat(np.fromiter(map(get, versions), np.int64, n), rows)
        for name, get in (
            ("version", lambda r: r.version),
            ("step", lambda r: r.step),
            ("states", lambda r: len(r.states)),
        )
    }
    for k, name in enumerate(("source", "action", "target")):
        columns[name] = pd.arrays.IntegerArray(np.ascontiguousarray(values[:, k]), ~has)
    return pd.DataFrame(columns)


def changes_table(source: _Models) -> pd.DataFrame:
    """Every operation on the model, in order, one row each (read from the model messages'
    operations: no version is rebuilt):

    - ``version`` (int64, the version the message that holds it made) and ``step`` (int64);
    - ``kind`` (string: split, merge, add or delete) and ``changed`` (bool: whether it
      changed the model; an ``add`` of a transition already there does not);
    - ``source``, ``target``, ``action``, ``result`` (nullable Int64): a ``split`` of
      ``source`` made state ``result``; a ``merge`` moved ``target``'s transitions to
      ``source`` (``result``) and removed ``target``; an ``add`` or ``delete`` is of the
      transition ``source -action-> target``.

    ``changes.loc[changes["kind"] == "split"].groupby("step").size()`` counts the new states
    of each step.
    """
    heads = version_heads(source.model_versions())
    columns: dict[str, list[Any]] = {
        name: [] for name in ("version", "step", "kind", "source", "target", "action", "result")
    }
    changed: list[bool] = []
    for record in heads:
        for operation in record.operations:
            args, kind = operation.args, operation.kind
            columns["version"].append(record.version)
            columns["step"].append(record.step)
            columns["kind"].append(kind)
            columns["source"].append(args[0])
            columns["target"].append(args[1] if len(args) > 1 else None)
            columns["action"].append(args[2] if len(args) > 2 else None)
            columns["result"].append(operation.result)
            changed.append(operation.changed)
    table: dict[str, Any] = {
        "version": np.asarray(columns["version"], np.int64),
        "step": np.asarray(columns["step"], np.int64),
        "kind": pd.array(columns["kind"], dtype="str"),
        "changed": np.asarray(changed, np.bool_),
    }
    for name in ("source", "target", "action", "result"):
        table[name] = pd.array(columns[name], dtype="Int64")
    return pd.DataFrame(table)


def scenario_table(source: _Scenario) -> pd.DataFrame:
    """The ``/rsstp/scenario`` message as one row: a column per field of its JSON
    (``schemas/``), a nested object's fields flattened with ``_`` (``feedback_mode``,
    ``strategy_name``), numbers, booleans and text with their types, every array as its JSON
    text (``lengths``: ``"[3.0,2.0,1.0]"``; ``json.loads`` reads it), a field that is null or
    absent left out. The tables of several recordings concatenate into one row per run.
    """
    row: dict[str, Any] = {}
    _flatten(source.scenario_record.to_json(), "", row)
    return pd.DataFrame({name: [value] for name, value in row.items()})


def _flatten(data: dict[str, Any], prefix: str, row: dict[str, Any]) -> None:
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            _flatten(value, f"{name}_", row)
        elif isinstance(value, list):
            row[name] = json.dumps(value, separators=(",", ":"))
        elif value is not None:
            row[name] = value


def recording_table(
    recording: Recording, what: str = "steps", *, truth: bool = False, truth_cache: bool = True
) -> pd.DataFrame:
    """The table ``what`` (one of :data:`TABLES`) of a recording; ``truth=True`` (steps only)
    adds the ground truth of every step (:func:`~rsstp_replay.audits.truth_table`)."""
    if what not in TABLES:
        raise TableError(f"unknown table {what!r}: expected one of {', '.join(TABLES)}")
    if truth and what != "steps":
        raise TableError(f"the ground truth goes with the steps table, not the {what} table")
    if what == "steps":
        if truth:
            from rsstp_replay.audits import truth_table

            return truth_table(recording, truth=recording.ground_truth(cache=truth_cache))
        return recording.steps()
    if what == "model":
        return model_table(recording)
    if what == "changes":
        return changes_table(recording)
    if what == "events":
        return recording.events()
    return scenario_table(recording)
