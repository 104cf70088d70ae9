"""The recording contract: record types mirroring the JSON Schemas, and the schemas themselves.

Recording is a layer around the simulation: these records are built from the runner's
outcomes and the world's poses, never from inside them. ``schemas/README.md`` is the
contract's documentation. :mod:`~rsstp_sim.recording.records` holds the record classes and
their JSON conversion, :mod:`~rsstp_sim.recording.builders` makes them from live objects,
:mod:`~rsstp_sim.recording.schemas` holds the schema files, topics and version policy, and
:mod:`~rsstp_sim.recording.schema_text` writes the schema files from the record classes
(``python -m rsstp_sim.recording.schema_text``; not imported here).
"""

from __future__ import annotations

# The package's names are its modules' public names, each listed once, in its module.
from rsstp_sim.recording import builders, recorder, records, schemas
from rsstp_sim.recording.builders import *  # noqa: F403
from rsstp_sim.recording.recorder import *  # noqa: F403
from rsstp_sim.recording.records import *  # noqa: F403
from rsstp_sim.recording.schemas import *  # noqa: F403

__all__ = [*builders.__all__, *recorder.__all__, *records.__all__, *schemas.__all__]
