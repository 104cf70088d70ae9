"""The thesis's ``compare`` (section 4.2), offline: two sub-memories of a recording.

For a researcher, ``compare(n, m)`` asks whether the agent's own data says anything about the
internal states at times ``n`` and ``m``. Walking both sub-memories in step, the first entry
where they differ decides:

- *unknown*: the actions differ first; the two histories took different paths, so they say
  nothing about each other;
- *different (state)*: same actions, but the model already put the two histories in different
  internal states before any sensation told them apart;
- *different (sensation)*: same actions and internal states, then different sensations: the
  model labels two situations alike that the world proves different. With a deterministic
  model this is the evidence for a split (and it is what the consistency audit finds for every
  pair at once);
- *unknown (identical)*: no difference to the end of the shorter sub-memory: nothing against
  treating the two as the same state (a merge), though nothing proves it either.

The answers are exactly those of the live :meth:`rsstp_sim.memory.Memory.compare` (it is called
on the memory the recording holds); only the findings object is added, for text and JSON.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

from rsstp_sim.memory import CompareKind, Memory
from rsstp_sim.words import counted

__all__ = ["CompareFindings", "HasMemory", "compare"]


class HasMemory(Protocol):
    """Anything that can hand out the agent's memory (a recording, or a test's fake)."""

    def memory(self) -> Memory: ...


_KIND_TEXT = {
    CompareKind.UNKNOWN: "unknown (the actions differ)",
    CompareKind.DIFFERENT_STATE: "different (state)",
    CompareKind.DIFFERENT_SENSATION: "different (sensation)",
    CompareKind.IDENTICAL: "unknown (identical)",
}


@dataclass(frozen=True, slots=True)
class CompareFindings:
    """The answer of ``compare(n, m)`` as in :class:`rsstp_sim.memory.CompareResult`.

    ``offset`` is where the kind was decided (entries ``n + offset`` and ``m + offset``); for
    :attr:`~rsstp_sim.memory.CompareKind.IDENTICAL` it equals ``length``, the length of both
    sub-memories (``T + 1 - max(n, m)``).
    """

    kind: CompareKind
    offset: int
    length: int
    n: int
    m: int

    @property
    def decided_at(self) -> tuple[int, int] | None:
        """The two entries (steps) where the kind was decided; None when identical."""
        if self.kind is CompareKind.IDENTICAL:
            return None
        return (self.n + self.offset, self.m + self.offset)

    def to_text(self) -> str:
        """One line: the kind, and where it was decided."""
        head = f"compare({self.n}, {self.m}): {_KIND_TEXT[self.kind]}"
        where = self.decided_at
        if where is None:
            entries = counted(self.length, "entry", "entries")
            return f"{head}: no difference over the {entries} of both sub-memories"
        return (
            f"{head} at offset {self.offset} (steps {where[0]} and {where[1]}); "
            f"sub-memories of {counted(self.length, 'entry', 'entries')}"
        )

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict; ``kind`` is the :class:`CompareKind` value (``"unknown"``, ...)."""
        return {
            "kind": self.kind.value,
            "offset": self.offset,
            "length": self.length,
            "n": self.n,
            "m": self.m,
        }


def compare(source: Memory | HasMemory, n: int, m: int) -> CompareFindings:
    """Compare the sub-memories starting at entries ``n`` and ``m`` (see the module docstring).

    ``source`` is a :class:`~rsstp_sim.memory.Memory` or anything with a ``memory()`` method
    (a recording). Raises :class:`~rsstp_sim.errors.MemoryRangeError` when ``n == m`` or either
    is outside ``0 .. T``, as the live compare does.
    """
    memory = source if isinstance(source, Memory) else source.memory()
    result = memory.compare(n, m)
    return CompareFindings(result.kind, result.offset, result.length, result.n, result.m)
