"""Counts in what the commands print: ``1 state``, ``2 states``, ``100,001 steps``.

Every number of things a message or a report shows goes through :func:`counted`, so the noun
agrees with the number and a large number has its thousands separators.
"""

from __future__ import annotations

__all__ = ["counted"]


def counted(count: int, noun: str, plural: str | None = None) -> str:
    """``count`` with thousands separators, then ``noun``, or ``plural`` (default ``noun`` +
    ``s``) unless ``count`` is 1."""
    return f"{count:,} {noun if count == 1 else plural or noun + 's'}"
