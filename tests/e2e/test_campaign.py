"""tools/campaign/campaign.py: campaigns of experiments over seeds and weathers, on this machine
and on a one-node Slurm cluster (docs/campaigns.md).

Local: a 4-task campaign of experiments/cut_in (2 seeds x 2 weathers, 3 simulated s each), its
leaderboard, report and the runs' configs; a second campaign gives the same leaderboard
(apart from wall_s) and the same runs; the leaderboard's score columns from a scorer.
Slurm (ctest label `slurm`; skipped only without sbatch): the cluster from
tools/campaign/slurm_local.sh in a temp folder; a 4-task campaign; a failing task resubmitted
once. SlurmLong (labels `slurm` and `long`): a driver killed while its array runs, then the
same command again (test_campaign_faults_slurm.Slurm does the same at random points).
BadInput: one message naming the file or option, exit 2; a failing task under the local
backend: the leaderboard is written, exit 1.
Distribution: an OpenSCENARIO parameter distribution (2 variants of benchmarks/suite/cut_in.xosc,
3 simulated s each) runs one task per variant, its parameters in the config and leaderboard.

Run with Debian's /usr/bin/python3; the binaries come from $CONVOY_BIN_DIR."""

import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

from e2e_util import BIN_DIR, REPO, E2ETestCase, start_local_slurm

CAMPAIGN = os.path.join(REPO, "tools", "campaign", "campaign.py")
CUT_IN = os.path.join(REPO, "experiments", "cut_in", "simulation_config.json")
MISSING_MAP = 'EngineConfigs/0/Map="missing_world.xodr"'
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_campaign import report, results, state  # noqa: E402 (after the path)


def campaign(*args, env=None, timeout=110):
    e = dict(os.environ, CONVOY_BIN_DIR=BIN_DIR)
    e.update(env or {})
    return subprocess.run(["/usr/bin/python3", CAMPAIGN] + [str(a) for a in args], env=e,
                          stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout)


def read_board(out):
    with open(os.path.join(out, "leaderboard.csv")) as f:
        return list(csv.DictReader(f))


def read_json(path):
    with open(path) as f:
        return json.load(f)


def write_suite(folder, entries):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "suite.json"), "w") as f:
        json.dump({"entries": entries}, f, indent=1)
    return folder


class CampaignTest(E2ETestCase):
    """E2ETestCase's temp folder (self.dir), its skip without a coordinator and its clean-up."""

    def setUp(self):
        super().setUp()
        self.t0 = time.monotonic()

    def tearDown(self):
        print("\n[%s: %.1f s]" % (self._testMethodName, time.monotonic() - self.t0), end=" ")
        super().tearDown()  # its temp folder and any process left in it

    def assertExit(self, r, code):
        self.assertEqual(r.returncode, code, "exit %d\n--- stdout ---\n%s\n--- stderr ---\n%s" % (
            r.returncode, r.stdout, r.stderr))

    def cut_in_suite(self, name="suite", bad=False):
        entries = [{"name": "cut_in", "config": CUT_IN}]
        if bad:
            entries.append({"name": "cut_in_no_map", "config": CUT_IN, "overrides": [MISSING_MAP]})
        return write_suite(os.path.join(self.dir, name), entries)


class Local(CampaignTest):
    def test_four_tasks_deterministic(self):
        suite = self.cut_in_suite()
        outs = [os.path.join(self.dir, "out%d" % i) for i in range(2)]
        boards = []
        for out in outs:
            r = campaign(suite, "--seeds", 2, "--weathers", "fog,clear", "--workers", 2,
                         "--seconds", 3, "--out", out)
            self.assertExit(r, 0)
            self.assertIn("all 4 tasks succeeded", r.stdout)
            rows = read_board(out)
            self.assertEqual([(x["scenario"], x["seed"], x["weather"]) for x in rows],
                             [("cut_in", "0", "clear"), ("cut_in", "0", "fog"),
                              ("cut_in", "1", "clear"), ("cut_in", "1", "fog")])
            self.assertEqual(list(rows[0]), list(results.COLUMNS))
            for x in rows:
                self.assertEqual(x["exit_code"], "0")
                self.assertGreater(float(x["wall_s"]), 0.0)
                self.assertEqual(x["driving_score"], "")   # no convoy_bench on this branch
            boards.append([{k: v for k, v in x.items() if k != "wall_s"} for x in rows])
            with open(os.path.join(out, "report.html")) as f:
                page = f.read()
            self.assertIn("cut_in", page)
            self.assertNotIn("<script", page)
            self.assertNotIn("http://", page.replace('xmlns="http://www.w3.org/2000/svg"', ""))
        self.assertEqual(boards[0], boards[1])
        # The seed and the weather reached the runs, and the runs are the same in both.
        for seed in (0, 1):
            for weather, visibility in (("clear", 20000.0), ("fog", 100.0)):
                name = "cut_in__s%d__%s" % (seed, weather)
                cfg = read_json(os.path.join(outs[0], "runs", name, "config.json"))
                w = [e for e in cfg["EngineConfigs"] if e["EngineName"] == "weather"][0]
                self.assertEqual((w["Seed"], w["Visibility"], w["Schedule"]), (seed, visibility, []))
                self.assertEqual(cfg["SimulationTimeout"], 3.0)
                runs = [read_json(os.path.join(o, "runs", name, "cut_in.json")) for o in outs]
                self.assertEqual(runs[0], runs[1])
        # Scores, as convoy_bench's score_run gives them, fill the score columns.
        def fake_score(run_dir):
            seed = read_json(os.path.join(run_dir, "config.json"))["EngineConfigs"][1]["Seed"]
            return {"driving_score": 80.0 - 10 * seed, "route_completion": 100.0,
                    "infraction_penalty": 0.8 - 0.1 * seed, "route_length_m": 500.0,
                    "infractions": [{"t": 1.0, "kind": "red_light", "other": "s1", "penalty": 0.7},
                                    {"t": 2.0, "kind": "collision_vehicle", "other": "car_0",
                                     "penalty": 1.0, "counted": False}]}
        plan = read_json(os.path.join(outs[0], "plan.json"))
        st = state.CampaignState.open(outs[0], plan, "local")
        records = results.collect(plan, st, fake_score)
        results.write(outs[0], records)
        rows = read_board(outs[0])
        self.assertEqual([x["driving_score"] for x in rows], ["80.0", "80.0", "70.0", "70.0"])
        self.assertEqual({(x["red_light"], x["collision_vehicle"], x["stop_sign"]) for x in rows},
                         {("1", "0", "0")})
        page = report.render(records, plan)
        self.assertIn("per km", page)
        self.assertIn("<svg", page)
        # No recordings: no dashboard links, no "convoy view" line.
        self.assertNotIn("mcap=", page)
        self.assertNotIn("convoy view", page)


    def test_record_gives_each_run_a_recording_linked_from_the_report(self):
        out = os.path.join(self.dir, "out")
        r = campaign(self.cut_in_suite(), "--weathers", "clear", "--seconds", 2, "--record",
                     "--out", out)
        self.assertExit(r, 0)
        run_dir = os.path.join(out, "runs", "cut_in__s0__clear")
        self.assertTrue(os.path.isfile(os.path.join(run_dir, "recording.mcap")))
        self.assertIn("--record", read_json(os.path.join(out, "plan.json"))["tasks"][0]["argv"])
        with open(os.path.join(out, "report.html")) as f:
            page = f.read()
        self.assertIn('href="/?mcap=/files/runs/cut_in__s0__clear/recording.mcap"', page)
        self.assertIn("<code>convoy view %s</code>" % out, page)


class SlurmCase(CampaignTest):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        cls.env = start_local_slurm(cls, "convoy-e2e-slurm-")

    def run_slurm(self, suite, out, *extra):
        return campaign(suite, "--backend", "slurm", "--out", out, "--poll", 0.3, *extra, env=self.env)


class Slurm(SlurmCase):
    def test_four_tasks(self):
        out = os.path.join(self.dir, "out")
        r = self.run_slurm(self.cut_in_suite(), out, "--seeds", 2, "--weathers", "clear,night",
                           "--workers", 2, "--seconds", 3)
        self.assertExit(r, 0)
        rows = read_board(out)
        self.assertEqual([(x["seed"], x["weather"], x["exit_code"]) for x in rows],
                         [("0", "clear", "0"), ("0", "night", "0"), ("1", "clear", "0"),
                          ("1", "night", "0")])
        st = read_json(os.path.join(out, "campaign.json"))
        self.assertEqual(len(st["arrays"]), 1)
        self.assertEqual([t["attempts"] for t in st["tasks"]], [1, 1, 1, 1])
        for t in st["tasks"]:
            rec = read_json(os.path.join(out, "runs", t["name"], "task.json"))
            self.assertEqual((rec["exit_code"], rec["job_id"]), (0, st["arrays"][0]["job_id"]))
        self.assertTrue(os.path.isfile(os.path.join(out, "report.html")))

    def test_failing_task_resubmitted_once(self):
        out = os.path.join(self.dir, "out")
        r = self.run_slurm(self.cut_in_suite(bad=True), out, "--workers", 2, "--seconds", 2)
        self.assertExit(r, 1)
        self.assertIn("1 of 2 tasks failed", r.stderr)
        self.assertIn("cut_in_no_map__s0__clear: exit 2", r.stderr)
        st = read_json(os.path.join(out, "campaign.json"))
        tasks = {t["name"]: t for t in st["tasks"]}
        self.assertEqual(tasks["cut_in__s0__clear"]["attempts"], 1)
        self.assertEqual(tasks["cut_in_no_map__s0__clear"]["attempts"], 2)
        self.assertEqual([a["indices"] for a in st["arrays"]], [[0, 1], [1]])
        with open(tasks["cut_in_no_map__s0__clear"]["log"]) as f:
            self.assertIn("missing_world.xodr", f.read())
        rows = read_board(out)
        self.assertEqual([(x["scenario"], x["exit_code"]) for x in rows],
                         [("cut_in", "0"), ("cut_in_no_map", "2")])
        with open(os.path.join(out, "report.html")) as f:
            self.assertIn("missing_world.xodr", f.read())   # the failed task's log tail



class SlurmLong(SlurmCase):
    """(ctest label `long`) The driver SIGKILLed once a task is done and started again: in the
    default run, e2e_campaign_faults.Slurm (test_sigkill_driver) kills the driver at random
    points and checks the same (one array, the same job, done tasks kept and not run again,
    the same leaderboard)."""

    def test_restart(self):
        out = os.path.join(self.dir, "out")
        suite = self.cut_in_suite()
        args = ["/usr/bin/python3", CAMPAIGN, suite, "--backend", "slurm", "--out", out, "--poll", 0.3, "--seeds", 4,
                "--workers", 1, "--seconds", 8]
        env = dict(os.environ, CONVOY_BIN_DIR=BIN_DIR, **self.env)
        p = subprocess.Popen([str(a) for a in args], env=env, stdin=subprocess.DEVNULL,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        self.addCleanup(lambda: p.poll() is None and p.kill())
        state_path = os.path.join(out, "campaign.json")
        deadline = time.monotonic() + 90
        done = []
        while time.monotonic() < deadline and p.poll() is None:
            try:
                done = [t for t in read_json(state_path)["tasks"] if t["state"] == "done"]
            except (OSError, ValueError):
                done = []
            if done:
                break
            time.sleep(0.1)
        self.assertTrue(done, "no task finished within 90 s")
        self.assertIsNone(p.poll(), "the campaign ended before it could be killed")
        os.kill(p.pid, signal.SIGKILL)
        p.wait()
        before = read_json(state_path)
        self.assertEqual(len(before["arrays"]), 1)
        self.assertLess(len([t for t in before["tasks"] if t["state"] == "done"]), 4)
        finished = {t["name"]: read_json(os.path.join(out, "runs", t["name"], "task.json"))
                    for t in before["tasks"] if t["state"] == "done"}
        r = self.run_slurm(suite, out, "--seeds", 4, "--workers", 1, "--seconds", 8)
        self.assertExit(r, 0)
        self.assertNotIn("submitted", r.stdout)
        after = read_json(state_path)
        self.assertEqual(after["arrays"][0]["job_id"], before["arrays"][0]["job_id"])
        self.assertEqual(len(after["arrays"]), 1)
        self.assertEqual([t["attempts"] for t in after["tasks"]], [1, 1, 1, 1])
        for name, rec in finished.items():
            self.assertEqual(read_json(os.path.join(out, "runs", name, "task.json")), rec)
        self.assertEqual([x["exit_code"] for x in read_board(out)], ["0"] * 4)


class Interrupt(CampaignTest):
    def interrupt(self, signum, command=("/usr/bin/python3", CAMPAIGN)):
        """A local campaign of four 600 s runs (about 40 s each), one at a time, sent `signum` (to the campaign
        alone) while its first run is going: it stops within seconds, exit 130, passing the
        signal on to that run (which ends as convoy run does), starting no other, leaving no
        process behind; the same command then runs what is left."""
        suite = self.cut_in_suite()
        out = os.path.join(self.dir, "out")
        e = dict(os.environ, CONVOY_BIN_DIR=BIN_DIR)
        p = subprocess.Popen(list(command) + [suite, "--seeds", "4", "--workers", "1",
                              "--seconds", "600", "--out", out], env=e, stdin=subprocess.DEVNULL,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            first = os.path.join(out, "runs", "cut_in__s0__clear", "summary.json")
            deadline = time.monotonic() + 60
            steps = os.path.join(out, "runs", "cut_in__s0__clear", "steps.csv")
            while time.monotonic() < deadline and not os.path.exists(steps):
                time.sleep(0.1)
            time.sleep(1.0)  # the first run is stepping
            p.send_signal(signum)
            stdout, stderr = p.communicate(timeout=60)
        finally:
            if p.poll() is None:
                p.kill()
                p.communicate()
        self.assertEqual(p.returncode, 130, stdout + stderr)
        self.assertIn("interrupted", stderr)
        # the run in flight ended as convoy run does when interrupted: its folder has a summary
        self.assertTrue(os.path.exists(first))
        tasks = read_json(os.path.join(out, "campaign.json"))["tasks"]
        self.assertEqual([t["state"] for t in tasks[1:]], ["pending"] * 3)
        self.assertEqual([t["attempts"] for t in tasks[1:]], [0] * 3)
        left = subprocess.run(["pgrep", "-f", out], capture_output=True, text=True).stdout.split()
        self.assertEqual(left, [], "processes left behind")

    def test_ctrl_c(self):
        self.interrupt(signal.SIGINT)

    def test_sigterm(self):
        self.interrupt(signal.SIGTERM)

    def test_sigterm_to_convoy_campaign(self):
        # `convoy campaign` becomes the campaign (exec): the signal reaches it
        self.interrupt(signal.SIGTERM, (os.path.join(BIN_DIR, "convoy"), "campaign"))


class RecordingLinks(unittest.TestCase):
    """report.html links each run that has a recording.mcap to the dashboard as `convoy view
    CAMPAIGN_DIR` serves it (no engines run here)."""

    def test_runs_with_a_recording_link_to_the_dashboard(self):
        out = tempfile.mkdtemp(prefix="convoy_report_")
        self.addCleanup(shutil.rmtree, out, True)
        records = []
        for seed in (0, 1):
            name = "cut in__s%d__clear" % seed
            run_dir = os.path.join(out, "runs", name)
            os.makedirs(run_dir)
            records.append({"name": name, "scenario": "cut_in", "seed": seed, "weather": "clear",
                            "config": "cut_in.json", "run_dir": run_dir, "state": "done",
                            "exit_code": 0, "attempts": 1, "wall_s": 1.0, "reason": None,
                            "log": os.path.join(run_dir, "task.log"), "summary": {},
                            "score": None})
        plan = {"seeds": 2, "weathers": ["clear"], "out": out}
        page = report.render(records, plan)
        self.assertNotIn("mcap=", page)
        self.assertNotIn("convoy view", page)
        with open(os.path.join(out, "runs", "cut in__s1__clear", "recording.mcap"), "wb") as f:
            f.write(b"\x89MCAP0\r\n")
        page = report.render(records, plan)
        self.assertIn("open with <code>convoy view CAMPAIGN_DIR</code>", page)
        self.assertIn("<code>convoy view %s</code>" % out, page)
        self.assertEqual(page.count("mcap="), 1)   # only the run with a recording
        self.assertIn('<a href="/?mcap=/files/runs/cut%20in__s1__clear/recording.mcap">view</a>',
                      page)
        self.assertLess(page.index("convoy view"), page.index("<h2>"))   # at the top
        self.assertNotIn("<script", page)


class BadInput(CampaignTest):
    def assertBad(self, r, *needles):
        self.assertExit(r, 2)
        lines = [l for l in r.stderr.splitlines() if l.startswith("campaign: error:")]
        self.assertEqual(len(lines), 1, r.stderr)
        for n in needles:
            self.assertIn(n, r.stderr)

    def test_missing_suite(self):
        missing = os.path.join(self.dir, "no_such_suite")
        self.assertBad(campaign(missing), missing, "does not exist")

    def test_empty_suite(self):
        os.makedirs(os.path.join(self.dir, "empty"))
        self.assertBad(campaign(os.path.join(self.dir, "empty")), "holds no run definitions")

    def test_missing_config(self):
        config = os.path.join(self.dir, "nowhere", "simulation_config.json")
        suite = write_suite(os.path.join(self.dir, "s"), [{"config": config}])
        self.assertBad(campaign(suite, "--out", os.path.join(self.dir, "out")), config,
                       "does not exist")

    def test_bad_suite_entry(self):
        suite = write_suite(os.path.join(self.dir, "s"), [{"config": CUT_IN, "seed": 3}])
        self.assertBad(campaign(suite), "suite.json: /entries/0/seed: unknown key")

    def test_config_without_weather_engine(self):
        config = os.path.join(REPO, "experiments", "tf_exchange", "simulation_config.json")
        suite = write_suite(os.path.join(self.dir, "s"), [{"config": config}])
        self.assertBad(campaign(suite, "--out", os.path.join(self.dir, "out")), config,
                       "no engine named 'weather'")

    def test_unknown_weather(self):
        self.assertBad(campaign(self.cut_in_suite(), "--weathers", "clear,hail"),
                       "--weathers", "unknown weather 'hail'")

    def test_slurm_without_sbatch(self):
        empty = os.path.join(self.dir, "bin")
        os.makedirs(empty)
        self.assertBad(campaign(self.cut_in_suite(), "--backend", "slurm", env={"PATH": empty}),
                       "--backend slurm", "'sbatch' is not on PATH")

    def test_missing_build(self):
        build = os.path.join(self.dir, "no_build")
        self.assertBad(campaign(self.cut_in_suite(), "--build", build), build, "--build")

    def test_failing_task_local(self):
        out = os.path.join(self.dir, "out")
        r = campaign(self.cut_in_suite(bad=True), "--seconds", 1, "--out", out)
        self.assertExit(r, 1)
        self.assertIn("1 of 2 tasks failed", r.stderr)
        self.assertIn(os.path.join(out, "runs", "cut_in_no_map__s0__clear", "task.log"), r.stderr)
        self.assertEqual([(x["scenario"], x["exit_code"]) for x in read_board(out)],
                         [("cut_in", "0"), ("cut_in_no_map", "2")])
        # The same --out with another plan is refused.
        self.assertBad(campaign(self.cut_in_suite(bad=True), "--seconds", 1, "--seeds", 2,
                                "--out", out), os.path.join(out, "campaign.json"),
                       "holds another campaign")


class Distribution(CampaignTest):
    """An OpenSCENARIO parameter distribution as a suite entry: one task per variant, its
    parameters in the generated config and in the leaderboard; a bad distribution is bad input."""

    DIST = """<?xml version="1.0"?>
<OpenSCENARIO>
  <FileHeader revMajor="1" revMinor="2" date="2026-11-27T00:00:00" description="d" author="t"/>
  <ParameterValueDistribution>
    <ScenarioFile filepath="%s"/>
    <Deterministic>
      <DeterministicSingleParameterDistribution parameterName="EgoS">
        <DistributionRange stepWidth="10"><Range lowerLimit="30" upperLimit="40"/></DistributionRange>
      </DeterministicSingleParameterDistribution>
    </Deterministic>
  </ParameterValueDistribution>
</OpenSCENARIO>
"""

    def suite(self, scenario):
        folder = os.path.join(self.dir, "suite")
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, "ego_start.xosc"), "w") as f:
            f.write(self.DIST % scenario)
        return folder

    def test_variants_run(self):
        out = os.path.join(self.dir, "out")
        r = campaign(self.suite(os.path.join(REPO, "benchmarks", "suite", "cut_in.xosc")),
                     "--workers", 2, "--seconds", 3, "--out", out)
        self.assertExit(r, 0)
        self.assertIn("campaign: 2 tasks", r.stdout)
        rows = read_board(out)
        self.assertEqual([(x["scenario"], x["parameters"], x["exit_code"]) for x in rows],
                         [("ego_start_001", "EgoS=30", "0"), ("ego_start_002", "EgoS=40", "0")])
        plan = read_json(os.path.join(out, "plan.json"))
        self.assertEqual([t["parameters"] for t in plan["tasks"]], [{"EgoS": 30.0}, {"EgoS": 40.0}])
        xs = []
        for name, s in (("ego_start_001", 30.0), ("ego_start_002", 40.0)):
            cfg = read_json(os.path.join(out, "runs", name + "__s0__clear", "scenario_config.json"))
            scen = [e for e in cfg["EngineConfigs"] if e["EngineType"] == "scenario"][0]
            self.assertEqual(scen["Parameters"], {"EgoS": s})
            xs.append(cfg["EngineConfigs"][0]["GazeboSDFModels"][0]["InitPose"][0])
        self.assertAlmostEqual(xs[1] - xs[0], 10.0)  # the ego starts where EgoS says

    def test_missing_scenario_is_bad_input(self):
        missing = os.path.join(self.dir, "nowhere", "cut_in.xosc")
        r = campaign(self.suite(missing), "--out", os.path.join(self.dir, "out"))
        self.assertExit(r, 2)
        self.assertIn("ego_start.xosc:5: <ScenarioFile> filepath: the scenario file %s does not exist"
                      % missing, r.stderr)


if __name__ == "__main__":
    unittest.main()
