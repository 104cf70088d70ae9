"""RSSTP replay: read recordings, reconstruct memory and model, audit, export, view.

:func:`open_recording` opens an MCAP recording written by ``rsstp-sim record``; the
:class:`Recording` gives its steps table, the agent's memory, the model at any step and the
events. Problems with a file raise a :class:`ReplayError` subclass; a file whose writer was
killed is read up to its last complete chunk, with an :class:`UnfinishedRecordingWarning`.
"""

from rsstp_replay.errors import (
    CorruptRecording,
    ForeignRecording,
    NotARecording,
    ReplayError,
    StepOutOfRange,
    UnfinishedRecordingWarning,
    UnsupportedVersion,
)
from rsstp_replay.recording import EVENT_KINDS, Recording, open_recording

__all__ = [
    "EVENT_KINDS",
    "CorruptRecording",
    "ForeignRecording",
    "NotARecording",
    "Recording",
    "ReplayError",
    "StepOutOfRange",
    "UnfinishedRecordingWarning",
    "UnsupportedVersion",
    "open_recording",
]
