"""RSSTP replay: read recordings, reconstruct memory and model, audit, export, view.

:func:`open_recording` opens an MCAP recording written by ``rsstp-sim record``; the
:class:`Recording` gives its steps table, the agent's memory, the model at any step and the
events. Problems with a file raise a :class:`ReplayError` subclass; a file whose writer was
killed is read up to its last complete chunk, with an :class:`UnfinishedRecordingWarning`.
:mod:`rsstp_replay.export.tables` gives the tables of a recording for pandas; :func:`write_table`
and :func:`read_table` (:mod:`rsstp_replay.export.table_files`) write one to Parquet or CSV and read
it back with its index and dtypes.
"""

from rsstp_replay.errors import (
    CorruptRecording,
    ForeignRecording,
    NotARecording,
    ReplayError,
    StepOutOfRange,
    TableError,
    UnfinishedRecordingWarning,
    UnsupportedVersion,
)
from rsstp_replay.export.table_files import read_table, write_table
from rsstp_replay.reader.recording import EVENT_KINDS, Recording, open_recording

__all__ = [
    "EVENT_KINDS",
    "CorruptRecording",
    "ForeignRecording",
    "NotARecording",
    "Recording",
    "ReplayError",
    "StepOutOfRange",
    "TableError",
    "UnfinishedRecordingWarning",
    "UnsupportedVersion",
    "open_recording",
    "read_table",
    "write_table",
]
