"""``python -m rsstp_replay`` runs the ``rsstp-replay`` command."""

import sys

from rsstp_replay.cli import main

sys.exit(main())
