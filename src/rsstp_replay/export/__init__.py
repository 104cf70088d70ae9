"""A recording in other tools' forms: its tables for pandas (:mod:`~rsstp_replay.export.tables`),
written to Parquet or CSV and read back (:mod:`~rsstp_replay.export.table_files`), and its
scene for Foxglove (:mod:`~rsstp_replay.export.foxglove`).
"""
