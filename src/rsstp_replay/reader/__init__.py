"""Reading a recording, in four layers from the bottom up: the MCAP file's records
(:mod:`~rsstp_replay.reader._container`), the messages inside its chunks
(:mod:`~rsstp_replay.reader._chunks`), the recording contract
(:mod:`~rsstp_replay.reader._contract`), and the :class:`~rsstp_replay.reader.recording.Recording`
(its steps decoded by :mod:`~rsstp_replay.reader._decode`, its model versions by
:mod:`~rsstp_replay.reader._models`, a version rebuilt on arrays by
:mod:`~rsstp_replay.reader._replay`). Reading never imports the audits.
"""

from rsstp_replay.reader._decode import (
    BLOCKED_COLUMNS,
    BodyReader,
    blocker_label,
    blocker_texts,
    body_reader,
)
from rsstp_replay.reader._models import (
    DeterminismPart,
    ModelHistory,
    model_history,
    version_alive,
    version_heads,
    version_sizes,
    version_state_ids,
)

__all__ = [
    "BLOCKED_COLUMNS",
    "BodyReader",
    "DeterminismPart",
    "ModelHistory",
    "blocker_label",
    "blocker_texts",
    "body_reader",
    "model_history",
    "version_alive",
    "version_heads",
    "version_sizes",
    "version_state_ids",
]
