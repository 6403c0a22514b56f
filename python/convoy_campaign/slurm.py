"""The Slurm backend: the campaign's tasks as Slurm job arrays, followed until they end.

Submission. One batch script, OUT/slurm/campaign.sbatch, runs the worker entry point
(`/usr/bin/python3 tools/campaign/campaign.py --task $SLURM_ARRAY_TASK_ID --plan
OUT/plan.json`); array index = task index. The tasks not yet submitted go in one array,
`sbatch --parsable --array=<indices>%<workers> --job-name convoy-campaign --output
OUT/slurm/%A_%a.out --chdir OUT OUT/slurm/campaign.sbatch`, which runs at most `workers` of them
at once. Once no array is active, the tasks that failed with fewer than MAX_ATTEMPTS (2)
attempts go in a second array of only their indices: a failed task is resubmitted once.

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
(The one gap: a driver stopped between sbatch's answer and the save resubmits that array's
tasks.)

The commands run through a `runner` (subprocess.run by default) so that tests can fake Slurm.
"""

import json
import os
import re
import subprocess
import time

MAX_ATTEMPTS = 2
JOB_NAME = "convoy-campaign"


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

    def _run(self, argv):
        try:
            return self.runner(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, timeout=60)
        except (OSError, subprocess.TimeoutExpired) as e:
            raise SlurmError("%s: %s" % (argv[0], e)) from None

    def submit(self, script, indices, throttle, out_dir):
        argv = ["sbatch", "--parsable", "--array=%s%%%d" % (array_spec(indices), throttle),
                "--job-name", JOB_NAME, "--output", os.path.join(out_dir, "slurm", "%A_%a.out"),
                "--chdir", out_dir, script]
        r = self._run(argv)
        job = r.stdout.strip().split(";")[0]
        if r.returncode != 0 or not job.isdigit():
            raise SlurmError("%s failed (exit %d): %s" % (" ".join(argv), r.returncode,
                                                          (r.stderr or r.stdout).strip()))
        return job

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
    with open(path, "w") as f:
        f.write("#!/bin/sh\n"
                "# Written by tools/campaign/campaign.py: one task of the campaign in %s\n"
                "#SBATCH --cpus-per-task=1\n"
                "exec /usr/bin/python3 %s --task \"$SLURM_ARRAY_TASK_ID\" --plan %s\n" % (
                    plan["out"], campaign_py, plan_path))
    os.chmod(path, 0o755)
    return path


def _task_record(task, job_id):
    try:
        with open(os.path.join(task["run_dir"], "task.json")) as f:
            rec = json.load(f)
    except (OSError, ValueError):
        return None
    return rec if str(rec.get("job_id")) == str(job_id) else None


def run(plan, state, workers, plan_path, campaign_py, slurm=None, poll_s=1.0, patience_s=120.0,
        log=print):
    slurm = slurm or Slurm()
    script = write_script(plan, plan_path, campaign_py)
    trouble_since = None
    while True:
        try:
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
            pending = [t["index"] for t in state.tasks if t["state"] == "pending"]
            retry = [t["index"] for t in state.tasks
                     if t["state"] == "failed" and t["attempts"] < MAX_ATTEMPTS]
            batch = pending or retry
            if not batch:
                return
            job = slurm.submit(script, batch, workers, plan["out"])
            attempt = 1 + max(state.tasks[i]["attempts"] for i in batch)
            state.arrays.append({"job_id": job, "indices": batch, "attempt": attempt,
                                 "finished": False})
            for i in batch:
                t = state.tasks[i]
                t.update(state="queued", job_id=job, exit_code=None, wall_s=None, reason=None)
                t["attempts"] += 1
            state.save()
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
