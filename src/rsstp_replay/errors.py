"""The replay side's exception hierarchy, and the warning for unfinished recordings.

Every message is one line: the file, what was expected, what was found and where (byte
offset, step) when it is known.
"""

from __future__ import annotations

from rsstp_sim.errors import RsstpError

__all__ = [
    "ViewerWarning",
    "CorruptRecording",
    "ForeignRecording",
    "NotARecording",
    "ReplayError",
    "StepOutOfRange",
    "TableError",
    "UnfinishedRecordingWarning",
    "UnsupportedVersion",
]


class ReplayError(RsstpError):
    """Root of every error the replay side raises on purpose."""


class NotARecording(ReplayError):
    """The path does not exist, is not a readable file, or is not an MCAP file at all."""


class ForeignRecording(ReplayError):
    """An MCAP file, but not one of ours: it has no ``/rsstp/*`` topic."""


class UnsupportedVersion(ReplayError):
    """A schema of the recording has a major version this reader does not know."""


class CorruptRecording(ReplayError):
    """Damaged bytes (CRC failure, undecodable record) or a message that breaks the contract."""


class StepOutOfRange(ReplayError):
    """A step index outside ``0 .. n_steps`` of the recording."""


class TableError(ReplayError):
    """A table that cannot be written or read back with its types (a CSV without its dtype
    sidecar, a dtype CSV cannot keep, an unknown format)."""


class UnfinishedRecordingWarning(UserWarning):
    """The file has no footer (the writer was killed): only its complete chunks were read."""


class ViewerWarning(UserWarning):
    """Something the viewer could not show as asked; it showed what it could instead."""


class BadStep(Exception):
    """A step message breaks the contract: ``index`` in the last batch, or ``step``. Internal:
    the reader turns it into :class:`CorruptRecording` with the file and the step."""

    def __init__(self, text: str, *, index: int | None = None, step: int | None = None) -> None:
        super().__init__(text)
        self.text = text
        self.index = index
        self.step = step


class PhysicsDifference(Exception):
    """The recorded world differs from the re-simulated one at ``step`` (None: the scenario),
    in ``field``. Internal: :func:`rsstp_replay.audits.physics.check_physics` turns it into its
    findings."""

    def __init__(self, step: int | None, field: str, difference: str) -> None:
        super().__init__(difference)
        self.step, self.field, self.difference = step, field, difference
