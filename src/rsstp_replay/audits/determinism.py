"""The determinism audit: how did the learned model's determinism evolve over a run?

For every model version of a recording (each ``/rsstp/model`` message: the model after a change)
the audit lists the (state, action) pairs with several successors (*nondeterministic*) and the
pairs, over the model's action alphabet, with none (*empty*).

What a finding says about the strategy:

- A nondeterministic pair means the model does not know where the action leads: the runner
  picks one successor at random, so the internal state the agent ends up in is a guess. A split
  (thesis 3.1.1) makes every pair into and out of the split state nondeterministic; a strategy
  that learns is expected to resolve them with deletes soon after.
- An empty pair means the model has no transition for an action: taking it leaves the internal
  state where it is (a ``no_transition`` step). The model is then *incomplete*: it cannot
  predict that move at all.
- ``deterministic_from`` is the first step from which the model stayed deterministic until the
  end of the recording (None when the final model is nondeterministic): when the strategy
  stopped guessing. ``first_complete_step`` is the first step at which the model was both
  deterministic and complete (one successor for every pair), a finished automaton, even if a
  later change broke it again; ``complete_from`` is the first step from which it stayed so.

The models are rebuilt incrementally, once, by the model history
(:func:`~rsstp_replay.reader.model_history`; a recording's as it was read): the first version
from its snapshot, each later one by applying the operations its message carries to the
previous one, and each version keeps the pairs of the states its operations touched
(:meth:`~rsstp_replay.reader.ModelHistory.determinism_changes`), which the audit adds up. A
message whose operations do not lead to its own model (another version number, other states,
another number of nondeterministic pairs) raises :class:`~rsstp_sim.errors.ModelError`: the
audit fails loudly on a recording it cannot trust.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import pandas as pd

from rsstp_format.records import ModelRecord
from rsstp_replay.reader import DeterminismPart, model_history
from rsstp_sim.errors import ModelError
from rsstp_sim.transition_system import DeterminismReport
from rsstp_sim.words import counted

__all__ = [
    "DeterminismFindings",
    "HasModelVersions",
    "VersionDeterminism",
    "audit_determinism",
]

NondeterministicPair = tuple[int, int, tuple[int, ...]]
"""``(state, action, successors)``: a pair with more than one successor."""
EmptyPair = tuple[int, int]
"""``(state, action)``: a pair with no successor."""

_TEXT_LIMIT = 20
"""How many pairs of each kind ``to_text`` lists before saying how many more there are."""


class HasModelVersions(Protocol):
    """Anything that can hand out the model messages of a run, in order (a recording)."""

    def model_versions(self) -> Sequence[ModelRecord]: ...


@dataclass(frozen=True, slots=True, kw_only=True)
class VersionDeterminism(DeterminismReport):
    """The determinism of one model version, the model after step ``step``: a
    :class:`~rsstp_sim.transition_system.DeterminismReport` (``nondeterministic`` lists
    ``(state, action, successors)`` and ``empty`` lists ``(state, action)``, both sorted) with
    the version's place and size."""

    version: int
    step: int
    states: int
    transitions: int

    def to_json(self, *, pairs: bool = True) -> dict[str, Any]:
        """A JSON-ready dict; without ``pairs`` only the counts."""
        result: dict[str, Any] = {
            "version": self.version,
            "step": self.step,
            "states": self.states,
            "transitions": self.transitions,
            "deterministic": self.deterministic,
            "complete": self.complete,
            "nondeterministic_pairs": len(self.nondeterministic),
            "empty_pairs": len(self.empty),
        }
        if pairs:
            result["nondeterministic"] = [
                {"state": s, "action": a, "successors": list(targets)}
                for s, a, targets in self.nondeterministic
            ]
            result["empty"] = [{"state": s, "action": a} for s, a in self.empty]
        return result


@dataclass(frozen=True, slots=True)
class DeterminismFindings:
    """The determinism audit over every model version of a run (see the module docstring).

    ``versions`` is in recording order; the last one is the final model, which holds until the
    end of the recording.
    """

    versions: tuple[VersionDeterminism, ...]

    @property
    def final(self) -> VersionDeterminism:
        """The final model (the last version)."""
        return self.versions[-1]

    @property
    def deterministic_from(self) -> int | None:
        """The first step from which the model stayed deterministic until the end; None when
        the final model is nondeterministic."""
        return _stayed_from(self.versions, deterministic_only=True)

    @property
    def complete_from(self) -> int | None:
        """The first step from which the model stayed deterministic and complete until the
        end; None when the final model is not."""
        return _stayed_from(self.versions, deterministic_only=False)

    @property
    def first_complete_step(self) -> int | None:
        """The first step at which the model was deterministic and complete; None if never."""
        return next((version.step for version in self.versions if version.complete), None)

    @property
    def nondeterministic_versions(self) -> int:
        """How many versions were nondeterministic."""
        return sum(not version.deterministic for version in self.versions)

    def to_frame(self) -> pd.DataFrame:
        """One row per version: ``version``, ``step``, ``states``, ``transitions``,
        ``nondeterministic_pairs``, ``empty_pairs`` (int64) and ``deterministic`` (bool)."""
        columns: dict[str, list[Any]] = {
            "version": [v.version for v in self.versions],
            "step": [v.step for v in self.versions],
            "states": [v.states for v in self.versions],
            "transitions": [v.transitions for v in self.versions],
            "nondeterministic_pairs": [len(v.nondeterministic) for v in self.versions],
            "empty_pairs": [len(v.empty) for v in self.versions],
            "deterministic": [v.deterministic for v in self.versions],
        }
        frame = pd.DataFrame(columns)
        return frame.astype(
            {name: "int64" for name in list(columns)[:-1]} | {"deterministic": bool}
        )

    def to_text(self) -> str:
        """Human readable: the verdict, when it was reached, then the final model's pairs."""
        final = self.final
        several, empty = len(final.nondeterministic), len(final.empty)
        verdict = (
            "deterministic"
            if not several
            else f"nondeterministic ({_plural(several, 'pair')} with several successors)"
        )
        complete = (
            "every pair has a successor"
            if not empty
            else f"{_plural(empty, 'pair')} with no successor"
        )
        lines = [
            f"final model (version {final.version}, step {final.step}): "
            f"{_plural(final.states, 'state')}, {_plural(final.transitions, 'transition')}; "
            f"{verdict}, {complete}",
            f"versions: {len(self.versions)}, nondeterministic: {self.nondeterministic_versions}",
        ]
        since = self.deterministic_from
        lines.append(
            "nondeterministic at the end"
            if since is None
            else f"deterministic from step {since} to the end"
        )
        first = self.first_complete_step
        if first is None:
            lines.append("never deterministic and complete")
        else:
            stayed = self.complete_from
            end = ", not at the end" if stayed is None else f"; from step {stayed} to the end"
            lines.append(f"first deterministic and complete at step {first}{end}")
        lines += _pair_lines(
            "pairs with several successors",
            [
                f"state {s} action {a} -> {list(targets)}"
                for s, a, targets in final.nondeterministic
            ],
        )
        lines += _pair_lines(
            "pairs with no successor", [f"state {s} action {a}" for s, a in final.empty]
        )
        return "\n".join(lines)

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict: the verdicts, one row of counts per version, and the final
        model's pairs (every version's pairs are in :attr:`versions`)."""
        return {
            "final_deterministic": self.final.deterministic,
            "final_complete": self.final.complete,
            "deterministic_from": self.deterministic_from,
            "complete_from": self.complete_from,
            "first_complete_step": self.first_complete_step,
            "nondeterministic_versions": self.nondeterministic_versions,
            "final": self.final.to_json(),
            "versions": [version.to_json(pairs=False) for version in self.versions],
        }


def audit_determinism(
    source: HasModelVersions | Sequence[ModelRecord],
) -> DeterminismFindings:
    """The determinism of every model version (see the module docstring).

    ``source`` is a recording (anything with ``model_versions()``) or the model messages
    themselves, in order. Raises :class:`~rsstp_sim.errors.ModelError` when there is no model
    message, or when a message's operations do not lead from the previous model to its own.
    """
    versions = source if isinstance(source, Sequence) else source.model_versions()
    if not versions:
        raise ModelError("determinism audit: no model message (a recording has one at step 0)")
    # Each version's changed states and their pairs, kept as the history was rebuilt (a
    # recording's as it was read): no model rebuilt here.
    history = model_history(versions)
    found = []
    rows: dict[int, DeterminismPart] = {}  # the states with a pair of several successors
    report = DeterminismReport((), ())  # or of none, and their pairs
    sizes = zip(*(column.tolist() for column in history.sizes()), strict=True)
    for k, (record, (n_states, n_transitions)) in enumerate(zip(history.heads, sizes, strict=True)):
        touched = False
        for s, part in history.determinism_changes(k).items():
            if part is not None:
                rows[s] = part
                touched = True
            elif rows.pop(s, None) is not None:
                touched = True
        if touched:  # (states in order, as the model's own report lists them)
            ordered = sorted(rows)
            report = DeterminismReport(
                tuple(pair for s in ordered for pair in rows[s][0]),
                tuple(pair for s in ordered for pair in rows[s][1]),
            )
        if len(report.nondeterministic) != record.nondeterministic_pairs:
            raise ModelError(
                f"model version {record.version} (step {record.step}) has "
                f"{len(report.nondeterministic)} pairs with several successors, the message "
                f"says {record.nondeterministic_pairs}"
            )
        found.append(
            VersionDeterminism(
                version=record.version,
                step=record.step,
                states=n_states,
                transitions=n_transitions,
                nondeterministic=report.nondeterministic,
                empty=report.empty,
            )
        )
    return DeterminismFindings(tuple(found))


def _stayed_from(versions: Sequence[VersionDeterminism], *, deterministic_only: bool) -> int | None:
    since = None
    for version in reversed(versions):
        if not (version.deterministic if deterministic_only else version.complete):
            break
        since = version.step
    return since


def _pair_lines(title: str, items: list[str]) -> list[str]:
    if not items:
        return []
    lines = [f"{title} in the final model: {len(items)}"]
    lines += [f"  {item}" for item in items[:_TEXT_LIMIT]]
    if len(items) > _TEXT_LIMIT:
        lines.append(f"  ... and {len(items) - _TEXT_LIMIT} more")
    return lines


_plural = counted
