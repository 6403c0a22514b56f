"""The run folder as the live-scoring functions use it (metrics_tf.py, detection_tf.py): the
run's effective config, and summary.json updated in place with a function's fields. In a live
run (`convoy run --live`) the fields also go to the viewers on /convoy/metrics, through the
coordinator's module convoy_live (absent outside Convoy: then nothing is sent)."""

import json
import os

try:
    import convoy_live as _live
except ImportError:  # not in the coordinator's interpreter
    _live = None

METRICS_TOPIC = "/convoy/metrics"
INFRACTIONS_TOPIC = "/convoy/infractions"


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
    publish_live(METRICS_TOPIC, fields)


def publish_live(topic, message):
    """Sends the dict `message` to the viewers of a live run on `topic` (/convoy/metrics or
    /convoy/infractions). True when sent; False without --live, outside Convoy, or when it
    cannot be sent (never raises: a viewer must not change the run)."""
    if _live is None:
        return False
    try:
        return bool(_live.enabled()) and bool(_live.publish(topic, message))
    except Exception:  # noqa: BLE001 (a message that is not JSON, say)
        return False
