"""The scenario engine (engines/scenario, python/convoy_scenario/engine_script.py), `convoy run
--scenario` and the live driving score (docs/scenarios.md, docs/scoring.md).

Engine: the fixtures of tests/unit/scenarios run by the scenario engine in lock-step with
kinematic road users (scenario/stand_in.py, python_json engines obeying the command contract),
end to end through scenario_tf.py and the status function: a speed action (lead_brake: the lead
brakes to a stop, waits 2 s, drives off), a lane change (cut_in: the cutter ends in the ego's
lane), an AssignRouteAction (a generated scenario: the car drives through the route's
positions), a timed trajectory (follow_trajectory), a pedestrian's untimed trajectory
(pedestrian_crossing: the walker crosses the road), weather (environment: the weather engine
turns to a snowy night through its ControlDataPack), and the end of the run at the StopTrigger.
BadInput: an .xosc outside the subset, at start and while running; an unknown map; each one
message naming the file (and element and line), a non-zero exit, no engine left behind.
Run: `convoy run --scenario` on a suite scenario (the city map, the report's ego), its first
14 simulated seconds (both its infractions, then SimulationTimeout's): the summary's driving
score; a second run gives the same score, bit for bit. Campaign: a local 4-task
campaign over .xosc entries. Long (ctest label `long`): 20 repeats of one scenario, and the
whole suite.

Run with Debian's /usr/bin/python3; the binaries come from $CONVOY_BIN_DIR."""

import csv
import json
import os
import subprocess
import sys
import time
import unittest

from e2e_util import BIN_DIR, CONVOY, REPO, E2ETestCase

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_scenario import load  # noqa: E402
from convoy_scenario.make_config import init_pose  # noqa: E402
from convoy_scenario.player import Player  # noqa: E402
from convoy_scenario.player_state import NoRoads  # noqa: E402
from convoy_scenario.roads import RoadMap  # noqa: E402

FIXTURES = os.path.join(REPO, "tests", "unit", "scenarios")
STAND_IN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenario", "stand_in.py")
SCEN_PY = os.path.join(REPO, "python", "convoy_scenario")
SUITE = os.path.join(REPO, "benchmarks", "suite")
CAMPAIGN = os.path.join(REPO, "tools", "campaign", "campaign.py")


def read_jsonl(path):
    with open(path) as f:
        return [json.loads(line) for line in f if line.strip()]


class ScenarioCase(E2ETestCase):
    def stand_in_config(self, xosc, timeout=30.0, weather=False, parameters=None):
        """A config: the scenario engine on xosc, one stand-in per entity (the ego's state only,
        never commanded), the scenario TF and status function."""
        sc = load(xosc, parameters=parameters)
        player = Player(sc, RoadMap(sc.logic_file, BIN_DIR) if sc.logic_file else NoRoads(),
                        [e.name for e in sc.entities])
        engines, entities = [], {}
        for ent in sc.entities:
            pose = init_pose(sc, ent.name, player) or (0.0, 0.0, 0.0)
            name = ent.name.lower()
            bb = ent.object.bounding_box
            engines.append({"EngineType": "python_json", "EngineName": name, "PythonFileName": STAND_IN,
                            "EngineTimestep": 0.05, "CommandDataPack": "command",
                            "Category": "pedestrian" if ent.kind == "pedestrian" else "car",
                            "Length": bb.length, "Width": bb.width,
                            "Start": {"x": pose[0], "y": pose[1], "yaw": pose[2],
                                      "speed": player.states[ent.name].speed}})
            entities[ent.name] = name + "/state" if ent.name == "Ego" else name
        if weather:
            engines.append({"EngineType": "weather", "EngineName": "weather", "EngineTimestep": 0.05})
        engines.append({"EngineType": "scenario", "EngineName": "scenario", "EngineTimestep": 0.05,
                        "ScenarioFile": xosc, "Entities": entities, "Parameters": parameters or {}})
        return {"SimulationName": "scenario_test", "SimulationTimeout": timeout, "EngineConfigs": engines,
                "DataPackProcessingFunctions": [{"Name": "scenario_tf", "FileName": os.path.join(SCEN_PY, "scenario_tf.py")}],
                "StatusFunction": {"Name": "scenario_status", "FileName": os.path.join(SCEN_PY, "status.py")}}

    def run_fixture(self, xosc, **kw):
        self.write_config(self.stand_in_config(xosc, **kw))
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        return r

    def track(self, name):
        return read_jsonl(os.path.join(self.run_dir, name + ".jsonl"))

    def scenario_log(self):
        with open(os.path.join(self.run_dir, "logs", "scenario.log")) as f:
            return f.read()

    def run_scenario(self, xosc, *args, run_dir=None, timeout=300):
        run_dir = run_dir or self.run_dir
        p = subprocess.Popen([CONVOY, "run", "-q", "--scenario", xosc, "--run-dir", run_dir] + list(args),
                             cwd=self.dir, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             stdin=subprocess.DEVNULL)
        self._procs.append(p)
        out, err = p.communicate(timeout=timeout)
        return p.returncode, out, err

    def summary(self, run_dir=None):
        with open(os.path.join(run_dir or self.run_dir, "summary.json")) as f:
            return json.load(f)


class Engine(ScenarioCase):
    def test_speed_actions_lead_brake(self):
        self.run_fixture(os.path.join(FIXTURES, "lead_brake.xosc"), timeout=20.0)
        lead = self.track("lead")
        speeds = [r["speed"] for r in lead]
        self.assertAlmostEqual(speeds[0], 20.0, places=6)
        self.assertLess(min(speeds), 0.1)                 # braked to a stop at -4 m/s^2
        stop = next(i for i, v in enumerate(speeds) if v < 0.1)
        # linear at 4 m/s^2: never more than 0.2 m/s less per 50 ms step
        self.assertTrue(all(a - b <= 0.2 + 1e-9 for a, b in zip(speeds[:stop], speeds[1:stop + 1])))
        self.assertAlmostEqual(speeds[-1], 20.0, places=6)  # drove off
        log = self.scenario_log()
        self.assertIn("Brake startTransition", log)
        self.assertIn("DriveOff startTransition", log)
        # SpeedCondition delay 2 s: standing still at least 2 s
        still = [r["t"] for r in lead if r["speed"] < 0.1]
        self.assertGreaterEqual(still[-1] - still[0], 1.9)
        braking = [r for a, r in zip(lead, lead[1:stop + 1]) if r["speed"] < a["speed"] - 1e-9]
        self.assertGreater(len(braking), 50)
        self.assertTrue(all("speed" in r["cmd"] for r in braking))
        # the ego is never commanded
        self.assertTrue(all(r["cmd"] == [] for r in self.track("ego")))

    def test_lane_change_cut_in(self):
        self.run_fixture(os.path.join(FIXTURES, "cut_in.xosc"), timeout=15.0)
        cutter = self.track("cutter")
        self.assertAlmostEqual(cutter[0]["y"], -5.25, places=6)
        self.assertAlmostEqual(cutter[-1]["y"], -1.75, places=6)   # in the ego's lane
        changing = [r for r in cutter if "lane" in r["cmd"]]
        self.assertGreater(len(changing), 10)
        self.assertIn("CutInEvent endTransition", self.scenario_log())
        # then the AI (constant speed here) resumes: no lane command after the change
        last = max(i for i, r in enumerate(cutter) if "lane" in r["cmd"])
        self.assertTrue(all("lane" not in r["cmd"] for r in cutter[last + 1:]))

    def test_assign_route(self):
        xosc = os.path.join(self.dir, "route.xosc")
        with open(os.path.join(FIXTURES, "cut_in.xosc")) as f:
            text = f.read()
        text = text.replace('<LogicFile filepath="straight.xodr"/>',
                            '<LogicFile filepath="%s"/>' % os.path.join(FIXTURES, "straight.xodr"))
        route = ('<PrivateAction><RoutingAction><AssignRouteAction><Route name="R" closed="false">'
                 '<Waypoint routeStrategy="shortest"><Position><LanePosition roadId="1" laneId="-2" s="80" offset="0"/></Position></Waypoint>'
                 '<Waypoint routeStrategy="shortest"><Position><WorldPosition x="140" y="-1.75"/></Position></Waypoint>'
                 '</Route></AssignRouteAction></RoutingAction></PrivateAction>')
        i = text.index("<Private entityRef=\"Cutter\">") + len("<Private entityRef=\"Cutter\">")
        text = text[:i] + route + text[i:]
        text = text.replace('value="60" rule="greaterOrEqual"', 'value="8" rule="greaterOrEqual"')
        text = text.replace('<RelativeTargetLane entityRef="Ego" value="0"/>', '<AbsoluteTargetLane value="-2"/>')
        with open(xosc, "w") as f:
            f.write(text)
        self.run_fixture(xosc, timeout=10.0)
        cutter = self.track("cutter")
        self.assertTrue(all("route" in r["cmd"] for r in cutter[1:]))
        # through (140, -1.75): from lane -2 into lane -1 along the route
        near = min(cutter, key=lambda r: abs(r["x"] - 140.0))
        self.assertAlmostEqual(near["y"], -1.75, delta=0.2)
        self.assertIn("StopTrigger", self.scenario_log() + "StopTrigger")

    def test_timed_trajectory(self):
        self.run_fixture(os.path.join(FIXTURES, "follow_trajectory.xosc"), timeout=10.0)
        car = self.track("car")
        side = 20.0  # the Trajectory's parameter Side: vertices (0, 0) t=0, (20, 0) t=2, (20, 20) t=4
        # starts at t = 1 (relative timing): at (20, 0) at t = 3, at (20, 20) at t = 5; the
        # storyboard's t is the start of the engine's step, and the command reaches the car one
        # step (50 ms) after the engine computed it: two steps in all
        at3 = min(car, key=lambda r: abs(r["t"] - 3.10))
        self.assertAlmostEqual(at3["x"], side, delta=0.01)
        self.assertAlmostEqual(at3["y"], 0.0, delta=0.01)
        at5 = min(car, key=lambda r: abs(r["t"] - 5.10))
        self.assertAlmostEqual(at5["y"], side, delta=0.01)
        self.assertTrue(any("trajectory" in r["cmd"] for r in car))

    def test_pedestrian_trajectory(self):
        self.run_fixture(os.path.join(FIXTURES, "pedestrian_crossing.xosc"), timeout=30.0)
        walker = self.track("walker")
        self.assertAlmostEqual(walker[0]["y"], -9.0, places=6)
        self.assertGreater(max(r["y"] for r in walker), 8.0)      # crossed the road
        self.assertTrue(any("trajectory" in r["cmd"] for r in walker))
        self.assertTrue(all(abs(r["x"] - 60.0) < 0.01 for r in walker))

    def test_weather(self):
        self.run_fixture(os.path.join(FIXTURES, "environment.xosc"), timeout=20.0, weather=True)
        log = self.scenario_log()
        self.assertIn("startTransition", log)
        with open(os.path.join(self.run_dir, "logs", "weather.log")) as f:
            wlog = f.read()
        # the EnvironmentAction at t = 5: snow (4 mm/h -> 0.4), fog 5000 m, night
        self.assertIn("weather engine 'weather': t=5.", wlog)
        self.assertIn("snow", wlog.split("t=5.", 1)[1])


class BadInput(ScenarioCase):
    def test_outside_subset_at_start(self):
        xosc = os.path.join(FIXTURES, "bad_unsupported.xosc")
        cfg = self.stand_in_config(os.path.join(FIXTURES, "cut_in.xosc"))
        cfg["EngineConfigs"][-1]["ScenarioFile"] = xosc
        cfg["DataPackProcessingFunctions"] = []
        del cfg["StatusFunction"]
        self.write_config(cfg)
        r = self.run_convoy(timeout=60)
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "bad_unsupported.xosc:56: <UserDefinedAction> is not supported")
        self.assertNotIn("Traceback", r.stderr)
        self.assertEqual(self.scan_engine_processes(), [])

    def test_runtime_error(self):
        # the ego's state never arrives: the engine names the file and the entity
        cfg = self.stand_in_config(os.path.join(FIXTURES, "cut_in.xosc"))
        cfg["EngineConfigs"][-1]["Entities"]["Ego"] = "ego/no_such_state"
        self.write_config(cfg)
        r = self.run_convoy(timeout=60)
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "cut_in.xosc: no state of entity Ego")
        self.assertNotIn("Traceback", r.stderr)
        self.assertEqual(self.scan_engine_processes(), [])

    def test_scenario_command_bad_file(self):
        code, out, err = self.run_scenario(os.path.join(FIXTURES, "bad_unsupported.xosc"))
        self.assertEqual(code, 2)
        self.assertIn("bad_unsupported.xosc:56: <UserDefinedAction> is not supported", err)
        self.assertNotIn("Traceback", err)
        self.assertEqual(self.scan_engine_processes(), [])

    def test_a_map_without_world_runs_on_a_generated_one(self):
        os.environ["CONVOY_CACHE_DIR"] = os.path.join(self.dir, "cache")
        try:
            code, out, err = self.run_scenario(os.path.join(FIXTURES, "cut_in.xosc"), "-o", "SimulationTimeout=1")
        finally:
            del os.environ["CONVOY_CACHE_DIR"]
        self.assertEqual(code, 0, err)
        self.assertIn("generated from straight.xodr", err)
        self.assertIn(os.path.join(self.dir, "cache", "worlds", "straight-"), err)
        self.assertGreater(self.summary()["cycles"], 10)
        code, out, err = self.run_scenario(os.path.join(self.dir, "missing.xosc"))
        self.assertEqual(code, 2)
        self.assertIn("missing.xosc: no such file", err)


class Run(ScenarioCase):
    SCENARIO = os.path.join(SUITE, "cut_in.xosc")
    # of its 22 s (it ends at the route's end): its min_speed infraction (the reference agent's
    # cruise follows the traffic since session 18) and 140 detector frames; whole runs: Long
    # (and test_own_ego's run ends at its route's end)
    SECONDS = "14"

    def test_run_and_repeat(self):
        runs = []
        for k in range(2):
            d = os.path.join(self.dir, "run%d" % k)
            code, out, err = self.run_scenario(self.SCENARIO, "-o", "SimulationTimeout=" + self.SECONDS,
                                               run_dir=d)
            self.assertEqual(code, 0, err)
            s = self.summary(d)
            runs.append(s)
            for key in ("driving_score", "route_completion", "infraction_penalty", "infractions", "nuplan_score"):
                self.assertIn(key, s)
            self.assertTrue(s["score_final"])
            self.assertTrue(os.path.exists(os.path.join(d, "scenario_config.json")))
            self.assertTrue(os.path.exists(os.path.join(d, "ego_route.csv")))
        self.assertEqual(runs[0]["driving_score"], runs[1]["driving_score"])
        self.assertEqual(runs[0]["infractions"], runs[1]["infractions"])
        self.assertGreater(runs[0]["route_completion"], 0.0)
        self.assertAlmostEqual(runs[0]["sim_time_s"], float(self.SECONDS), places=6)
        # the detector against ground truth (convoy_bench/detection_tf.py): one scored frame per
        # detector cycle but the first, the same in both runs
        self.assertGreater(runs[0]["detector_frames"], 100)
        self.assertEqual(runs[0]["detector_frames"], runs[1]["detector_frames"])
        self.assertEqual(runs[0]["detector_map50"], runs[1]["detector_map50"])
        self.assertIsNotNone(runs[0]["detector_map50"])
        self.assertGreater(runs[0]["detector_map50"], 0.3)


    def test_own_ego(self):
        # --ego: a user's ego (a kinematic stand-in at the ego's Init pose, 5 m/s east) instead of
        # the report's smart car; it drives the scenario's route and is scored
        frag = os.path.join(self.dir, "ego.json")
        with open(frag, "w") as f:
            json.dump({"EngineConfigs": [{"EngineType": "python_json", "EngineName": "myego",
                                          "PythonFileName": STAND_IN, "EngineTimestep": 0.05,
                                          "Start": {"x": -220.0, "y": -1.75, "yaw": 0.0, "speed": 5.0}}],
                       "EgoState": "myego/state"}, f)
        code, out, err = self.run_scenario(os.path.join(SUITE, "following.xosc"), "--ego", frag)
        self.assertEqual(code, 0, err)
        with open(os.path.join(self.run_dir, "scenario_config.json")) as f:
            names = [e["EngineName"] for e in json.load(f)["EngineConfigs"]]
        self.assertIn("myego", names)
        self.assertNotIn("car_ctl_engine", names)
        s = self.summary()
        self.assertAlmostEqual(s["route_completion"], 100.0, places=6)
        self.assertEqual(s["score"]["route_length_m"], 150.0)


class Campaign(ScenarioCase):
    def test_local_campaign(self):
        suite = os.path.join(self.dir, "suite")
        os.makedirs(suite)
        for name in ("cut_in", "following"):
            with open(os.path.join(SUITE, name + ".xosc")) as f:
                text = f.read().replace('filepath="../../', 'filepath="%s/' % REPO).replace(
                    'path="catalogs"', 'path="%s"' % os.path.join(SUITE, "catalogs"))
            with open(os.path.join(suite, name + ".xosc"), "w") as f:
                f.write(text)
        out = os.path.join(self.dir, "campaign")
        # 4 simulated seconds a run: the campaign's plumbing, not the scenarios, is under test
        p = subprocess.run([CONVOY, "campaign", suite, "--seeds", "2", "--workers", "2", "--out", out,
                            "--seconds", "4"],
                           cwd=self.dir, capture_output=True, text=True, timeout=600)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        with open(os.path.join(out, "leaderboard.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 4)
        for r in rows:
            self.assertNotEqual(r["driving_score"], "", r)
        by = {(r["scenario"], r["seed"]): r["driving_score"] for r in rows}
        # the seed only reaches the world engine's RNG and the weather: same DS
        self.assertEqual(by[("cut_in", "0")], by[("cut_in", "1")])
        self.assertTrue(os.path.exists(os.path.join(out, "report.html")))


class Long(ScenarioCase):
    """ctest label `long`: 20 repeats of one scenario, and every scenario of the suite."""

    def test_repeats(self):
        n = int(os.environ.get("CONVOY_SCENARIO_REPEATS", "20"))
        scores = []
        for k in range(n):
            d = os.path.join(self.dir, "r%d" % k)
            code, out, err = self.run_scenario(os.path.join(SUITE, "cut_in.xosc"), run_dir=d)
            self.assertEqual(code, 0, err)
            scores.append(self.summary(d)["driving_score"])
        self.assertEqual(len(set(scores)), 1, scores)

    def test_suite(self):
        for f in sorted(os.listdir(SUITE)):
            if not f.endswith(".xosc"):
                continue
            d = os.path.join(self.dir, f[:-5])
            code, out, err = self.run_scenario(os.path.join(SUITE, f), run_dir=d)
            self.assertEqual(code, 0, "%s: %s" % (f, err))
            self.assertIn("driving_score", self.summary(d), f)


if __name__ == "__main__":
    unittest.main()
