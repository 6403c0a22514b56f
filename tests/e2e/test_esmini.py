"""esmini's example scenarios through Convoy (issue 25; docs/scenarios.md, "Agreement with
esmini"), on the copies and reference tracks committed in tests/data/esmini:

- Agreement: benchmarks/esmini_compare.py runs all 69 with `convoy run --scenario FILE --ego
  scenario` and compares each run's tracks.csv with esmini's; every scenario meets what
  tests/data/esmini/expected.json says of it (within 0.5 m, or a listed, explained difference).
- EgoScenario: the same run twice gives the same tracks.csv byte for byte; tracks.csv's
  columns; --scenario-param reaches the scenario; a scenario without a road network runs.
- BadInput: an element Convoy does not read, a missing map and a missing catalog end before any
  engine starts, exit 2, one message naming the file, line and element (or path).
- DefaultEgo: one esmini scenario with the stack under test driving the ego, a few seconds.

Run: cd tests/e2e && CONVOY_BIN_DIR=/work/main/build/bin /usr/bin/python3 -m unittest -v test_esmini
"""

import csv
import json
import os
import shutil
import subprocess
import sys
import unittest

from e2e_util import CONVOY, REPO, E2ETestCase

ESMINI = os.path.join(REPO, "tests", "data", "esmini")
XOSC = os.path.join(ESMINI, "xosc")
BENCH = os.path.join(REPO, "benchmarks", "esmini_compare.py")
TRACKS_HEADER = ["t", "entity", "x", "y", "z", "heading", "speed", "road", "lane", "s"]


class EsminiCase(E2ETestCase):
    def scenario_run(self, xosc, *extra, run_dir=None, timeout=120):
        run_dir = run_dir or os.path.join(self.dir, "run_" + os.path.basename(xosc)[:-5])
        cmd = [CONVOY, "run", "--scenario", xosc, "--run-dir", run_dir, "-q"] + list(extra)
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
        return p, run_dir

    def assert_no_engines_left(self):
        """No process of this test's runs (their command lines name its folder) is left."""
        out = subprocess.run(["pgrep", "-f", self.dir], capture_output=True, text=True)
        self.assertEqual(out.stdout.strip(), "", "a process was left behind")


class Agreement(EsminiCase):
    def test_every_example_as_expected(self):
        with open(os.path.join(ESMINI, "expected.json")) as f:
            expected = json.load(f)
        out = os.path.join(self.dir, "compare")
        report = os.path.join(self.dir, "compare.json")
        p = subprocess.run([sys.executable, BENCH, XOSC, "--convoy", CONVOY, "--out", out,
                            "--json", report], capture_output=True, text=True, timeout=1500)
        self.assertEqual(p.returncode, 0, p.stderr[-2000:])
        with open(report) as f:
            results = {r["name"]: r for r in json.load(f)["scenarios"]}
        self.assertEqual(len(results), 69)
        problems = []
        for name, r in sorted(results.items()):
            if name in expected["refused"]:
                if r["status"] != "refused":
                    problems.append("%s: expected refused, got %s" % (name, r["status"]))
                continue
            if r["status"] != "run":
                problems.append("%s: %s: %s" % (name, r["status"], r.get("message")))
                continue
            if name in expected["differ"]:
                continue
            err, cov = r.get("position_error_m"), r.get("coverage", 0.0)
            if err is None or err > 0.5 or cov < 0.95:
                problems.append("%s: position error %s m over %.0f%% of esmini's steps" % (
                    name, err, 100 * cov))
        self.assertEqual(problems, [], "\n".join(problems))
        ran = sum(1 for r in results.values() if r["status"] == "run")
        within = sum(1 for r in results.values() if r.get("position_error_m") is not None and
                     r["position_error_m"] <= 0.5 and r["coverage"] >= 0.95)
        self.assertGreaterEqual(ran, expected["min_run"])
        self.assertGreaterEqual(within, expected["min_within"])


class EgoScenario(EsminiCase):
    def test_same_run_same_tracks(self):
        xosc = os.path.join(XOSC, "cut-in.xosc")
        a, dir_a = self.scenario_run(xosc, "--ego", "scenario", run_dir=os.path.join(self.dir, "a"))
        b, dir_b = self.scenario_run(xosc, "--ego", "scenario", run_dir=os.path.join(self.dir, "b"))
        self.assertEqual((a.returncode, b.returncode), (0, 0), a.stderr + b.stderr)
        with open(os.path.join(dir_a, "tracks.csv"), "rb") as fa, \
                open(os.path.join(dir_b, "tracks.csv"), "rb") as fb:
            self.assertEqual(fa.read(), fb.read())
        with open(os.path.join(dir_a, "tracks.csv")) as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows[0], TRACKS_HEADER)
        self.assertEqual({r[1] for r in rows[1:]}, {"Ego", "OverTaker"})
        self.assertEqual(rows[1][:2], ["0.000", "Ego"])
        with open(os.path.join(dir_a, "summary.json")) as f:
            self.assertTrue(json.load(f)["status_function_done"])   # its StopTrigger ended it

    def test_scenario_param(self):
        xosc = os.path.join(XOSC, "cut-in.xosc")
        p, run_dir = self.scenario_run(xosc, "--ego", "scenario", "--scenario-param", "EgoSpeed=36",
                                       "-o", "SimulationTimeout=1")
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(run_dir, "tracks.csv")) as f:
            ego = [r for r in csv.DictReader(f) if r["entity"] == "Ego"]
        self.assertAlmostEqual(float(ego[0]["speed"]), 10.0, places=3)   # 36 km/h

    def test_no_road_network(self):
        p, run_dir = self.scenario_run(os.path.join(XOSC, "parking_lot.xosc"), "--ego", "scenario",
                                       "-o", "SimulationTimeout=3")
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(run_dir, "tracks.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertTrue(rows)
        self.assertTrue(all(r["road"] == "" for r in rows))   # free: no lanes


class BadInput(EsminiCase):
    def copy_example(self, name):
        d = os.path.join(self.dir, "xosc")
        if not os.path.isdir(d):
            shutil.copytree(XOSC, d)
            shutil.copytree(os.path.join(ESMINI, "xodr"), os.path.join(self.dir, "xodr"))
        return os.path.join(d, name)

    def refused(self, xosc, *needles):
        p, run_dir = self.scenario_run(xosc, "--ego", "scenario")
        self.assertEqual(p.returncode, 2, p.stderr)
        for n in needles:
            self.assertIn(n, p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        self.assertFalse(os.path.exists(os.path.join(run_dir, "tracks.csv")))
        self.assert_no_engines_left()

    def test_unsupported_element(self):
        xosc = self.copy_example("cut-in.xosc")
        with open(xosc) as f:
            text = f.read()
        text = text.replace("<GlobalAction>", "<UserDefinedAction><CustomCommandAction type=\"x\"/>"
                            "</UserDefinedAction><GlobalAction>", 1) if "<GlobalAction>" in text else \
            text.replace("<Private entityRef=\"Ego\">", "<UserDefinedAction/><Private entityRef=\"Ego\">", 1)
        with open(xosc, "w") as f:
            f.write(text)
        self.refused(xosc, "cut-in.xosc:", "<UserDefinedAction>", "is not supported")

    def test_missing_map(self):
        xosc = self.copy_example("cut-in.xosc")
        os.remove(os.path.join(self.dir, "xodr", "e6mini.xodr"))
        self.refused(xosc, "cut-in.xosc:", "<LogicFile>", "e6mini.xodr")

    def test_missing_catalog(self):
        self.refused(os.path.join(XOSC, "car_walk.xosc"), "car_walk.xosc:15:", "<CatalogReference>",
                     "/tmp/openx-assets/catalogs", "does not exist")


class DefaultEgo(EsminiCase):
    def test_stack_drives_the_ego(self):
        p, run_dir = self.scenario_run(os.path.join(XOSC, "cut-in.xosc"), "-o", "SimulationTimeout=3",
                                       timeout=300)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(run_dir, "scenario_config.json")) as f:
            cfg = json.load(f)
        scen = next(e for e in cfg["EngineConfigs"] if e["EngineType"] == "scenario")
        self.assertEqual(scen["Entities"]["OverTaker"], "scenario")   # the default controller
        self.assertEqual(scen["Entities"]["Ego"], "gazebo/smart_car::road_user")
        with open(os.path.join(run_dir, "tracks.csv")) as f:
            names = {r["entity"] for r in csv.DictReader(f)}
        self.assertEqual(names, {"Ego", "OverTaker"})


if __name__ == "__main__":
    unittest.main()
