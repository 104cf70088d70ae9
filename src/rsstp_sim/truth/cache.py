"""The ground truth kept on disk: a scenario's truth is computed once, then read back.

Tabulating a world and minimising it takes seconds for a few hundred thousand poses, and every
audit of every recording of that world needs the same truth. :func:`load_truth` keeps it under
``$XDG_CACHE_HOME/rsstp/truth/`` (``~/.cache/rsstp/truth/`` when the variable is unset), one
file per key. The key is a hash of what makes the world (the body, and every field of its
scenario but the name, the description, the text and the feedback mode) and of the package
version, so a renamed or re-commented scenario shares its entry, and a new version of the
package computes afresh.

An entry is an ``.npz`` archive of plain arrays (no pickles) holding its own key and a SHA-256
of its arrays. It is written to a side file and renamed into place, so a reader never sees half
an entry, and workers of a sweep writing the same entry at once each leave a whole one. An
entry that cannot be read, names another key or fails its checksum is computed again and
replaced, never trusted. A cache folder that cannot be written is no error: the truth is
computed and returned, and nothing is kept.
"""

from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import os
import tempfile
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rsstp_sim.interface import World, WorldScenario
from rsstp_sim.truth._ground_truth import GroundTruth, check_truth_size, compute_truth

__all__ = ["CacheInfo", "cache_info", "truth_cache_dir", "load_truth", "truth_key"]

_ARRAYS = (
    "pose_codes",
    "pose_values",
    "sensation",
    "next_pose",
    "true_class",
    "class_next",
    "class_sensation",
)


def truth_cache_dir() -> Path:
    """Where entries are kept: ``$XDG_CACHE_HOME/rsstp/truth`` (default ``~/.cache``)."""
    base = os.environ.get("XDG_CACHE_HOME") or ""
    root = Path(base) if os.path.isabs(base) else Path.home() / ".cache"
    return root / "rsstp" / "truth"


_NOT_THE_WORLD = frozenset({"name", "description", "source", "origin", "feedback_mode"})
"""Scenario fields that do not change the ground truth (a renamed world keeps its entry)."""


def truth_key(scenario: WorldScenario) -> str:
    """The hash naming a scenario's entry: its body, its world and the package version."""
    from rsstp_sim import __version__

    world = {
        field.name: getattr(scenario, field.name)
        for field in dataclasses.fields(scenario)  # type: ignore[arg-type]
        if field.name not in _NOT_THE_WORLD
    }
    text = json.dumps(
        {"package": __version__, "body": scenario.body, "world": world},
        sort_keys=True,
        separators=(",", ":"),
        default=repr,  # floats exactly (repr), and the bodies' small dataclasses
    )
    return hashlib.sha256(text.encode()).hexdigest()


def load_truth(
    scenario: WorldScenario,
    *,
    cache: bool = True,
    max_poses: int = 2_000_000,
    world: World | None = None,
) -> GroundTruth:
    """The ground truth of ``scenario``: read from the cache when a sound entry is there,
    else computed (:func:`~rsstp_sim.truth.compute_truth`) and kept. ``cache=False`` neither
    reads nor writes the cache. A world over the size bounds is refused either way
    (:func:`~rsstp_sim.truth.check_truth_size`). ``world``: the scenario's world when
    already built (a sweep's worker has its run's): sized and enumerated itself instead of
    by its body."""
    if not cache:
        return compute_truth(scenario, max_poses=max_poses, world=world)
    check_truth_size(scenario, max_poses=max_poses, world=world)
    key = truth_key(scenario)
    path = truth_cache_dir() / f"{key}.npz"
    started = time.perf_counter()
    found = _read(path, key, scenario)
    if found is not None:
        return dataclasses.replace(found, seconds=time.perf_counter() - started)
    truth = compute_truth(scenario, max_poses=max_poses, world=world)
    _write(path, key, truth)
    return truth


@dataclass(frozen=True, slots=True)
class CacheInfo:
    """Where the cache is, whether it can be written, and what it holds."""

    path: Path
    writable: bool
    entries: int
    bytes: int

    def to_text(self) -> str:
        state = "" if self.writable else " (not writable: truths are computed, not kept)"
        noun = "entry" if self.entries == 1 else "entries"
        return f"truth cache: {self.path}{state}: {self.entries:,} {noun}, {self.bytes:,} bytes"

    def to_json(self) -> dict[str, object]:
        return {
            "path": str(self.path),
            "writable": self.writable,
            "entries": self.entries,
            "bytes": self.bytes,
        }


def cache_info() -> CacheInfo:
    """The cache folder and its entries (nothing is created)."""
    path = truth_cache_dir()
    entries = sorted(path.glob("*.npz")) if path.is_dir() else []
    existing = path
    while not existing.exists() and existing != existing.parent:
        existing = existing.parent
    return CacheInfo(
        path=path,
        writable=os.access(existing, os.W_OK),
        entries=len(entries),
        bytes=sum(entry.stat().st_size for entry in entries),
    )


def _digest(arrays: dict[str, np.ndarray]) -> str:
    digest = hashlib.sha256()
    for name in (*_ARRAYS, "actions", "start_index", "value_names", "radices", "units", "wrap"):
        array = np.ascontiguousarray(arrays[name])
        digest.update(f"{name}:{array.dtype.str}:{array.shape}".encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


def _read(path: Path, key: str, scenario: WorldScenario) -> GroundTruth | None:
    """The entry at ``path``, or None when it is missing, unreadable, foreign or damaged."""
    try:
        data = path.read_bytes()
        with np.load(io.BytesIO(data), allow_pickle=False) as archive:
            arrays = {name: archive[name] for name in archive.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError):
        return None
    try:
        if str(arrays["key"]) != key or str(arrays["digest"]) != _digest(arrays):
            return None
        next_pose = arrays["next_pose"].astype(np.int64, copy=False)
        truth = GroundTruth(
            scenario_name=scenario.name,
            actions=tuple(int(a) for a in arrays["actions"]),
            pose_codes=arrays["pose_codes"].astype(np.int64, copy=False),
            pose_values=arrays["pose_values"].astype(np.int64, copy=False),
            sensation=arrays["sensation"].astype(np.bool_, copy=False),
            next_pose=next_pose,
            blocked=next_pose == np.arange(len(next_pose))[:, None],
            start_index=int(arrays["start_index"]),
            true_class=arrays["true_class"].astype(np.int64, copy=False),
            class_next=arrays["class_next"].astype(np.int64, copy=False),
            class_sensation=arrays["class_sensation"].astype(np.bool_, copy=False),
            value_names=tuple(str(name) for name in arrays["value_names"]),
            radices=tuple(int(r) for r in arrays["radices"]),
            units=tuple(int(u) for u in arrays["units"]),
            wrap=bool(arrays["wrap"]),
        )
    except (KeyError, ValueError, TypeError):
        return None
    if truth.actions != tuple(scenario.actions) or not _consistent(truth):
        return None
    return truth


def _consistent(truth: GroundTruth) -> bool:
    """The arrays fit together (a checksum can be right about a file written by a bug)."""
    poses, classes, width = truth.n_poses, truth.n_classes, len(truth.actions)
    return bool(
        poses > 0
        and truth.next_pose.shape == (poses, width)
        and truth.pose_values.shape == (poses, truth.n_values)
        and len(truth.value_names) == len(truth.units) == truth.n_values
        and truth.sensation.shape == truth.true_class.shape == (poses,)
        and truth.class_next.shape == (classes, width)
        and 0 <= truth.start_index < poses
        and truth.next_pose.min() >= 0
        and truth.next_pose.max() < poses
        and truth.true_class.min() >= 0
        and truth.true_class.max() < classes
        and truth.class_next.min() >= 0
        and truth.class_next.max() < classes
    )


def _write(path: Path, key: str, truth: GroundTruth) -> None:
    """Keep ``truth`` at ``path`` through a side file; a folder that cannot be written keeps
    nothing."""
    arrays: dict[str, np.ndarray] = {
        "pose_codes": truth.pose_codes,
        "pose_values": truth.pose_values,
        "sensation": truth.sensation,
        "next_pose": truth.next_pose,
        "true_class": truth.true_class,
        "class_next": truth.class_next,
        "class_sensation": truth.class_sensation,
        "actions": np.asarray(truth.actions, np.int64),
        "start_index": np.asarray(truth.start_index, np.int64),
        "value_names": np.asarray(truth.value_names, np.str_),
        "radices": np.asarray(truth.radices, np.int64),
        "units": np.asarray(truth.units, np.int64),
        "wrap": np.asarray(truth.wrap),
    }
    arrays["digest"] = np.asarray(_digest(arrays))
    arrays["key"] = np.asarray(key)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)  # type: ignore[arg-type]  # (the stubs type a keyword as allow_pickle)
    side: str | None = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(
            dir=path.parent, prefix=f".{key[:12]}-", suffix=".tmp", delete=False
        ) as handle:
            side = handle.name
            handle.write(buffer.getbuffer())
        os.replace(side, path)
        side = None
    except OSError:
        return
    finally:
        if side is not None:
            try:
                os.unlink(side)
            except OSError:
                pass
