"""``python -m rsstp_sim`` runs the ``rsstp-sim`` command."""

import sys

from rsstp_sim.cli import main

sys.exit(main())
