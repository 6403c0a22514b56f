"""The scenario engine's pieces that need no simulation (docs/scenarios.md, "Running a
scenario"; docs/scoring.md, "Live scoring"): the commands built from storyboard steps
(engine_script.Commander), the config generator (make_config) on the suite and on bad input,
the live score against score_drive, the campaign's .xosc entry type, the suite's files.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_scenario_run
(convoy-odr from $CONVOY_BIN_DIR or build/bin; tests needing it are skipped without it)."""

import contextlib
import copy
import json
import math
import os
import sys
import tempfile
import types
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))

# engine_script imports nrp_core's EngineScript; a stand-in base class is enough here
if "nrp_core.engines.python_json" not in sys.modules:
    try:
        import nrp_core.engines.python_json  # noqa: F401
    except Exception:
        mod = types.ModuleType("nrp_core.engines.python_json")
        mod.EngineScript = object
        sys.modules["nrp_core.engines.python_json"] = mod

from convoy_scenario import ScenarioError, Storyboard, load, loads  # noqa: E402
from convoy_scenario import engine_script, make_config  # noqa: E402
from convoy_scenario.odr import OdrQuery, find_odr  # noqa: E402
from convoy_bench import live, score  # noqa: E402

FIXTURES = os.path.join(HERE, "scenarios")
SUITE = os.path.join(REPO, "benchmarks", "suite")
CITY = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")


def have_odr():
    try:
        find_odr()
        return True
    except ScenarioError:
        return False


@contextlib.contextmanager
def cache_dir(path):
    """$CONVOY_CACHE_DIR set to `path` within the block."""
    old = os.environ.get("CONVOY_CACHE_DIR")
    os.environ["CONVOY_CACHE_DIR"] = path
    try:
        yield
    finally:
        if old is None:
            del os.environ["CONVOY_CACHE_DIR"]
        else:
            os.environ["CONVOY_CACHE_DIR"] = old


def kinematic_world(t, states):
    return {k: dict(v) for k, v in states.items()}


class CommanderTest(unittest.TestCase):
    def test_cut_in_commands(self):
        sc = load(os.path.join(FIXTURES, "cut_in.xosc"))
        board = Storyboard(sc)
        ents = engine_script.parse_entities({"Ego": "ego/state", "Cutter": "car_1"}, sc)
        cmdr = engine_script.Commander(ents, "Ego", None)
        ego = {"x": 50.0, "y": -1.75, "yaw": 0.0, "speed": 20.0, "road": "1", "lane": -1, "s": 50.0, "t": -1.75}
        cut = {"x": 30.0, "y": -5.25, "yaw": 0.0, "speed": 25.0, "road": "1", "lane": -2, "s": 30.0, "t": -5.25}
        seen = []
        for k in range(1, 200):
            t = 0.05 * k
            ego["x"] += 20 * 0.05
            cut["x"] += 25 * 0.05
            r = board.step(t, {"Ego": dict(ego), "Cutter": dict(cut)})
            cmds, weather = cmdr.commands(r, int(round(t * 1e9)))
            self.assertIsNone(weather)
            self.assertEqual(sorted(cmds), ["car_1"])   # the ego is never commanded
            self.assertEqual(cmds["car_1"]["time_ns"], int(round(t * 1e9)))
            seen.append(cmds["car_1"])
        lane = [c["lane"] for c in seen if "lane" in c]
        self.assertTrue(lane)
        self.assertEqual(lane[0]["lane"], -1)
        self.assertEqual(lane[0]["from_lane"], -2)
        self.assertIsInstance(lane[0]["lane"], int)
        self.assertAlmostEqual(lane[-1]["progress"], 1.0)
        speeds = [c["speed"] for c in seen if "speed" in c]
        self.assertEqual(set(speeds[0]), {"speed", "target_speed", "acceleration"})
        # the AI's turn: steps with no action leave every domain key out
        self.assertTrue(any(set(c) == {"time_ns"} for c in seen))

    def test_entities_mapping(self):
        sc = load(os.path.join(FIXTURES, "cut_in.xosc"))
        self.assertEqual(engine_script.parse_entities({}, sc),
                         {"Ego": ("Ego", "state", "command"), "Cutter": ("Cutter", "state", "command")})
        with self.assertRaises(ScenarioError) as e:
            engine_script.parse_entities({"Cuter": "x"}, sc)
        self.assertIn("no entity 'Cuter'", str(e.exception))

    def test_route_end(self):
        pts = [[0, 0], [10, 0], [20, 0]]
        self.assertFalse(engine_script.past_route_end(pts, 18.0, 0.0))
        self.assertTrue(engine_script.past_route_end(pts, 19.5, 0.0))
        self.assertTrue(engine_script.past_route_end(pts, 25.0, 2.0))
        self.assertFalse(engine_script.past_route_end(pts, 25.0, 8.0))


@unittest.skipUnless(have_odr(), "convoy-odr is not built")
class MakeConfigTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convoy-makeconfig-")

    def test_suite_cut_in(self):
        out = os.path.join(self.tmp, "c.json")
        cfg = make_config.write(os.path.join(SUITE, "cut_in.xosc"), out)
        types_ = [e["EngineType"] for e in cfg["EngineConfigs"]]
        self.assertEqual(types_[:2], ["gazebo_grpc", "weather"])   # the campaign's indices
        self.assertIn("scenario", types_)
        self.assertIn("traffic_lights", types_)
        agent = next(e for e in cfg["EngineConfigs"] if e["EngineName"] == "Cutter")
        self.assertEqual(agent["EngineType"], "vehicle_agent")
        self.assertEqual(agent["StartPose"], {"x": -232.0, "y": -5.25, "yaw": 0.0})
        self.assertEqual(agent["InitialSpeed"], 12.0)
        self.assertEqual(agent["Model"], "sedan_blue")
        self.assertEqual((agent["Length"], agent["Width"]), (4.65, 1.84))
        self.assertAlmostEqual(agent["Wheelbase"], 2.7)
        world = cfg["EngineConfigs"][0]
        self.assertEqual(world["GazeboSDFModels"][0]["InitPose"], [-220.0, -1.75, 0.0, 0.0, 0.0, 0.0])
        scen = next(e for e in cfg["EngineConfigs"] if e["EngineType"] == "scenario")
        self.assertEqual(scen["Entities"], {"Cutter": "Cutter", "Ego": "gazebo/smart_car::road_user"})
        route = scen["EgoRoute"]
        self.assertAlmostEqual(make_config.polyline_length(route), 150.0, places=6)  # RouteLength
        self.assertEqual(route[0], [-220.0, -1.75])
        self.assertEqual(cfg["SimulationTimeout"], 30.5)
        with open(os.path.join(self.tmp, "ego_route.csv")) as f:
            rows = f.read().splitlines()
        self.assertEqual(rows[0], "x,y,heading")
        self.assertGreater(len(rows), 80)   # 150 m + 30 m at 2 m
        for e in cfg["EngineConfigs"]:
            for k in ("GazeboWorldFile", "PythonFileName", "ScenarioFile", "Map"):
                if k in e:
                    self.assertTrue(os.path.isabs(e[k]), (k, e[k]))

    def test_weather_and_routes(self):
        cfg, drive, length = make_config.build(os.path.join(SUITE, "following_rain.xosc"))
        w = cfg["EngineConfigs"][1]
        self.assertEqual((w["Precipitation"], w["PrecipitationType"]), (0.7, "rain"))
        cfg, drive, length = make_config.build(os.path.join(SUITE, "left_turn.xosc"))
        end = drive[-1]
        self.assertGreater(end[1], 14.0)     # turned left, north into road 4
        merger = make_config.build(os.path.join(SUITE, "merge.xosc"))[0]
        m = next(e for e in merger["EngineConfigs"] if e["EngineName"] == "Merger")
        self.assertEqual(m["Route"], {"to": "2:-1"})

    def test_every_suite_scenario_generates(self):
        names = sorted(f for f in os.listdir(SUITE) if f.endswith(".xosc"))
        self.assertGreaterEqual(len(names), 20)
        for f in names:
            cfg, drive, length = make_config.build(os.path.join(SUITE, f))
            self.assertGreater(length, 50.0, f)

    def test_a_map_without_world_gets_one_generated_and_cached(self):
        cache = os.path.join(self.tmp, "cache")
        with cache_dir(cache):
            cfg = make_config.build(os.path.join(FIXTURES, "cut_in.xosc"))[0]
            world = cfg["EngineConfigs"][0]["GazeboWorldFile"]
            self.assertTrue(world.startswith(os.path.join(cache, "worlds", "straight-")), world)
            self.assertTrue(os.path.exists(world))
            again = make_config.build(os.path.join(FIXTURES, "cut_in.xosc"))[0]
            self.assertEqual(again["EngineConfigs"][0]["GazeboWorldFile"], world)   # the cached one
            # the map's bytes name the entry: another map, another world
            self.assertEqual(len(os.listdir(os.path.join(cache, "worlds"))), 1)

    def test_a_map_that_cannot_be_parsed_leaves_no_world(self):
        cache = os.path.join(self.tmp, "cache_bad")
        bad = os.path.join(self.tmp, "bad_map.xosc")
        with open(os.path.join(FIXTURES, "cut_in.xosc")) as f:
            text = f.read().replace("straight.xodr", os.path.join(REPO, "tests", "opendrive", "data",
                                                                  "malformed.xodr"))
        with open(bad, "w") as f:
            f.write(text)
        with cache_dir(cache):
            with self.assertRaises(ScenarioError) as e:
                make_config.build(bad)
        self.assertIn("malformed.xodr:", str(e.exception))
        worlds = os.path.join(cache, "worlds")
        self.assertEqual(os.listdir(worlds) if os.path.exists(worlds) else [], [])

    def test_cli_errors(self):
        err = os.path.join(self.tmp, "err.txt")
        with open(err, "w") as f:
            old, sys.stderr = sys.stderr, f
            try:
                rc = make_config.main([os.path.join(FIXTURES, "bad_unsupported.xosc"), "--out",
                                       os.path.join(self.tmp, "x.json")])
            finally:
                sys.stderr = old
        self.assertEqual(rc, 2)
        with open(err) as f:
            self.assertIn("bad_unsupported.xosc:56: <UserDefinedAction> is not supported", f.read())


class LiveScoreTest(unittest.TestCase):
    def drive(self):
        route = [[-220.0 + 2 * k, -1.75] for k in range(76)]
        ego, others, cols = [], [], []
        for k in range(301):
            t = 0.05 * k
            x = -220.0 + 8.0 * t
            ego.append({"x": x, "y": -1.75, "yaw": 0.0, "speed": 8.0, "length": 2.5, "length_offset": 0.9})
            others.append({"car_1": {"class": "car", "x": x + 20, "y": -5.25, "yaw": 0.0, "speed": 10.0,
                                     "length": 4.5, "length_offset": 1.4}})
            cols.append([] if t < 5 else [{"t": 5.0, "a": "car_1", "b": "smart_car", "class_a": "car",
                                           "class_b": "car", "relative_speed_mps": 2.0}])
        return route, ego, others, cols

    def run_live(self):
        route, ego, others, cols = self.drive()
        ls = live.LiveScore(route, CITY)
        for k in range(len(ego)):
            ls.add(0.05 * k, ego[k], others[k], cols[k], {})
        return ls

    def test_matches_score_drive(self):
        ls = self.run_live()
        r = ls.result(final=True, timed_out=True)
        again = score.score_drive(copy.deepcopy(ls.samples), {"points": ls.route["points"]},
                                  copy.deepcopy(ls.events) + ([] if r["route_finished"] else
                                                              [{"t": ls.samples[-1]["t"], "kind": "scenario_timeout",
                                                                "other": None}]))
        self.assertEqual(r["driving_score"], again["driving_score"])
        kinds = [i["kind"] for i in r["infractions"]]
        self.assertIn("collision_vehicle", kinds)
        self.assertIn("scenario_timeout", kinds)          # 120 of 150 m: not finished
        rc = r["route_completion"]
        self.assertAlmostEqual(rc, 100.0 * 120.0 / 150.0, delta=0.5)
        p = 1.0
        for i in sorted(r["infractions"], key=lambda i: (i["t"], i["kind"])):
            p *= i["penalty"] if i.get("counted", True) else 1.0
        self.assertAlmostEqual(r["driving_score"], rc * p, places=9)
        f = live.summary_fields(r, True)
        self.assertEqual(set(f["infractions"][0]), {"time", "kind", "other", "penalty", "counted"} |
                         set(f["infractions"][0]) & {"percentage", "distance_m"})

    def test_bit_identical(self):
        a = self.run_live().result(final=True, timed_out=True)
        b = self.run_live().result(final=True, timed_out=True)
        self.assertEqual(json.dumps(a, sort_keys=True, default=str), json.dumps(b, sort_keys=True, default=str))


class CampaignEntryTest(unittest.TestCase):
    def test_argv(self):
        from convoy_scenario.campaign_entry import xosc_command
        e = {"config": "/s/cut_in.xosc", "overrides": ["EngineConfigs/5/v0=3"]}
        argv = xosc_command(e, 1, "clear", {"convoy": "convoy", "run_dir": "/o/r", "seconds": None})
        self.assertEqual(argv, ["convoy", "run", "-q", "--scenario", "/s/cut_in.xosc", "--run-dir", "/o/r",
                                "-o", "EngineConfigs/0/GazeboRNGSeed=1", "-o", "EngineConfigs/1/Seed=1",
                                "-o", "EngineConfigs/5/v0=3"])
        argv = xosc_command(e, 0, "fog", {"convoy": "convoy", "run_dir": "/o/r", "seconds": 5})
        self.assertIn("SimulationTimeout=5.0", argv)
        self.assertIn("EngineConfigs/1/Visibility=100.0", argv)
        self.assertIn("EngineConfigs/1/Schedule=[]", argv)


if __name__ == "__main__":
    unittest.main()
