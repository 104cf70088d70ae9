"""How deeply a text's brackets nest, measured before it is parsed.

Python's TOML and JSON parsers recurse once per level of nesting: a file nested a few
thousand deep ends in a ``RecursionError`` (a traceback of thousands of lines) instead of a
parse error. Every TOML and JSON text a user gives (a scenario, a sweep file, ``--matrix``,
``--param``) is measured here first and refused past :data:`MAX_NESTING` levels, in one line.

The measure counts every ``[`` and ``{`` as one level in and every ``]`` and ``}`` as one
out, inside strings too: it can only overstate the nesting, and no text this project reads
nests anywhere near the limit (a scenario nests three deep).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_NESTING", "nesting_depth", "too_deep"]

MAX_NESTING = 100
"""The deepest nesting of brackets and braces a TOML or JSON text given by a user may have."""

_DELTA = np.zeros(256, np.int64)
_DELTA[[ord("["), ord("{")]] = 1
_DELTA[[ord("]"), ord("}")]] = -1


def nesting_depth(text: str | bytes) -> int:
    """The deepest running count of open brackets and braces in ``text``."""
    data = text.encode("utf-8", "surrogatepass") if isinstance(text, str) else text
    if not data:
        return 0
    depth = np.cumsum(_DELTA[np.frombuffer(data, np.uint8)])
    return max(0, int(depth.max()))


def too_deep(text: str | bytes) -> str | None:
    """One line when ``text`` nests deeper than :data:`MAX_NESTING`, else None."""
    depth = nesting_depth(text)
    if depth <= MAX_NESTING:
        return None
    return f"nested {depth:,} levels deep, more than the {MAX_NESTING} this reader takes"
