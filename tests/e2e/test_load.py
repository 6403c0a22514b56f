"""Determinism under load (issue 30, part 4), label `long` only: a subset of the scenario suite
(benchmarks/suite) as a local campaign quietly (1 worker) and under load (4 workers on the
machine's cores next to a CPU hog per core), through benchmarks/load_bench.py; every
leaderboard row (but wall_s), summary.json (but its wall-clock keys), tracks.csv and
ego_planner.json must be the same. The full suite: `benchmarks/load_bench.py` (docs/benchmarks.md,
"Soak and load (issue 30)").

- UnderLoad: cut_in, jaywalker and lead_brake (a vehicle cutting in, a pedestrian crossing,
  a lead car braking), each to its own end; also that no hog outlives the benchmark.
- Compare: the comparison itself finds a changed driving score, a changed summary value and a
  changed track file (so that UnderLoad can fail), and ignores wall_s."""

import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

from e2e_util import BIN_DIR, REPO

BENCH = os.path.join(REPO, "benchmarks", "load_bench.py")
sys.path.insert(0, os.path.join(REPO, "benchmarks"))
import load_bench  # noqa: E402

SCENARIOS = ["cut_in", "jaywalker", "lead_brake"]


def hogs_of(pid):
    """Live processes whose parent is pid and that run load_bench's busy loop."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/cmdline" % entry, "rb") as f:
                cmd = f.read()
            with open("/proc/%s/stat" % entry) as f:
                stat = f.read()
        except OSError:
            continue
        ppid = int(stat[stat.rfind(")") + 2:].split()[1])
        if ppid == pid and b"getppid" in cmd:
            found.append(int(entry))
    return found


class LoadCase(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convoy-load-")
        if not os.environ.get("CONVOY_E2E_KEEP"):
            self.addCleanup(shutil.rmtree, self.tmp, True)


class UnderLoad(LoadCase):
    def test_scores_equal_under_load(self):
        out = os.path.join(self.tmp, "out")
        build = os.path.dirname(os.path.abspath(BIN_DIR))
        p = subprocess.Popen([sys.executable, BENCH, "--scenarios", ",".join(SCENARIOS),
                              "--out", out, "--build", build], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
        try:
            text, _ = p.communicate(timeout=2400)
        except subprocess.TimeoutExpired:
            p.kill()
            text, _ = p.communicate()
            self.fail("load_bench did not end within 40 min:\n" + text[-3000:])
        print(text)
        self.assertEqual(p.returncode, 0, text[-3000:])
        n = len(SCENARIOS)
        self.assertIn("driving scores equal under load: %d/%d" % (n, n), text)
        self.assertIn("leaderboard rows equal under load (all columns but wall_s): %d/%d"
                      % (n, n), text)
        self.assertIn("tasks fully equal (leaderboard row, summary.json, tracks, planner): "
                      "%d/%d" % (n, n), text)
        for mode in ("quiet", "load"):
            with open(os.path.join(out, mode, "leaderboard.csv"), newline="") as f:
                rows = list(csv.DictReader(f))
            self.assertEqual(sorted(r["scenario"] for r in rows), SCENARIOS)
            for r in rows:  # every run went to its end and was scored
                self.assertEqual(r["exit_code"], "0", r)
                self.assertNotEqual(r["driving_score"], "", r)
            for s in SCENARIOS:
                tracks = os.path.join(out, mode, "runs", "%s__s0__clear" % s, "tracks.csv")
                self.assertGreater(os.path.getsize(tracks), 1000)
        self.assertEqual(hogs_of(p.pid), [])


def fake_campaign(root, ds="81.2", x="1.0", planner="{}"):
    """A campaign folder with one task (cut_in, seed 0, clear)."""
    run = os.path.join(root, "runs", "cut_in__s0__clear")
    os.makedirs(run)
    cols = list(load_bench.KEY) + ["driving_score", "exit_code", "wall_s"]
    with open(os.path.join(root, "leaderboard.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        w.writerow(["cut_in", "0", "clear", "", ds, "0", "%.3f" % (len(root) * 1.5)])
    with open(os.path.join(run, "summary.json"), "w") as f:
        json.dump({"driving_score": float(ds), "sim_time_s": 21.8, "wall_s": len(root),
                   "pid": len(root) + 7}, f)
    with open(os.path.join(run, "tracks.csv"), "w") as f:
        f.write("t,entity,x\n0.000,Ego,%s\n" % x)
    with open(os.path.join(run, "ego_planner.json"), "w") as f:
        f.write(planner)


class Compare(LoadCase):
    def compare(self, **changed):
        q, l = os.path.join(self.tmp, "q"), os.path.join(self.tmp, "loaded")
        fake_campaign(q)
        fake_campaign(l, **changed)
        return load_bench.compare(q, l)

    def test_equal_apart_from_wall_time(self):
        self.assertEqual(self.compare(), (1, 1, 1, 1))

    def test_a_changed_driving_score(self):
        self.assertEqual(self.compare(ds="81.3"), (1, 0, 0, 0))

    def test_a_changed_track(self):
        self.assertEqual(self.compare(x="1.5"), (1, 1, 1, 0))

    def test_a_changed_planner_record(self):
        self.assertEqual(self.compare(planner='{"stops": 1}'), (1, 1, 1, 0))


if __name__ == "__main__":
    unittest.main()
