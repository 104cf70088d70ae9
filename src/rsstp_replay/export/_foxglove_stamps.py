"""The scene's per-step messages as protobuf bytes: a pose's encoding, with the step's stamp.

A ``foxglove.SceneUpdate`` of one entity and a ``foxglove.FrameTransforms`` differ from step
to step, for a pose the arm comes back to, only in their timestamps, and a timestamp is the
first field of a ``SceneEntity`` and of a ``FrameTransform`` (field 1). So foxglove-sdk
encodes each pose's entity and transforms once without a timestamp, and a step's message is
the timestamp's field put in front of each, with the length prefixes that follow (protobuf
writes fields in field-number order, a sub-message as its tag, its length and its bytes).
``tests/replay/test_foxglove_stamps.py`` compares the bytes with the SDK's own encoding of
the whole messages.
"""

from __future__ import annotations

import functools
from collections.abc import Callable

from foxglove.messages import FrameTransforms, SceneUpdate

from rsstp_format.schemas import STEP_NS
from rsstp_replay.errors import ReplayError

__all__ = ["PoseMessages", "timestamp_field"]

_ENTITIES = 0x12  # SceneUpdate.entities: field 2, length-delimited
_TRANSFORMS = 0x0A  # FrameTransforms.transforms: field 1, length-delimited
_STAMP = 0x0A  # SceneEntity.timestamp and FrameTransform.timestamp: field 1
_SECONDS, _NANOS = 0x08, 0x10  # Timestamp.seconds (field 1), .nanos (field 2): varints


def _varint(value: int) -> bytes:
    out = bytearray()
    while value > 0x7F:
        out.append(value & 0x7F | 0x80)
        value >>= 7
    out.append(value)
    return bytes(out)


_MILLIS = 1_000_000_000 // STEP_NS
"""Steps a second."""
_NANOS_FIELDS = [
    bytes((_NANOS,)) + _varint(nsec) if nsec else b""
    for nsec in (STEP_NS * k for k in range(_MILLIS))
]


@functools.lru_cache(maxsize=4)
def _seconds_field(sec: int) -> bytes:
    return bytes((_SECONDS,)) + _varint(sec) if sec else b""


def timestamp_field(step: int) -> bytes:
    """The timestamp field of a message of ``step`` (``step * STEP_NS`` ns): proto3 leaves a
    zero seconds or nanos out."""
    sec, k = divmod(step, _MILLIS)
    stamp = _seconds_field(sec) + _NANOS_FIELDS[k]
    return bytes((_STAMP, len(stamp))) + stamp


def _fields(data: bytes, tag: int) -> list[bytes]:
    """The bytes of each length-delimited field ``tag`` of an encoded message that holds only
    those fields."""
    found = []
    at = 0
    while at < len(data):
        if data[at] != tag:
            raise ReplayError(
                f"foxglove-sdk's encoding: expected field tag {tag:#x} at byte {at}, found "
                f"{data[at]:#x} (its messages' layout changed: the stamps need the same change)"
            )
        at += 1
        length = shift = 0
        while True:
            byte = data[at]
            at += 1
            length |= (byte & 0x7F) << shift
            shift += 7
            if byte < 0x80:
                break
        found.append(data[at : at + length])
        at += length
    return found


class PoseMessages:
    """The arm's ``SceneUpdate`` and the links' ``FrameTransforms`` at a step, from each
    pose's encoding: ``arm(row)`` and ``links(row)`` give the messages of the pose of the
    caller's ``row`` without a timestamp. A pose's encoding is kept (for ``cached`` poses at
    most), and the links' message as a template for each length of the stamp (a handful)."""

    def __init__(
        self,
        arm: Callable[[int], SceneUpdate],
        links: Callable[[int], FrameTransforms],
        *,
        cached: int,
    ) -> None:
        self._arm, self._links = arm, links
        self._cached = cached
        self._entities: dict[int, bytes] = {}  # pose code -> the arm's entity
        self._transforms: dict[int, list[bytes]] = {}  # pose code -> each link's transform
        # pose code * 32 + stamp length -> the links' message, a %b for each stamp
        self._templates: dict[int, tuple[bytes, int]] = {}

    def at(self, step: int, code: int, row: int) -> tuple[bytes, bytes, bytes]:
        """The messages of ``step``, at pose ``code`` (the caller's ``row``): the arm's
        ``SceneUpdate`` as its head and its tail (the pose's entity, shared by every step),
        and the links' ``FrameTransforms``."""
        stamp = timestamp_field(step)
        entity = self._entities.get(code)
        if entity is None:
            entity = self._entity(code, row)
        found = self._templates.get(code * 32 + len(stamp))
        if found is None:
            found = self._template(code, row, len(stamp))
        template, count = found
        return (
            _prefix(_ENTITIES, len(stamp) + len(entity)) + stamp,
            entity,
            template % ((stamp,) * count),
        )

    def _entity(self, code: int, row: int) -> bytes:
        if len(self._entities) >= self._cached:
            self._entities.clear()
        (entity,) = _fields(self._arm(row).encode(), _ENTITIES)
        self._entities[code] = entity
        return entity

    def _template(self, code: int, row: int, stamp_length: int) -> tuple[bytes, int]:
        transforms = self._transforms.get(code)
        if transforms is None:
            if len(self._transforms) >= self._cached:
                self._transforms.clear()
                self._templates.clear()
            encoded = self._links(row).encode()
            transforms = self._transforms[code] = _fields(encoded, _TRANSFORMS)
        template = b"".join(  # a %b for each stamp; any "%" of the bytes escaped
            _prefix(_TRANSFORMS, stamp_length + len(t)).replace(b"%", b"%%")
            + b"%b"
            + t.replace(b"%", b"%%")
            for t in transforms
        )
        found = self._templates[code * 32 + stamp_length] = (template, len(transforms))
        return found


_PREFIXES = {
    tag: [bytes((tag,)) + _varint(length) for length in range(1 << 14)]
    for tag in (_ENTITIES, _TRANSFORMS)
}


def _prefix(tag: int, length: int) -> bytes:
    """A length-delimited field's tag and length."""
    return _PREFIXES[tag][length] if length < 1 << 14 else bytes((tag,)) + _varint(length)
