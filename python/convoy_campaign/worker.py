"""One task of a campaign: the worker entry point both backends run
(`campaign.py --task K --plan OUT/plan.json`, or run_task in the local backend's pool).

It runs the task's argv (plan.json, "tasks"[K]) with stdin closed, and
- first takes the task's lock, OUT/locks/<name>.lock (atomic.py), waiting up to LOCK_WAIT_S
  (120 s; $CONVOY_CAMPAIGN_LOCK_WAIT_S) for an earlier attempt's run that still holds it (a run
  whose campaign was killed: it gets SIGTERM when its parent dies and ends as on Ctrl-C); the
  lock is passed on to the run, so it is held until the run has ended. Still held after the
  wait: the task is not run, exit code 75, no task.json;
- then moves a run folder left by an earlier attempt (a finished one, or a partial one without
  task.json) to OUT/previous/<name> (replacing an older one there), so that each attempt starts
  from an empty run folder;
- writes the run's stdout and stderr, with a header line naming the command, to
  <run_dir>/task.log;
- runs `convoy run` with the parent-death signal SIGTERM (`setpriv --pdeathsig TERM`, when
  setpriv is installed): if the worker (or the local campaign) is killed, the run stops too
  instead of writing on into a folder the next attempt will use;
- at the end writes <run_dir>/task.json (atomically, fsync'ed): {"index", "name", "exit_code",
  "wall_s", "log", "job_id", "attempt", "submission", "host", "finished"}; "exit_code" is the
  run's exit code (a run ended by signal N counts as 128 + N, as a shell reports it; 127 when
  the program cannot be started); "job_id" is $SLURM_ARRAY_JOB_ID under Slurm, else "local",
  and "attempt" the campaign's attempt number (local backend), so that a follower can tell this
  attempt's file from an earlier one's; "submission" is $CONVOY_CAMPAIGN_SUBMISSION, the token
  the Slurm backend gave the array (slurm.py, "Restart").
task.json is written last: a run folder without it is a run that did not finish, never a done
task. SIGTERM and SIGINT (Slurm's scancel, Ctrl-C) are passed on to the run, which shuts its
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

from . import atomic

def _lock_wait_s():
    try:
        return max(0.0, float(os.environ.get("CONVOY_CAMPAIGN_LOCK_WAIT_S", "120")))
    except ValueError:
        return 120.0


LOCK_WAIT_S = _lock_wait_s()
EXIT_BUSY = 75  # EX_TEMPFAIL: an earlier run of the task still holds its lock
SETPRIV = shutil.which("setpriv")


def load_plan(path):
    with open(path) as f:
        return json.load(f)


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


def lock_path(plan, task):
    return os.path.join(plan["out"], "locks", task["name"] + ".lock")


def _take_lock(plan, task):
    path = lock_path(plan, task)
    def told():
        print("campaign: %s: waiting for an earlier run of this task to end (%s)" % (
            task["name"], path), file=sys.stderr, flush=True)
    return atomic.wait_lock(path, LOCK_WAIT_S, on_wait=told)


def _fresh_run_dir(plan, task):
    run_dir = task["run_dir"]
    if os.path.exists(run_dir):
        previous = os.path.join(plan["out"], "previous", task["name"])
        shutil.rmtree(previous, ignore_errors=True)
        os.makedirs(os.path.dirname(previous), exist_ok=True)
        os.replace(run_dir, previous)
    os.makedirs(run_dir)


def _run(task, f, lock_fd):
    """Runs the task's argv, its output into `f`; its exit code."""
    argv = task["argv"]
    if SETPRIV:
        argv = [SETPRIV, "--pdeathsig", "TERM", "--"] + argv
    try:
        proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=f, stderr=subprocess.STDOUT,
                                cwd=os.path.dirname(task["config"]), pass_fds=(lock_fd,))
    except OSError as e:
        f.write("campaign worker: cannot start %s: %s\n" % (argv[0], e))
        return 127
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
    return 128 - code if code < 0 else code


def run_task(plan, index, job_id=None, attempt=None):
    """Runs task `index` of `plan`; returns its task.json record (exit code EXIT_BUSY and no
    task.json when an earlier run of the task still holds its lock)."""
    task = plan["tasks"][index]
    run_dir = task["run_dir"]
    log = os.path.join(run_dir, "task.log")
    job_id = job_id or os.environ.get("SLURM_ARRAY_JOB_ID") or "local"
    record = {"index": index, "name": task["name"], "log": log, "job_id": str(job_id),
              "attempt": attempt, "submission": os.environ.get("CONVOY_CAMPAIGN_SUBMISSION"),
              "host": socket.gethostname()}
    t0 = time.monotonic()
    try:
        lock_fd = _take_lock(plan, task)
    except atomic.Busy:
        print("campaign: %s: an earlier run of this task still holds %s after %g s; not run" % (
            task["name"], lock_path(plan, task), LOCK_WAIT_S), file=sys.stderr, flush=True)
        return dict(record, exit_code=EXIT_BUSY, wall_s=round(time.monotonic() - t0, 3),
                    finished=time.strftime("%Y-%m-%dT%H:%M:%S"))
    try:
        _fresh_run_dir(plan, task)
        t0 = time.monotonic()
        with open(log, "w") as f:
            f.write("$ %s\n" % shlex.join(task["argv"]))
            f.flush()
            code = _run(task, f, lock_fd)
        record.update(exit_code=code, wall_s=round(time.monotonic() - t0, 3),
                      finished=time.strftime("%Y-%m-%dT%H:%M:%S"))
        atomic.write_json(os.path.join(run_dir, "task.json"), record, indent=1, sort_keys=True)
    finally:
        os.close(lock_fd)
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
