"""Campaigns survive (issue 30; docs/campaigns.md, "Restart"): a campaign killed at random
points - the campaign process (SIGKILL, SIGTERM, SIGINT), a Slurm worker
(`campaign.py --task K`), a task's `convoy run` - is started again with the same command and
the same --out; it runs only what is missing, and its leaderboard.csv equals an uninterrupted
campaign's row for row, every column but wall_s (the measured wall time of a run, which no two
runs share). As experiments/cut_in has no driving score, the leaderboard's score columns are
empty on both sides; each run's own result, cut_in.json (the cars' end states, the smallest
gap), is compared with the uninterrupted campaign's too.

Each test prints what it killed (the seeded random kill point: CONVOY_FAULTS_SEED=N repeats a
run's points) and what it found. Invariants checked at every kill: a task.json of a successful
run, once there, is never replaced (the task is not run again); a run folder without task.json
(a run cut short) is moved to previous/ and run again, never counted done; no second array is
submitted for tasks already submitted; no process is left behind.

Local: 6 tasks (cut_in, 3 seeds x clear,fog, 3 simulated s, 2 workers). Slurm (label `slurm`,
skipped without sbatch; the one-node cluster of tools/campaign/slurm_local.sh in a temp
folder, as test_campaign.Slurm): 4 tasks. The uninterrupted campaign runs once per class.
Run with Debian's /usr/bin/python3; the binaries come from $CONVOY_BIN_DIR."""

import csv
import fcntl
import json
import os
import random
import signal
import subprocess
import time
import unittest

from e2e_util import BIN_DIR, REPO, E2ETestCase

CAMPAIGN = os.path.join(REPO, "tools", "campaign", "campaign.py")
CUT_IN = os.path.join(REPO, "experiments", "cut_in", "simulation_config.json")
SEED = int(os.environ.get("CONVOY_FAULTS_SEED") or random.SystemRandom().randrange(1 << 30))
COMPARED = "every column but wall_s"


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def board(out):
    """leaderboard.csv's rows without wall_s."""
    with open(os.path.join(out, "leaderboard.csv")) as f:
        return [{k: v for k, v in row.items() if k != "wall_s"} for row in csv.DictReader(f)]


def say(msg):
    print("\n  " + msg, end="", flush=True)


class Campaign:
    """One campaign folder: the command, its processes, and what its files say."""

    def __init__(self, test, out, args, env=None):
        self.test, self.out, self.args = test, out, [str(a) for a in args]
        self.env = dict(os.environ, CONVOY_BIN_DIR=BIN_DIR, **(env or {}))
        self.n = 0

    def start(self, extra_env=None):
        self.n += 1
        log = open(os.path.join(self.test.dir, "%s.%d.log" % (os.path.basename(self.out), self.n)),
                   "w+")
        p = subprocess.Popen(["/usr/bin/python3", CAMPAIGN] + self.args + ["--out", self.out],
                             env=dict(self.env, **(extra_env or {})), stdin=subprocess.DEVNULL,
                             stdout=log, stderr=subprocess.STDOUT, preexec_fn=_default_sigint)
        p.log = log
        self.test._procs.append(p)
        self.test.addCleanup(log.close)
        return p

    def run(self, extra_env=None, timeout=120):
        p = self.start(extra_env)
        p.wait(timeout=timeout)
        return p.returncode, output(p)

    def names(self):
        plan = read_json(os.path.join(self.out, "plan.json"))
        return [t["name"] for t in plan["tasks"]] if plan else []

    def state(self):
        return read_json(os.path.join(self.out, "campaign.json")) or {"tasks": [], "arrays": []}

    def run_dir(self, name):
        return os.path.join(self.out, "runs", name)

    def record(self, name):
        return read_json(os.path.join(self.run_dir(name), "task.json"))

    def successful(self):
        """{name: task.json} of the runs that ended with exit code 0."""
        recs = {n: self.record(n) for n in self.names()}
        return {n: r for n, r in recs.items() if r is not None and r.get("exit_code") == 0}

    def partial(self):
        """Run folders without task.json: runs that did not finish."""
        return [n for n in self.names() if os.path.isdir(self.run_dir(n))
                and self.record(n) is None]

    def running(self):
        """Tasks whose run is stepping now (steps.csv there, no task.json yet)."""
        return [n for n in self.partial()
                if os.path.exists(os.path.join(self.run_dir(n), "steps.csv"))]

    def pids(self, needle):
        return list(self.processes(needle))

    def processes(self, needle):
        """{pid: command line} of the processes whose command line holds `needle`."""
        r = subprocess.run(["pgrep", "-af", "--", needle], capture_output=True, text=True)
        return {int(line.split(" ", 1)[0]): line.split(" ", 1)[1]
                for line in r.stdout.splitlines() if " " in line}

    def kill_task_process(self, rng, p, what):
        """SIGKILLs the running `convoy run` (what="run") or Slurm worker (what="worker") of
        some task, a random 0-0.3 s after it is seen; returns (task name, pid)."""
        names = self.names() or wait_for(self.names, p)
        for _ in range(20):
            if what == "run":
                needle = "--run-dir %s/" % os.path.join(self.out, "runs")
                name_of = lambda cmd: cmd.split(needle, 1)[1].split()[0]
            else:
                needle = "--plan %s" % os.path.join(self.out, "plan.json")
                name_of = lambda cmd: names[int(cmd.split("--task ", 1)[1].split()[0])]
            found = wait_for(lambda: self.processes(needle), p)
            if not found:
                break
            pid, cmd = rng.choice(sorted(found.items()))
            time.sleep(rng.uniform(0.0, 0.3))
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                continue  # it ended meanwhile: the next one
            return name_of(cmd), pid
        raise AssertionError("no %s could be killed: the campaign ended first" % what)


def _default_sigint():
    # A campaign started from a background job inherits SIGINT ignored; the tests send it.
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def output_of(path):
    with open(path) as f:
        return f.read()


def output(p):
    p.log.seek(0)
    return p.log.read()


def wait_for(cond, p=None, timeout=60.0):
    """cond()'s first true value, or None when the process p ended (or timeout) before."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        v = cond()
        if v:
            return v
        if p is not None and p.poll() is not None:
            return None
        time.sleep(0.02)
    return None


class FaultTest(E2ETestCase):
    BACKEND = "local"
    SEEDS, WEATHERS, WORKERS = 3, "clear,fog", 2
    baseline = None

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        print("\n[%s: CONVOY_FAULTS_SEED=%d; compared: %s]" % (cls.__name__, SEED, COMPARED),
              end="", flush=True)

    def setUp(self):
        super().setUp()
        self.rng = random.Random("%d/%s/%s" % (SEED, type(self).__name__, self._testMethodName))
        self.kills = 0
        self.t0 = time.monotonic()

    def tearDown(self):
        if self.BACKEND == "slurm":
            subprocess.run(["scancel", "--name", "convoy-campaign"],  # this class's cluster
                           env=dict(os.environ, **self.env), capture_output=True, timeout=30)
        print("\n  [%s: %d interruption(s), %.1f s]" % (self._testMethodName, self.kills,
                                                       time.monotonic() - self.t0), end=" ")
        super().tearDown()

    def args(self, suite):
        a = [suite, "--seeds", self.SEEDS, "--weathers", self.WEATHERS, "--workers",
             self.WORKERS, "--seconds", 3]
        return a + (["--backend", "slurm", "--poll", 0.3] if self.BACKEND == "slurm" else [])

    def campaign(self, name="out", env=None):
        suite = os.path.join(self.dir, "suite")
        os.makedirs(suite, exist_ok=True)
        with open(os.path.join(suite, "suite.json"), "w") as f:
            json.dump({"entries": [{"name": "cut_in", "config": CUT_IN}]}, f)
        return Campaign(self, os.path.join(self.dir, name), self.args(suite),
                        env=dict(getattr(self, "env", {}), **(env or {})))

    def uninterrupted(self):
        """The uninterrupted campaign's leaderboard and runs, once per class."""
        cls = type(self)
        if cls.baseline is None:
            c = self.campaign("baseline")
            code, out = c.run()
            self.assertEqual(code, 0, out)
            cls.baseline = (board(c.out), {n: read_json(os.path.join(c.run_dir(n), "cut_in.json"))
                                           for n in c.names()})
            say("uninterrupted campaign: %d rows, %.1f s" % (len(cls.baseline[0]),
                                                             time.monotonic() - self.t0))
        return cls.baseline

    # -- kill points -------------------------------------------------------------------------

    def kill_point(self, c, p):
        """Waits for a random point of campaign p; returns its description (None: p ended)."""
        kinds = ["start", "run", "end"] + (["array"] if self.BACKEND == "slurm" else [])
        kind = self.rng.choice(kinds)
        if kind == "start":
            delay = self.rng.uniform(0.05, 1.0)
            time.sleep(delay)
            what = "%.2f s after its start" % delay
        elif kind == "array":
            if not wait_for(lambda: c.state()["arrays"], p):
                return None
            delay = self.rng.uniform(0.0, 1.5)
            time.sleep(delay)
            what = "%.2f s after it saved its array" % delay
        elif kind == "run":
            names = wait_for(c.running, p)
            if not names:
                return None
            delay = self.rng.uniform(0.0, 0.6)
            time.sleep(delay)
            what = "%.2f s into the run of %s" % (delay, names[0])
        else:
            before = set(c.successful())
            if not wait_for(lambda: set(c.successful()) - before, p):
                return None
            delay = self.rng.uniform(0.0, 0.15)
            time.sleep(delay)
            what = "%.2f s after a task ended" % delay
        return what if p.poll() is None else None

    def found(self, c):
        st = {t["name"]: t["state"] for t in c.state()["tasks"]}
        ok = c.successful()
        failed = [n for n in c.names() if c.record(n) and n not in ok]
        return ("done %d, ended but not yet recorded %d, failed (interrupted) %d, %s (run folder, "
                "no task.json) %s, not started %d" % (
                    sum(1 for n in ok if st.get(n) == "done"),
                    sum(1 for n in ok if st.get(n) != "done"), len(failed),
                    "cut short" if self.BACKEND == "local" else "running under Slurm",
                    c.partial() or "none",
                    sum(1 for n in c.names() if not os.path.isdir(c.run_dir(n)))))

    def interrupt(self, c, signum, env=None):
        """Starts the campaign, sends signum to it at a random point; True if it was running."""
        p = c.start(env)
        what = self.kill_point(c, p)
        if what is None:
            p.wait(timeout=120)
            say("%s: not sent, the campaign ended first (exit %d)" % (
                signal.Signals(signum).name, p.returncode))
            return False
        p.send_signal(signum)
        p.wait(timeout=120)
        if p.returncode == 0:
            say("%s: sent as the campaign ended (exit 0); not counted" %
                signal.Signals(signum).name)
            return False
        self.kills += 1
        say("kill %d: %s to the campaign (pid %d) %s: exit %d; found %s" % (
            self.kills, signal.Signals(signum).name, p.pid, what, p.returncode, self.found(c)))
        if signum != signal.SIGKILL and p.returncode != -signum:
            # (-signum: it came before Python had set up its handlers, e.g. while importing)
            self.assertEqual(p.returncode, 130, output(p))
            self.assertIn("interrupted", output(p))
        return True

    # -- checks ----------------------------------------------------------------------------

    def check_kept(self, c, kept, partial):
        """Successful task.json files never replaced; folders cut short noted."""
        for name, rec in kept.items():
            self.assertEqual(c.record(name), rec, "%s: its successful run was run again" % name)
        kept.update(c.successful())
        if self.BACKEND == "local":  # (under Slurm the runs go on without the driver)
            partial.update(c.partial())

    def finish(self, c, kept, partial, arrays=None):
        """The same command to the end; the leaderboard and runs equal the uninterrupted ones."""
        rows, runs = self.uninterrupted()
        self.check_kept(c, kept, partial)
        missing = [n for n in c.names() if n not in kept]
        code, out = c.run()
        self.assertEqual(code, 0, out)
        self.check_kept(c, kept, partial)
        st = c.state()
        self.assertEqual({t["state"] for t in st["tasks"]}, {"done"})
        for name in partial:
            self.assertTrue(os.path.isdir(os.path.join(c.out, "previous", name)),
                            "%s: its cut-short run folder was not moved to previous/" % name)
        if arrays is not None:
            self.assertEqual(len(st["arrays"]), arrays, st["arrays"])
        got = board(c.out)
        self.assertEqual(got, rows)
        for name, result in runs.items():
            self.assertEqual(read_json(os.path.join(c.run_dir(name), "cut_in.json")), result, name)
        self.assertEqual(c.pids(c.out), [], "processes left behind")
        waits = sum(output_of(os.path.join(self.dir, f)).count("waiting for an earlier run")
                    for f in os.listdir(self.dir) if f.endswith(".log"))
        say("last start: %d task(s) without a successful run before it %s; %d cut-short "
            "folder(s) moved to previous/; %d wait(s) for an orphaned run to end; leaderboard "
            "(%d rows, %s) and every cut_in.json equal the uninterrupted run's" % (
                len(missing), missing, len(partial), waits, len(got), COMPARED))

    def kill_rounds(self, signals, arrays=None):
        c = self.campaign()
        self.uninterrupted()
        kept, partial = {}, set()
        for signum in signals:
            self.check_kept(c, kept, partial)
            self.interrupt(c, signum)
        self.assertGreater(self.kills, 0, "no kill point was reached")
        self.finish(c, kept, partial, arrays)
        return c


class Local(FaultTest):
    def test_sigkill_campaign(self):
        """Three SIGKILLs at random points (its runs get SIGTERM from their parent-death
        signal and keep their task's lock until they have ended); the first round also
        checks that a second campaign on the same --out is refused."""
        c = self.campaign()
        p = c.start()
        self.assertTrue(wait_for(lambda: os.path.exists(os.path.join(c.out, "campaign.json")), p))
        code, out = c.run()
        self.assertEqual(code, 2, out)
        self.assertIn("is in use by another campaign process (pid %d" % p.pid, out)
        p.kill()
        p.wait()
        self.kills += 1
        say("kill %d: SIGKILL to the campaign (pid %d) as it started; found %s" % (
            self.kills, p.pid, self.found(c)))
        kept, partial = {}, set()
        for _ in range(2):
            self.check_kept(c, kept, partial)
            self.interrupt(c, signal.SIGKILL)
        self.finish(c, kept, partial)

    def test_sigterm_and_sigint(self):
        self.kill_rounds([signal.SIGTERM, signal.SIGINT])

    def test_killed_run_and_missing_task_json(self):
        """A task's convoy run SIGKILLed: that task fails (exit 137), the others do not; the
        same command runs it alone. Then a done task's task.json removed: it runs again, once
        its lock (held by the test as by an orphaned run) is free; a task left "running" whose
        run has its task.json: taken, not run again."""
        c = self.campaign()
        self.uninterrupted()
        p = c.start()
        victim, pid = c.kill_task_process(self.rng, p, "run")
        p.wait(timeout=120)
        self.kills += 1
        self.assertEqual(p.returncode, 1, output(p))
        self.assertIn("%s: exit 137" % victim, output(p))
        say("kill %d: SIGKILL to the convoy run of %s (pid %d): campaign exit 1; found %s" % (
            self.kills, victim, pid, self.found(c)))
        kept, partial = {}, set()
        self.finish(c, kept, partial)
        self.assertTrue(os.path.isdir(os.path.join(c.out, "previous", victim)))
        # A task marked done whose run folder has no task.json is not done: it runs again.
        gone = self.rng.choice(c.names())
        os.unlink(os.path.join(c.run_dir(gone), "task.json"))
        del kept[gone]
        # ... while an orphaned run of it (here: the test) holds its lock: not run after the
        # wait (exit 75); then run once the lock is free.
        lock = os.open(os.path.join(c.out, "locks", gone + ".lock"), os.O_RDWR)
        fcntl.flock(lock, fcntl.LOCK_EX)
        code, out = c.run({"CONVOY_CAMPAIGN_LOCK_WAIT_S": "1"})
        self.assertEqual(code, 1, out)
        self.assertIn("%s: marked done, but" % gone, out)
        self.assertIn("%s: waiting for an earlier run of this task to end" % gone, out)
        self.assertIn("%s: an earlier run of this task still holds" % gone, out)
        self.assertIn("%s: exit 75" % gone, out)
        p = c.start()
        self.assertTrue(wait_for(lambda: "waiting for an earlier run" in output(p), p))
        os.close(lock)
        p.wait(timeout=120)
        out = output(p)
        self.assertEqual(p.returncode, 0, out)
        self.assertEqual([n for n in c.names() if c.record(n) != kept.get(n)], [gone])
        self.assertEqual(board(c.out), self.uninterrupted()[0])
        say("%s's task.json removed: with its lock held, not run (exit 75) after 1 s; lock "
            "freed: only it ran again; leaderboard equal" % gone)
        # A task left "running" whose run ended (its task.json of that attempt there: the
        # campaign was killed between the two saves) is taken as it is, not run again.
        ended = self.rng.choice(c.names())
        st = c.state()
        st["tasks"][c.names().index(ended)]["state"] = "running"
        with open(os.path.join(c.out, "campaign.json"), "w") as f:
            json.dump(st, f)
        kept = c.successful()
        code, out = c.run()
        self.assertEqual(code, 0, out)
        self.assertIn("%s: ended before the campaign stopped (exit 0" % ended, out)
        self.assertEqual(c.successful(), kept)
        say("%s left 'running' with its task.json there: taken as done, nothing ran" % ended)


if __name__ == "__main__":
    unittest.main()
