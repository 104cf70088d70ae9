"""The JSON Schemas of a recording, as shipped in the package (``rsstp_format/schemas/*.json``).

A recording registers each schema's file byte for byte (:func:`schema_bytes`), so the
files are part of the contract (they are written from the record classes by
:mod:`~rsstp_format.schema_text`); ``schemas/README.md`` documents every field, the
topics, the metadata record, the attachment and the version policy: a reader accepts any
``2.x`` (ignoring fields it does not know) and refuses another major version
(:func:`check_schema_version`).

>>> TOPICS["/rsstp/step"]
'rsstp.Step'
>>> schema_json("rsstp.Step")["version"] == SCHEMA_VERSION
True
>>> parse_version("1.2")
(1, 2)
"""

from __future__ import annotations

import functools
import hashlib
import json
import re
from collections.abc import Mapping
from importlib import resources
from typing import TYPE_CHECKING, Any

from rsstp_format.records import RecordFormatError

if TYPE_CHECKING:
    from jsonschema import Draft202012Validator

__all__ = [
    "ATTACHMENT_MEDIA_TYPE",
    "ATTACHMENT_NAME",
    "MESSAGE_ENCODING",
    "METADATA_CHECKSUM_KEY",
    "METADATA_CHECKSUM_SINCE",
    "METADATA_KEYS",
    "METADATA_NAME",
    "SCHEMA_ENCODING",
    "SCHEMA_NAMES",
    "READ_MAJORS",
    "SCHEMA_VERSION",
    "STEP_NS",
    "TOPICS",
    "BODY_TOPICS",
    "check_schema_version",
    "log_time_ns",
    "metadata_checksum",
    "parse_version",
    "schema_bytes",
    "schema_json",
    "validate",
    "validator",
    "version_refusal",
]

SCHEMA_VERSION = "3.0"
"""The version (``major.minor``) of the schemas this package writes."""

READ_MAJORS = (2, 3)
"""The major versions this package reads: 3 (a model message is a keyframe or a change) and
2 (every model message a whole snapshot: a keyframe each)."""

SCHEMA_NAMES = (
    "rsstp.Scenario",
    "rsstp.Step",
    "rsstp.Model",
    "rsstp.Event",
    "rsstp.RoverScenario",
    "rsstp.RoverStep",
)
"""The MCAP schema names, which are also the schemas' titles and file names."""

BODY_TOPICS: dict[str, dict[str, str]] = {
    "arm": {
        "/rsstp/scenario": "rsstp.Scenario",
        "/rsstp/step": "rsstp.Step",
        "/rsstp/model": "rsstp.Model",
        "/rsstp/event": "rsstp.Event",
    },
    "rover": {
        "/rsstp/scenario": "rsstp.RoverScenario",
        "/rsstp/step": "rsstp.RoverStep",
        "/rsstp/model": "rsstp.Model",
        "/rsstp/event": "rsstp.Event",
    },
}
"""Body -> topic -> schema name: every body has the same topics; the scenario and the step
messages are its own (its world, its ground truth), the model and the events everyone's."""

TOPICS: dict[str, str] = BODY_TOPICS["arm"]
"""Topic -> schema name, of an arm's recording."""

MESSAGE_ENCODING = "json"
SCHEMA_ENCODING = "jsonschema"

STEP_NS = 1_000_000
"""``log_time`` of step ``t`` is ``t * STEP_NS`` nanoseconds: time ranges are step ranges."""

METADATA_NAME = "rsstp"
METADATA_KEYS = (
    "package",
    "package_version",
    "python",
    "numpy",
    "shapely",
    "mcap",
    "seed",
    "strategy",
    "strategy_params",
    "strategy_import_path",
    "strategy_distribution",
    "strategy_version",
    "scenario_sha256",
)
"""The keys of the ``rsstp`` metadata record (every value a string)."""
METADATA_CHECKSUM_KEY = "metadata_sha256"
"""The record's last key, from 2.2: :func:`metadata_checksum` of all the others."""
METADATA_CHECKSUM_SINCE = (2, 2)
"""The schema version from which a recording's metadata must carry its checksum (an older
file has none: it is read, its metadata marked unverified)."""

ATTACHMENT_NAME = "scenario.toml"
ATTACHMENT_MEDIA_TYPE = "application/toml"

_VERSION = re.compile(r"(0|[1-9][0-9]*)\.(0|[1-9][0-9]*)")


def log_time_ns(step: int) -> int:
    """The ``log_time`` (and ``publish_time``) of step ``step``, in nanoseconds."""
    return step * STEP_NS


def metadata_checksum(metadata: Mapping[str, str]) -> str:
    """The SHA-256 (hex) that covers an ``rsstp`` metadata record: of every key but
    :data:`METADATA_CHECKSUM_KEY`, written as one JSON object, keys sorted, no spaces,
    non-ASCII as UTF-8 (``schemas/README.md`` gives the rule for other languages).

    >>> metadata_checksum({"seed": "1", "package": "rsstp"}) == hashlib.sha256(
    ...     b'{"package":"rsstp","seed":"1"}').hexdigest()
    True
    """
    others = {key: value for key, value in metadata.items() if key != METADATA_CHECKSUM_KEY}
    text = json.dumps(others, sort_keys=True, separators=(",", ":"), ensure_ascii=False)
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def parse_version(text: object) -> tuple[int, int]:
    """``"major.minor"`` -> ``(major, minor)``; anything else raises :class:`RecordFormatError`."""
    match = _VERSION.fullmatch(text) if isinstance(text, str) else None
    if match is None:
        raise RecordFormatError(f'schema version: expected "major.minor", found {text!r}')
    return int(match[1]), int(match[2])


def schema_bytes(name: str) -> bytes:
    """The packaged schema file's exact bytes (what a recording registers)."""
    return _schema_bytes(_known(name))


def schema_json(name: str) -> dict[str, Any]:
    """The packaged schema, parsed (a fresh dict on every call)."""
    parsed: dict[str, Any] = json.loads(schema_bytes(name))
    return parsed


def validator(name: str) -> Draft202012Validator:
    """A (cached) draft 2020-12 validator for the packaged schema ``name``."""
    return _validator(_known(name))


def validate(name: str, instance: Mapping[str, Any]) -> None:
    """Check a decoded message against schema ``name``, ranges included.

    Raises :class:`RecordFormatError` naming the field path of the most relevant error.
    """
    from jsonschema.exceptions import best_match  # (not imported by a recording run)

    error = best_match(validator(name).iter_errors(instance))
    if error is not None:
        path = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in error.absolute_path)
        where = f"{path.removeprefix('.')}: " if path else ""
        raise RecordFormatError(f"{name}: {where}{error.message}")


def check_schema_version(name: str, data: bytes) -> tuple[int, int]:
    """Check a schema found in a recording: title ``name`` and a version of a major this
    package reads (:data:`READ_MAJORS`).

    Returns ``(major, minor)``. A later minor version is accepted (its new fields are
    ignored); another major version, or a schema that is not ours, is refused.
    """
    try:
        schema = json.loads(data)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise RecordFormatError(f"{name}: the schema is not JSON: {exc}") from None
    except RecursionError:
        raise RecordFormatError(f"{name}: the schema nests too deeply") from None
    if not isinstance(schema, dict) or schema.get("title") != name:
        found = schema.get("title") if isinstance(schema, dict) else schema
        raise RecordFormatError(f"{name}: the schema's title: expected {name!r}, found {found!r}")
    try:
        major, minor = parse_version(schema.get("version"))
    except RecordFormatError as exc:
        raise RecordFormatError(f"{name}: {exc}") from None
    if major not in READ_MAJORS:
        raise RecordFormatError(f"{name}: schema {version_refusal(f'{major}.{minor}')}")
    return major, minor


def version_refusal(version: object) -> str:
    """Why a recording's schema ``version`` of another major is not read, and what to do."""
    return (
        f"version {version} is not supported (this reader understands "
        f"{' and '.join(f'{major}.x' for major in READ_MAJORS)}; "
        f"re-record the run with rsstp-sim record: its scenario.toml is attached)"
    )


def _known(name: str) -> str:
    if name not in SCHEMA_NAMES:
        raise RecordFormatError(f"unknown schema {name!r} (known: {', '.join(SCHEMA_NAMES)})")
    return name


@functools.cache
def _schema_bytes(name: str) -> bytes:
    return resources.files("rsstp_format").joinpath(f"schemas/{name}.json").read_bytes()


@functools.cache
def _validator(name: str) -> Draft202012Validator:
    from jsonschema import Draft202012Validator

    return Draft202012Validator(json.loads(_schema_bytes(name)))
