"""The root of every error the project raises on purpose, and the file format's own."""

from __future__ import annotations

__all__ = ["RecordFormatError", "RsstpError"]


class RsstpError(Exception):
    """Root of every error this project raises on purpose."""


class RecordFormatError(RsstpError):
    """A message does not have the shape of its record: the message names the field path."""
