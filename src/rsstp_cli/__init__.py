"""The command lines: ``rsstp-sim`` (:mod:`rsstp_cli.sim`) and ``rsstp-replay``
(:mod:`rsstp_cli.replay`), with the sweep's two commands (:mod:`rsstp_cli.sweep`).

This package sits above the three others (``rsstp_sim``, ``rsstp_replay``, ``rsstp_sweep``)
and none of them imports it. The console scripts start in :mod:`rsstp_cli.start`, which loads
the rest only once Ctrl-C is safe; ``python -m rsstp_cli.sim`` and
``python -m rsstp_cli.replay`` run the same commands. This module imports nothing, so
starting a command costs no more than the command itself.
"""

__all__: list[str] = []
