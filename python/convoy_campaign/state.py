"""A campaign's state, OUT/campaign.json: what has been run, so that the same command with the
same --out picks up where a stopped campaign left off.

    {"version": 1, "backend": "local" | "slurm", "plan_digest": "<sha1 of the tasks' names
     and argv>", "arrays": [{"job_id", "indices", "attempt", "finished"}],
     "tasks": [{"index", "name", "state", "attempts", "job_id", "exit_code", "wall_s", "log",
                "reason"}]}

A task's "state" is "pending" (not yet submitted), "queued" (submitted, waiting), "running",
"done" (exit code 0) or "failed" (a non-zero exit code, or none known: then "reason" says
why). "attempts" counts its submissions; "job_id" is the Slurm array (or "local") of the last
one. "arrays" lists the Slurm job arrays submitted, in order (empty for the local backend).

The file is rewritten whole after every change, atomically (atomic.py: a temporary file,
fsync, rename): a campaign killed at any point leaves the last saved state. A campaign.json
written for another plan (other entries, seeds, weathers, --seconds or convoy) or another
backend is refused with a message saying so.

On a restart, check_done() holds "done" to its proof: a task is done only when its run folder
has a task.json with exit code 0 (the worker writes it last, after the run has ended); a task
marked done without one (its folder removed or replaced by hand) is pending again. With the
local backend, adopt_finished() takes a task that was running when the campaign stopped and
whose task.json of that very attempt is there (the run ended, the campaign was stopped before
it saved that): it is not run again.
"""

import hashlib
import json
import os

from . import atomic

FINAL_STATES = ("done", "failed")


class StateError(Exception):
    """The --out folder holds state the command cannot continue."""


def plan_digest(plan):
    h = hashlib.sha1()
    for t in plan["tasks"]:
        h.update(json.dumps([t["name"], t["argv"]]).encode())
    return h.hexdigest()


class CampaignState:
    def __init__(self, path, doc):
        self.path = path
        self.doc = doc

    @property
    def tasks(self):
        return self.doc["tasks"]

    @property
    def arrays(self):
        return self.doc["arrays"]

    @classmethod
    def open(cls, out_dir, plan, backend):
        """The state in out_dir/campaign.json, or a new one for `plan` (not yet written)."""
        path = os.path.join(out_dir, "campaign.json")
        digest = plan_digest(plan)
        if os.path.exists(path):
            try:
                with open(path) as f:
                    doc = json.load(f)
                doc["tasks"], doc["arrays"]
            except (OSError, ValueError, KeyError, TypeError) as e:
                raise StateError("%s: cannot continue from it (%s); remove it or use another "
                                 "--out" % (path, e)) from None
            if doc.get("plan_digest") != digest:
                raise StateError("%s holds another campaign (other entries, seeds, weathers, "
                                 "--seconds, --record or convoy); use another --out" % path)
            if doc.get("backend") != backend:
                raise StateError("%s was run with --backend %s, not %s; use another --out" % (
                    path, doc.get("backend"), backend))
            return cls(path, doc)
        tasks = [{"index": t["index"], "name": t["name"], "state": "pending", "attempts": 0,
                  "job_id": None, "exit_code": None, "wall_s": None,
                  "log": os.path.join(t["run_dir"], "task.log"), "reason": None}
                 for t in plan["tasks"]]
        return cls(path, {"version": 1, "backend": backend, "plan_digest": digest,
                          "arrays": [], "tasks": tasks})

    def save(self):
        atomic.write_json(self.path, self.doc, indent=1, sort_keys=True)

    def check_done(self, plan, log=print):
        """Done tasks without the task.json of a successful run become pending again."""
        for t, task in zip(self.tasks, plan["tasks"]):
            if t["state"] != "done":
                continue
            rec = read_task_record(task)
            if rec is None or rec.get("exit_code") != 0:
                log("campaign: %s: marked done, but %s is %s; it runs again" % (
                    t["name"], os.path.join(task["run_dir"], "task.json"),
                    "missing" if rec is None else "not a successful run's"))
                t.update(state="pending", exit_code=None, wall_s=None, reason=None)

    def adopt_finished(self, plan, log=print):
        """Local backend: a task left "running" whose run folder holds the task.json of that
        attempt ended; its record is taken instead of running it again."""
        for t, task in zip(self.tasks, plan["tasks"]):
            if t["state"] not in ("running", "queued"):
                continue
            rec = read_task_record(task)
            if rec is None or rec.get("job_id") != "local" or rec.get("attempt") != t["attempts"]:
                continue
            self.finish(t["index"], rec.get("exit_code"), rec.get("wall_s"))
            log("campaign: %s: ended before the campaign stopped (exit %s, %s)" % (
                t["name"], rec.get("exit_code"), os.path.join(task["run_dir"], "task.json")))

    def finish(self, index, exit_code, wall_s=None, reason=None):
        t = self.tasks[index]
        t["exit_code"] = exit_code
        t["wall_s"] = wall_s
        t["reason"] = reason
        t["state"] = "done" if exit_code == 0 else "failed"

    def failed(self):
        return [t for t in self.tasks if t["state"] == "failed"]


def read_task_record(task):
    """The run folder's task.json (dict), None when missing or unreadable."""
    try:
        with open(os.path.join(task["run_dir"], "task.json")) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return None
    return rec if isinstance(rec, dict) else None
