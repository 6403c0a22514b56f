"""The run folder as the live-scoring functions use it (metrics_tf.py, detection_tf.py): the
run's effective config, and summary.json updated in place with a function's fields."""

import json
import os


def run_dir():
    return os.environ.get("CONVOY_RUN_DIR", ".")


def load_config():
    """The run's effective config (RUN_DIR/config.json, written by the coordinator)."""
    with open(os.path.join(run_dir(), "config.json")) as f:
        return json.load(f)


def update_summary(fields):
    """Merges `fields` into RUN_DIR/summary.json (a missing or broken file counts as empty),
    replacing the file at once so that a reader never sees half of it."""
    path = os.path.join(run_dir(), "summary.json")
    try:
        with open(path) as f:
            summary = json.load(f)
        if not isinstance(summary, dict):
            summary = {}
    except (OSError, ValueError):
        summary = {}
    summary.update(fields)
    tmp = "%s.%d.tmp" % (path, os.getpid())
    with open(tmp, "w") as f:
        json.dump(summary, f, indent=1)
    os.replace(tmp, path)
