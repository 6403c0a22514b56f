"""One task of a campaign: the worker entry point both backends run
(`campaign.py --task K --plan OUT/plan.json`, or run_task in the local backend's pool).

It runs the task's argv (plan.json, "tasks"[K]) with stdin closed, and
- first moves a run folder left by an earlier attempt to OUT/previous/<name> (replacing an
  older one there), so that each attempt starts from an empty run folder;
- writes the run's stdout and stderr, with a header line naming the command, to
  <run_dir>/task.log;
- at the end writes <run_dir>/task.json: {"index", "name", "exit_code", "wall_s", "log",
  "job_id", "host", "finished"}; "exit_code" is the run's exit code (a run ended by signal N
  counts as 128 + N, as a shell reports it; 127 when the program cannot be started); "job_id"
  is $SLURM_ARRAY_JOB_ID under Slurm, else "local", so that a follower can tell this attempt's
  file from an earlier one's.
SIGTERM and SIGINT (Slurm's scancel, Ctrl-C) are passed on to the run, which shuts its
engines down; task.json is still written. The worker's own exit code is the run's.
"""

import json
import os
import shlex
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time


def load_plan(path):
    with open(path) as f:
        return json.load(f)


def _write_json(path, doc):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")
    os.replace(tmp, path)


_running = set()  # the `convoy run` processes of this process's tasks in flight
_running_lock = threading.Lock()


def interrupt_all(signum):
    """Sends `signum` to every run in flight (the local backend, interrupted)."""
    with _running_lock:
        procs = list(_running)
    for proc in procs:
        try:
            proc.send_signal(signum)
        except ProcessLookupError:
            pass


def run_task(plan, index, job_id=None):
    """Runs task `index` of `plan`; returns its task.json record."""
    task = plan["tasks"][index]
    run_dir = task["run_dir"]
    if os.path.exists(run_dir):
        previous = os.path.join(plan["out"], "previous", task["name"])
        shutil.rmtree(previous, ignore_errors=True)
        os.makedirs(os.path.dirname(previous), exist_ok=True)
        os.replace(run_dir, previous)
    os.makedirs(run_dir)
    log = os.path.join(run_dir, "task.log")
    job_id = job_id or os.environ.get("SLURM_ARRAY_JOB_ID") or "local"
    t0 = time.monotonic()
    with open(log, "w") as f:
        f.write("$ %s\n" % shlex.join(task["argv"]))
        f.flush()
        try:
            proc = subprocess.Popen(task["argv"], stdin=subprocess.DEVNULL, stdout=f,
                                    stderr=subprocess.STDOUT, cwd=os.path.dirname(task["config"]))
        except OSError as e:
            f.write("campaign worker: cannot start %s: %s\n" % (task["argv"][0], e))
            code = 127
        else:
            with _running_lock:
                _running.add(proc)

            def forward(signum, _frame):
                try:
                    proc.send_signal(signum)
                except ProcessLookupError:
                    pass
            old = {}
            if _in_main_thread():
                for s in (signal.SIGTERM, signal.SIGINT):
                    old[s] = signal.signal(s, forward)
            try:
                code = proc.wait()
            finally:
                for s, h in old.items():
                    signal.signal(s, h)
                with _running_lock:
                    _running.discard(proc)
            if code < 0:
                code = 128 - code
    record = {"index": index, "name": task["name"], "exit_code": code,
              "wall_s": round(time.monotonic() - t0, 3), "log": log, "job_id": str(job_id),
              "host": socket.gethostname(), "finished": time.strftime("%Y-%m-%dT%H:%M:%S")}
    _write_json(os.path.join(run_dir, "task.json"), record)
    return record


def _in_main_thread():
    return threading.current_thread() is threading.main_thread()


def main(plan_path, index):
    """The worker entry point: exit code of the run, 2 for a bad --task / --plan."""
    try:
        plan = load_plan(plan_path)
    except (OSError, ValueError) as e:
        print("campaign: --plan %s: %s" % (plan_path, e), file=sys.stderr)
        return 2
    if not 0 <= index < len(plan.get("tasks", [])):
        print("campaign: --task %d: the plan %s has tasks 0..%d" % (
            index, plan_path, len(plan.get("tasks", [])) - 1), file=sys.stderr)
        return 2
    record = run_task(plan, index)
    return min(record["exit_code"], 255)
