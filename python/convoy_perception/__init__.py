"""Perception helpers. `convoy_perception.evaluation` is the project's one definition of how
detections are scored against the world engine's ground truth (docs/perception.md)."""
