"""The Slurm backend: the campaign's tasks as Slurm job arrays, followed until they end.

Submission. One batch script, OUT/slurm/campaign.sbatch, runs the worker entry point
(`/usr/bin/python3 tools/campaign/campaign.py --task $SLURM_ARRAY_TASK_ID --plan
OUT/plan.json`); array index = task index. The tasks not yet submitted go in one array,
`sbatch --parsable --array=<indices>%<workers> --job-name convoy-campaign --comment
convoy-campaign:TOKEN --output OUT/slurm/%A_%a.out --chdir OUT OUT/slurm/campaign.sbatch`
(TOKEN: see Restart), which runs at most `workers` of them
at once. Once no array is active, the tasks that failed with fewer than MAX_ATTEMPTS (2)
attempts in this invocation go in a second array of only their indices: a failed task is
resubmitted once. A task that had failed before this invocation started counts as not yet
submitted (the same command runs failed tasks again, as the local backend does).

Following, every `poll_s` seconds, per active array: `squeue -h -r -j JOBID -o "%K %T"` lists
its tasks still queued or running. A task that has left the queue has ended: its exit code and
wall time come from its run folder's task.json when that file's "job_id" is this array's (the
worker writes it before it exits); otherwise from `scontrol show job -o JOBID` (its
ArrayTaskId's JobState and ExitCode; a task killed by signal N counts as 128 + N), with
"reason" saying that task.json is missing; if scontrol no longer knows the job (Slurm forgets
ended jobs after MinJobAge, 300 s by default), the exit code is unknown (None) and the task
failed. `sacct` is not used (it needs an accounting database). squeue's "Invalid job id"
means that no task of the array is queued; any other failure of squeue or scontrol is retried
at the next poll, up to `patience_s` seconds in a row, then raised as SlurmError.

Restart. All of this lives in OUT/campaign.json (state.py): job ids, each task's attempts and
state, saved after every change, so that the same command with the same --out, after the
driver was stopped, follows the arrays still active and submits only what has not been run.
A submission is recorded before sbatch runs: campaign.json's "submitting" holds a fresh token
and the indices, and the array carries the token twice, as its comment (`sbatch --comment
convoy-campaign:TOKEN`) and in its tasks' environment ($CONVOY_CAMPAIGN_SUBMISSION, which the
worker writes into task.json). Once sbatch has answered, the array and the tasks' new state
replace "submitting" in one save (SIGINT and SIGTERM wait from sbatch's start to that save).
A driver stopped between the two (SIGKILL) finds "submitting" at its restart and looks for the
array before it submits anything: `squeue -h -t all -o "%F %k"` (every job slurmctld still
knows, with its comment), else a task.json of those tasks carrying the token (the array ran
and Slurm forgot it). Found, it is followed as if the save had happened; not found, sbatch
never took it, and it is submitted again. (What remains: sbatch still talking to slurmctld when the restarted driver
looks, i.e. a restart within sbatch's own few milliseconds.)

The commands run through a `runner` (subprocess.run by default) so that tests can fake Slurm.
"""

import os
import re
import signal
import subprocess
import time
import uuid
from contextlib import contextmanager

from . import atomic
from .state import read_task_record

MAX_ATTEMPTS = 2
JOB_NAME = "convoy-campaign"
COMMENT_PREFIX = "convoy-campaign:"
TOKEN_ENV = "CONVOY_CAMPAIGN_SUBMISSION"


class SlurmError(Exception):
    """Slurm refused or failed a command; the message carries its output."""


def array_spec(indices):
    """"0-3,7,9-10" for [0, 1, 2, 3, 7, 9, 10]."""
    parts, xs = [], sorted(indices)
    i = 0
    while i < len(xs):
        j = i
        while j + 1 < len(xs) and xs[j + 1] == xs[j] + 1:
            j += 1
        parts.append(str(xs[i]) if i == j else "%d-%d" % (xs[i], xs[j]))
        i = j + 1
    return ",".join(parts)


class Slurm:
    """The Slurm commands the backend uses."""

    def __init__(self, runner=subprocess.run):
        self.runner = runner

    def _run(self, argv, env=None):
        try:
            return self.runner(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=60, env=env)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise SlurmError("%s: %s" % (argv[0], e)) from None

    def submit(self, script, indices, throttle, out_dir, token):
        argv = ["sbatch", "--parsable", "--array=%s%%%d" % (array_spec(indices), throttle),
                "--job-name", JOB_NAME, "--comment", COMMENT_PREFIX + token,
                "--output", os.path.join(out_dir, "slurm", "%A_%a.out"),
                "--chdir", out_dir, script]
        r = self._run(argv, env=dict(os.environ, **{TOKEN_ENV: token}))
        job = r.stdout.strip().split(";")[0]
        if r.returncode != 0 or not job.isdigit():
            raise SlurmError("%s failed (exit %d): %s" % (" ".join(argv), r.returncode,
                                                          (r.stderr or r.stdout).strip()))
        return job

    def find(self, token):
        """The job id of the array submitted with `token` that slurmctld still knows, or None."""
        r = self._run(["squeue", "-h", "-t", "all", "-o", "%F %k"])
        if r.returncode != 0:
            raise SlurmError("squeue failed (exit %d): %s" % (r.returncode, r.stderr.strip()))
        for line in r.stdout.splitlines():
            job, _, comment = line.strip().partition(" ")
            if comment.strip() == COMMENT_PREFIX + token and job.isdigit():
                return job
        return None

    def queued(self, job_id):
        """{task index: Slurm state} of the array's tasks still in the queue."""
        r = self._run(["squeue", "-h", "-r", "-j", job_id, "-o", "%K %T"])
        if r.returncode != 0:
            if "Invalid job id" in r.stderr:
                return {}
            raise SlurmError("squeue -j %s failed (exit %d): %s" % (job_id, r.returncode,
                                                                   r.stderr.strip()))
        out = {}
        for line in r.stdout.splitlines():
            parts = line.split()
            if len(parts) == 2 and parts[0].isdigit():
                out[int(parts[0])] = parts[1]
        return out

    def ended(self, job_id):
        """{task index: (JobState, exit code)} from scontrol; {} once Slurm forgot the job."""
        r = self._run(["scontrol", "show", "job", "-o", job_id])
        if r.returncode != 0:
            if "Invalid job id" in r.stderr:
                return {}
            raise SlurmError("scontrol show job %s failed (exit %d): %s" % (
                job_id, r.returncode, r.stderr.strip()))
        out = {}
        for line in r.stdout.splitlines():
            f = dict(m.groups() for m in re.finditer(r"(\w+)=(\S*)", line))
            if f.get("ArrayJobId") != job_id or not f.get("ArrayTaskId", "").isdigit():
                continue
            code, _, sig = f.get("ExitCode", "").partition(":")
            exit_code = None
            if code.isdigit() and sig.isdigit():
                exit_code = int(code) if int(sig) == 0 else 128 + int(sig)
            out[int(f["ArrayTaskId"])] = (f.get("JobState"), exit_code)
        return out


def write_script(plan, plan_path, campaign_py):
    path = os.path.join(plan["out"], "slurm", "campaign.sbatch")
    os.makedirs(os.path.dirname(path), exist_ok=True)
    atomic.write_text(path, "#!/bin/sh\n"
                      "# Written by tools/campaign/campaign.py: one task of the campaign in %s\n"
                      "#SBATCH --cpus-per-task=1\n"
                      "exec /usr/bin/python3 %s --task \"$SLURM_ARRAY_TASK_ID\" --plan %s\n" % (
                          plan["out"], campaign_py, plan_path))
    os.chmod(path, 0o755)
    return path


def _task_record(task, job_id):
    rec = read_task_record(task)
    return rec if rec is not None and str(rec.get("job_id")) == str(job_id) else None


@contextmanager
def _signals_held():
    """SIGINT and SIGTERM wait until the block ends (a state change and its save go whole)."""
    held = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _submitted(state, job, batch, attempt):
    """The array `job` of `batch` into the state, replacing the intent, in one save."""
    with _signals_held():
        state.arrays.append({"job_id": job, "indices": batch, "attempt": attempt,
                             "finished": False})
        for i in batch:
            t = state.tasks[i]
            t.update(state="queued", job_id=job, exit_code=None, wall_s=None, reason=None)
            t["attempts"] += 1
        state.doc.pop("submitting", None)
        state.save()


def _resolve_intent(plan, state, slurm, log):
    """A submission recorded but not saved as done (the driver stopped in between): find its
    array (squeue by comment, else a task.json with its token) or drop it."""
    intent = state.doc.get("submitting")
    if not intent:
        return
    token, batch = intent["token"], intent["indices"]
    job = slurm.find(token)
    where = "squeue, comment %s%s" % (COMMENT_PREFIX, token)
    if job is None:
        for i in batch:
            rec = read_task_record(plan["tasks"][i])
            if rec is not None and rec.get("submission") == token and rec.get("job_id"):
                job, where = str(rec["job_id"]), "task.json of %s" % rec.get("name")
                break
    if job is None:
        with _signals_held():
            state.doc.pop("submitting", None)
            state.save()
        log("campaign: the array being submitted when the campaign stopped is not in Slurm; "
            "submitting its tasks again")
        return
    _submitted(state, job, batch, intent["attempt"])
    log("campaign: found job array %s, submitted when the campaign stopped (%s): %s" % (
        job, where, array_spec(batch)))


def run(plan, state, workers, plan_path, campaign_py, slurm=None, poll_s=1.0, patience_s=120.0,
        log=print):
    slurm = slurm or Slurm()
    script = write_script(plan, plan_path, campaign_py)
    before = {t["index"]: t["attempts"] for t in state.tasks}  # attempts of earlier invocations
    trouble_since = None
    while True:
        try:
            _resolve_intent(plan, state, slurm, log)
            _follow(plan, state, slurm, log)
            trouble_since = None
        except SlurmError as e:
            trouble_since = trouble_since or time.monotonic()
            if time.monotonic() - trouble_since > patience_s:
                raise
            log("campaign: %s (retrying)" % e)
            time.sleep(poll_s)
            continue
        if not any(not a["finished"] for a in state.arrays):
            pending = [t["index"] for t in state.tasks if t["state"] == "pending" or (
                t["state"] == "failed" and t["attempts"] == before[t["index"]])]
            retry = [t["index"] for t in state.tasks if t["state"] == "failed"
                     and t["attempts"] - before[t["index"]] < MAX_ATTEMPTS]
            batch = pending or retry
            if not batch:
                return
            attempt = 1 + max(state.tasks[i]["attempts"] for i in batch)
            token = uuid.uuid4().hex
            state.doc["submitting"] = {"token": token, "indices": batch, "attempt": attempt,
                                       "time": time.strftime("%Y-%m-%dT%H:%M:%S")}
            state.save()
            with _signals_held():  # Ctrl-C waits for sbatch's answer and its save
                job = slurm.submit(script, batch, workers, plan["out"], token)
                _submitted(state, job, batch, attempt)
            log("campaign: submitted job array %s (%s tasks%s): %s" % (
                job, len(batch), ", resubmitted" if batch is retry else "", array_spec(batch)))
        time.sleep(poll_s)


def _follow(plan, state, slurm, log):
    changed = False
    for a in state.arrays:
        if a["finished"]:
            continue
        job = a["job_id"]
        queued = slurm.queued(job)
        ended = None
        open_tasks = 0
        for i in a["indices"]:
            t = state.tasks[i]
            if t["job_id"] != job or t["state"] in ("done", "failed"):
                continue
            if i in queued:
                s = "running" if queued[i] in ("RUNNING", "COMPLETING") else "queued"
                if t["state"] != s:
                    t["state"] = s
                    changed = True
                open_tasks += 1
                continue
            rec = _task_record(plan["tasks"][i], job)
            if rec is not None:
                state.finish(i, rec.get("exit_code"), rec.get("wall_s"))
            else:
                if ended is None:
                    ended = slurm.ended(job)
                js, code = ended.get(i, (None, None))
                if js is not None and js in ("PENDING", "RUNNING", "COMPLETING", "CONFIGURING"):
                    open_tasks += 1      # between squeue and scontrol: look again next poll
                    continue
                reason = ("no task.json; Slurm says JobState=%s" % js if js
                          else "no task.json and Slurm no longer knows job %s" % job)
                state.finish(i, code if code != 0 else None, None, reason)
            t = state.tasks[i]
            log("campaign: %s: %s (exit %s%s)" % (t["name"], t["state"], t["exit_code"],
                                                  ", " + t["reason"] if t["reason"] else ""))
            changed = True
        if open_tasks == 0:
            a["finished"] = True
            changed = True
    if changed:
        state.save()


def check_installed():
    """None, or the message for a missing sbatch / squeue / scontrol."""
    from shutil import which
    for tool in ("sbatch", "squeue", "scontrol"):
        if which(tool) is None:
            return ("--backend slurm: '%s' is not on PATH (install slurm-client, or run "
                    "scripts/setup.sh; docs/campaigns.md)" % tool)
    return None
