"""Slurm campaigns killed at random points and started again (test_campaign_faults.py has the
machinery and the local backend; docs/campaigns.md, "Restart"). SlurmLong (label `long`): a
task's convoy run killed under Slurm."""
import os
import shutil
import signal
import sys
import unittest

from e2e_util import start_local_slurm
from test_campaign_faults import *  # noqa: F401,F403 (the machinery: FaultTest, Campaign, say...)
from test_campaign_faults import FaultTest


class SlurmCase(FaultTest):
    BACKEND = "slurm"
    SEEDS = 2

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.env = start_local_slurm(cls, "convoy-e2e-slurm-faults-")

    def kill_in_task(self, what):
        """SIGKILLs the worker (what="worker") or the convoy run (what="run") of a random
        running task: the task fails, is resubmitted once, and the campaign ends 0."""
        c = self.campaign()
        self.uninterrupted()
        p = c.start()
        victim, pid = c.kill_task_process(self.rng, p, what)
        index = c.names().index(victim)
        started = os.path.isdir(c.run_dir(victim))
        # A worker killed in the last milliseconds, after its task.json: the task is done.
        late = (c.record(victim) or {}).get("exit_code") == 0
        self.kills += 1
        say("kill %d: SIGKILL to the %s of %s (pid %d), %s" % (
            self.kills, what, victim, pid, "after its task.json (a done task)" if late else
            "its run folder there" if started else "before it made its run folder"))
        p.wait(timeout=120)
        self.assertEqual(p.returncode, 0, output(p))
        st = c.state()
        attempts = {t["name"]: t["attempts"] for t in st["tasks"]}
        arrays = [a["indices"] for a in st["arrays"]]
        self.assertEqual(attempts[victim], 1 if late else 2)
        self.assertEqual(sum(attempts.values()), len(attempts) + (0 if late else 1))
        self.assertEqual(arrays[1:], [] if late else [[index]])
        self.assertEqual(os.path.isdir(os.path.join(c.out, "previous", victim)),
                         started and not late)
        say("found: %s %s (arrays %s); the others ran once" % (
            victim, "done" if late else "failed once and was resubmitted", arrays))
        self.finish(c, {}, set(), arrays=len(arrays))


class Slurm(SlurmCase):
    def test_sigkill_driver(self):
        """Two SIGKILLs of the driver at random points (the array keeps running): the restart
        follows the same array; exactly one array is ever submitted."""
        self.kill_rounds([signal.SIGKILL, signal.SIGKILL], arrays=1)

    def test_sigterm_and_sigint_driver(self):
        self.kill_rounds([signal.SIGTERM, signal.SIGINT], arrays=1)

    def test_killed_worker(self):
        self.kill_in_task("worker")

    def sbatch_wrapper(self, when):
        """A `sbatch` on PATH that SIGKILLs the driver (its parent) before or after the real
        sbatch submits."""
        folder = os.path.join(self.dir, "bin_" + when)
        os.makedirs(folder)
        real = shutil.which("sbatch")
        body = ('kill -9 $PPID\nexit 1\n' if when == "before" else
                'out=$(%s "$@"); rc=$?\necho "$out"\nkill -9 $PPID\nexit $rc\n' % real)
        with open(os.path.join(folder, "sbatch"), "w") as f:
            f.write("#!/bin/sh\n" + body)
        os.chmod(os.path.join(folder, "sbatch"), 0o755)
        return {"PATH": folder + os.pathsep + os.environ["PATH"]}

    def test_killed_around_sbatch(self):
        """The driver SIGKILLed right before sbatch (its intent saved, nothing submitted):
        the restart submits; then right after sbatch's answer, before the save: the restart
        finds the array by its comment and submits nothing."""
        c = self.campaign()
        self.uninterrupted()
        kept, partial = {}, set()
        for when in ("before", "after"):
            p = c.start(self.sbatch_wrapper(when))
            p.wait(timeout=60)
            self.assertEqual(p.returncode, -signal.SIGKILL, output(p))
            if when == "after":
                self.assertIn("is not in Slurm; submitting its tasks again", output(p))
            self.kills += 1
            st = c.state()
            self.assertIn("submitting", st)
            self.assertEqual(st["arrays"], [])
            say("kill %d: SIGKILL to the driver %s sbatch: found the submission recorded "
                "(token %s), no array saved" % (self.kills, when, st["submitting"]["token"]))
            if when == "before":
                continue
            code, out = c.run()
            self.assertEqual(code, 0, out)
            self.assertIn("found job array", out)
            self.assertNotIn("submitted job array", out)
            say([line for line in out.splitlines() if "found job array" in line][0])
            self.check_kept(c, kept, partial)
        st = c.state()
        self.assertNotIn("submitting", st)
        self.assertEqual([t["attempts"] for t in st["tasks"]], [1] * len(st["tasks"]))
        self.finish(c, kept, partial, arrays=1)

    def test_intent_found_from_task_json(self):
        """An unsaved submission whose array Slurm has forgotten (squeue no longer lists it) is
        found by the token its tasks wrote into task.json; without one it is dropped."""
        sys.path.insert(0, os.path.join(REPO, "python"))
        from convoy_campaign import slurm, state
        tasks = [{"index": i, "name": n, "run_dir": os.path.join(self.dir, "runs", n)}
                 for i, n in enumerate(("a", "b"))]
        for found in (True, False):
            st = state.CampaignState(os.path.join(self.dir, "campaign.json"), {
                "arrays": [], "submitting": {"token": "T%d" % found, "indices": [0, 1],
                                             "attempt": 1},
                "tasks": [{"index": i, "name": t["name"], "state": "pending", "attempts": 0}
                          for i, t in enumerate(tasks)]})
            if found:
                os.makedirs(tasks[1]["run_dir"])
                with open(os.path.join(tasks[1]["run_dir"], "task.json"), "w") as f:
                    json.dump({"name": "b", "job_id": "77", "submission": "T1", "exit_code": 0}, f)
            lines = []
            slurm._resolve_intent({"tasks": tasks}, st, type("Gone", (), {
                "find": lambda self, token: None})(), lines.append)
            self.assertNotIn("submitting", read_json(st.path))
            self.assertEqual(st.arrays, [{"job_id": "77", "indices": [0, 1], "attempt": 1,
                                          "finished": False}] if found else [])
            self.assertEqual([t["attempts"] for t in st.tasks], [1, 1] if found else [0, 0])
            say(lines[0])


class SlurmLong(SlurmCase):
    """(ctest label `long`) A task's convoy run SIGKILLed under Slurm. In the default run:
    Slurm.test_killed_worker (a task's worker SIGKILLed: failed, resubmitted once, the same
    checks) and test_campaign_faults.Local.test_killed_run_and_missing_task_json (a task's
    convoy run SIGKILLed)."""

    def test_killed_run(self):
        self.kill_in_task("run")


if __name__ == "__main__":
    unittest.main()
