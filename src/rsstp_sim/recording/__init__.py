"""Recording a run: the recorder, and the records it builds from the simulator's live objects.

Recording is a layer around the simulation: records are built from the runner's outcomes and
the world's poses, never from inside them. The record classes, the schemas and the topics are
the file format's (:mod:`rsstp_format`); :mod:`~rsstp_sim.recording.builders` makes records
from live objects and :mod:`~rsstp_sim.recording.recorder` writes them.
"""

from __future__ import annotations

# The package's names are its modules' public names, each listed once, in its module.
from rsstp_sim.recording import builders, recorder
from rsstp_sim.recording.builders import *  # noqa: F403
from rsstp_sim.recording.recorder import *  # noqa: F403

__all__ = [*builders.__all__, *recorder.__all__]
