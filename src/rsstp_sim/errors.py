"""The simulator's exception hierarchy: one root, one subclass per condition.

The root (:class:`RsstpError`) and the recording format's error (:class:`RecordFormatError`)
are the file format's (:mod:`rsstp_format.errors`), the floor both packages stand on.
"""

from __future__ import annotations

from rsstp_format.errors import RecordFormatError, RsstpError

__all__ = [
    "RsstpError",
    "ScenarioError",
    "ModelError",
    "MemoryRangeError",
    "StrategyError",
    "GraphvizFailed",
    "OutputError",
    "RecordingError",
    "RecordingWriteError",
    "ChunkProcessFailed",
    "ActionError",
    "EnvError",
    "RecordFormatError",
    "TruthError",
    "UnknownPose",
    "UsageError",
]


class ScenarioError(RsstpError):
    """A scenario file or built-in name is invalid; the message names file, key path and problem."""


class ModelError(RsstpError):
    """An operation on a transition system refers to a state or action it does not have."""


class MemoryRangeError(RsstpError):
    """A memory index (for example in ``compare``) is out of range or otherwise invalid."""


class StrategyError(RsstpError):
    """A strategy name is unknown, its parameters are invalid, or it returned an invalid action."""


class OutputError(RsstpError):
    """An output file could not be written whole (a full disk, a file-size limit, ...)."""


class GraphvizFailed(RsstpError):
    """Graphviz failed to lay out or draw a graph (the message has its first error)."""


class RecordingError(RsstpError):
    """A recording cannot be written (existing output, unwritable directory, ...)."""


class RecordingWriteError(RecordingError):
    """Writing a recording failed part way (a full disk, a file-size limit, an I/O error);
    ``safe_steps`` are in complete chunks of the side file, which a reader recovers."""

    def __init__(self, message: str, *, safe_steps: int, side_file: str) -> None:
        super().__init__(message)
        self.safe_steps = safe_steps
        self.side_file = side_file


class ChunkProcessFailed(RecordingError):
    """The helper process that builds a long run's chunks failed, or ended before the run."""


class ActionError(RsstpError):
    """An action is not one of the scenario's actions."""


class UsageError(RsstpError):
    """A command-line argument is invalid."""


class TruthError(RsstpError):
    """The ground truth cannot be computed (pose space too large) or does not know a pose."""


class EnvError(RsstpError, ValueError):
    """An argument of the Gymnasium environment is invalid (a ``ValueError`` too, as
    Gymnasium's users expect)."""


class UnknownPose(RsstpError, KeyError):
    """A pose code the world has not reached (a ``KeyError`` too: a lookup that missed)."""
