#!/usr/bin/python3
"""Runs a suite of Convoy experiments over seeds and weathers (docs/campaigns.md):

    /usr/bin/python3 tools/campaign/campaign.py SUITE_DIR [--seeds N] [--weathers clear,rain]
        [--workers N] [--backend local|slurm] [--out DIR] [--seconds S] [--build DIR]

The command line is python/convoy_campaign/cli.py's."""
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))

from convoy_campaign.cli import main  # noqa: E402 (after the path)
from convoy_scenario.campaign_entry import register as register_xosc  # noqa: E402
from convoy_scenario.distribution_entry import register as register_distributions  # noqa: E402

register_xosc()  # OpenSCENARIO entries (.xosc): convoy run --scenario
register_distributions()  # .xosc parameter distributions: one entry per variant

if __name__ == "__main__":
    sys.exit(main())
