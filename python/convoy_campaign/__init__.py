"""Convoy campaigns: a suite of experiments run over seeds and weathers, on this machine or on
a Slurm cluster, merged into a leaderboard and a report (docs/campaigns.md).

suite.py (entries, weathers, each task's command), worker.py (one task), state.py
(OUT/campaign.json), local.py and slurm.py (the backends), results.py (leaderboard.csv),
report.py (report.html), cli.py (the command line, tools/campaign/campaign.py)."""
