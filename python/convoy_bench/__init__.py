"""Convoy's benchmark metrics: the CARLA Leaderboard 2.0 driving score and a nuPlan-style
closed-loop score of one drive (score.py), read from a city_traffic run folder (runs.py).
See docs/scoring.md."""
