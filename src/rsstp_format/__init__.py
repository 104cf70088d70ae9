"""The recording's file format: the floor both the simulator and the replay side stand on.

:mod:`~rsstp_format.records` holds one record class per message type, the one source of every
message's fields; :mod:`~rsstp_format.schemas` the JSON Schemas generated from them
(:mod:`~rsstp_format.schema_text`), the topics and the version policy;
:mod:`~rsstp_format.vocabulary` the words both sides speak (blocker kinds, feedback and
collision modes, the model's operations). It imports neither the simulator nor the replay
side.
"""
