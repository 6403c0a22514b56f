"""The scenario engine's pieces that need no simulation (docs/scenarios.md, "Running a
scenario"; docs/scoring.md, "Live scoring"): the commands built from storyboard steps
(engine_script.Commander), the config generator (make_config) on the suite and on bad input,
the live score against score_drive, the campaign's .xosc entry type, the suite's files.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_scenario_run
(convoy-odr from $CONVOY_BIN_DIR or build/bin; tests needing it are skipped without it)."""

import array
import collections
import contextlib
import copy
import json
import math
import os
import sys
import shutil
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
        self.addCleanup(shutil.rmtree, self.tmp, True)

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

    def run_live(self, cls=None):
        route, ego, others, cols = self.drive()
        ls = (cls or live.LiveScore)(route, CITY)
        for k in range(len(ego)):
            ls.add(0.05 * k, ego[k], others[k], cols[k], {})
        return ls

    def test_matches_score_drive(self):
        ls = self.run_live()
        r = ls.result(final=True, timed_out=True)
        samples = self.run_live(ReferenceLiveScore).samples
        again = score.score_drive(copy.deepcopy(samples), {"points": ls.route["points"]},
                                  copy.deepcopy(ls.events) + ([] if r["route_finished"] else
                                                              [{"t": samples[-1]["t"], "kind": "scenario_timeout",
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


# --- issue 30: LiveScore in bounded memory, the same scores -----------------------------------

from convoy_bench import geometry, nuplan, road_map  # noqa: E402
from convoy_bench.runs import EGO_WIDTH, VEHICLE_CLASSES, WRONG_WAY_ANGLE  # noqa: E402


class ReferenceLiveScore:
    """LiveScore before issue 30 (every sample kept, the whole drive rescored): the
    reference the bounded LiveScore must match bit for bit."""

    def __init__(self, route_points, map_path, stop_lines=(), ego="smart_car", ego_width=EGO_WIDTH):
        self.route = {"points": [[float(p[0]), float(p[1])] for p in route_points]}
        self.map = road_map.load(map_path)
        self.stop_lines = list(stop_lines)
        self.ego = ego
        self.ego_width = ego_width
        self.samples = []
        self.events = []
        self.collided = {}         # other -> time of its first collision with the ego
        self.seen_collisions = 0
        self.prev_ahead = {}
        self.crossed_on_red = {}
        self.last_t = None

    def _flags(self, s):
        corners = geometry.box_corners([s["x"]], [s["y"]], [s["yaw"]], [s["length"]], self.ego_width,
                                       [s["length_offset"]])
        xs = [s["x"]] + [float(corners[0, k, 0]) for k in range(4)]
        ys = [s["y"]] + [float(corners[0, k, 1]) for k in range(4)]
        where, *cw = road_map.locate(self.map, xs, ys, [s["yaw"]] * 5)
        lanes = {(c["road"], c["lane"]) for c in cw}
        in_junction = where["junction"] or any(c["junction"] for c in cw)
        wrong = (where["lane_type"] == "driving" and not where["junction"] and where["heading"] is not None
                 and math.cos(where["heading"] - s["yaw"]) < math.cos(WRONG_WAY_ANGLE))
        s.update({"road": where["road"], "lane": where["lane"], "on_road": where["on_road"],
                  "wrong_way": wrong, "in_junction": in_junction,
                  "multiple_lanes": len(lanes) > 1 and not in_junction,
                  "speed_limit": where["speed_limit"]})

    def _red_lights(self, t, s, signals):
        fx = s["x"] + (s["length_offset"] + 0.5 * s["length"]) * math.cos(s["yaw"])
        fy = s["y"] + (s["length_offset"] + 0.5 * s["length"]) * math.sin(s["yaw"])
        for sl in self.stop_lines:
            a = sl.ahead(fx, fy, s["yaw"], at_entry=True)
            prev = self.prev_ahead.get(sl.id)
            if a is None:
                self.prev_ahead.pop(sl.id, None)
                continue
            self.prev_ahead[sl.id] = a
            b = sl.ahead(fx, fy, s["yaw"])
            pb = self.prev_ahead.get((sl.id, "line"))
            self.prev_ahead[(sl.id, "line")] = b
            if pb is not None and b is not None and pb > 0 >= b:
                self.crossed_on_red[sl.id] = signals.get(sl.id) == "red"
            if prev is not None and prev > 0 >= a and signals.get(sl.id) == "red" and \
                    self.crossed_on_red.get(sl.id, True):
                self.events.append({"t": t, "kind": "red_light", "other": sl.id})

    def add(self, t, ego, others, collisions=(), signals=None):
        """One step: ego {"x", "y", "yaw", "speed", "length", "length_offset"}; others {id:
        {"class", "x", "y", "yaw", "speed", "length", "length_offset"}}; collisions the world's
        cumulative list; signals {id: state}."""
        t = float(t)
        if self.last_t is not None and t <= self.last_t:
            return
        self.last_t = t
        s = {"t": t, "x": float(ego["x"]), "y": float(ego["y"]), "yaw": float(ego["yaw"]),
             "speed": float(ego["speed"]), "length": float(ego.get("length") or 2.5),
             "width": self.ego_width, "length_offset": float(ego.get("length_offset") or 0.0)}
        self._flags(s)
        for c in list(collisions)[self.seen_collisions:]:
            a, b = c.get("a"), c.get("b")
            if self.ego not in (a, b) or a == b:
                continue
            other, cls = (b, c.get("class_b")) if a == self.ego else (a, c.get("class_a"))
            kind = ("collision_pedestrian" if cls == "pedestrian" else
                    "collision_vehicle" if cls in VEHICLE_CLASSES else "collision_static")
            e = {"t": float(c["t"]), "kind": kind, "other": other, "other_class": cls}
            if other in others:
                e["other_state"] = dict(others[other])
            self.events.append(e)
            self.collided.setdefault(other, float(c["t"]))
        self.seen_collisions = len(list(collisions))
        if signals:
            self._red_lights(t, s, signals)
        active = [o for oid, o in sorted(others.items())
                  if not (oid in self.collided and self.collided[oid] < t)]
        wide = s["multiple_lanes"] or s["in_junction"] or not s["on_road"]
        s["ttc"] = nuplan.ttc_at(s, active, wide=wide)
        vehicles = [o["speed"] for _, o in sorted(others.items()) if o["class"] in VEHICLE_CLASSES]
        s["traffic_speed"] = math.fsum(vehicles) / len(vehicles) if vehicles else None
        self.samples.append(s)

    def result(self, final=False, timed_out=False):
        """score.score_drive's result for the drive so far (None with fewer than 2 samples).
        final and timed_out: the run ended before the ego finished its route -> one
        scenario_timeout infraction (at the last sample's time)."""
        if len(self.samples) < 2 or len(self.route["points"]) < 2:
            return None
        events = list(self.events)
        r = score.score_drive(self.samples, self.route, events)
        if final and timed_out and not r["route_finished"]:
            events.append({"t": self.samples[-1]["t"], "kind": "scenario_timeout", "other": None})
            r = score.score_drive(self.samples, self.route, events)
        return r


class _StopLine:
    """A stop line across the road at x = line_x, the junction's entry 2 m further (the
    interface of convoy_scenario.stop_lines for an ego driving +x)."""
    id = "sl_1"

    def __init__(self, line_x):
        self.line_x = line_x

    def ahead(self, fx, fy, yaw, at_entry=False):
        d = self.line_x + (2.0 if at_entry else 0.0) - fx
        return d if -5.0 < d < 40.0 else None


class BoundedLiveScoreTest(unittest.TestCase):
    """LiveScore keeps bounded state and gives ReferenceLiveScore's results, bit for bit."""
    ROUTE = [[-220.0 + 2 * k, -1.75] for k in range(76)]          # 150 m along +x

    # (until s, ego speed m/s, y): stops, wrong way (y 1.75), off road (y -12), a crawl above
    # the blocked speed, overspeed (16 > 13.9 m/s) through a red light, the route's end, then
    # stopped until blocked (180 s)
    PHASES = ((3.0, 8.0, -1.75), (63.0, 0.0, -1.75), (66.0, 8.0, 1.75), (69.0, 8.0, -12.0),
              (300.0, 0.12, -1.75), (302.0, 16.0, -1.75), (400.0, 0.0, -1.75), (403.0, 6.0, -1.75),
              (1200.0, 0.0, -1.75))
    COLLISIONS = (  # (reported from t, collision)
        (10.0, {"t": 10.0, "a": "ped_1", "b": "smart_car", "class_a": "pedestrian", "class_b": "car"}),
        (20.0, {"t": 20.0, "a": "smart_car", "b": "pole_7", "class_a": "car", "class_b": "static"}),
        (64.5, {"t": 64.0, "a": "car_2", "b": "smart_car", "class_a": "car", "class_b": "car"}),
        (300.4, {"t": 300.5, "a": "smart_car", "b": "car_1", "class_a": "car", "class_b": "car"}),
        (301.0, {"t": 301.0, "a": "smart_car", "b": "car_1", "class_a": "car", "class_b": "car"}),
        (301.0, {"t": 301.0, "a": "car_1", "b": "car_2", "class_a": "car", "class_b": "car"}),
    )

    def stream(self, seconds):
        """Steps (t, ego, others, collisions, signals) at 20 Hz, as the transceiver gives them
        (time_ns * 1e-9; a repeated time now and then)."""
        x, y, steps = -220.0, -1.75, []
        for k in range(int(seconds * 20) + 1):
            t = (k * 50000000) * 1e-9
            v, yy = next((v, yy) for end, v, yy in self.PHASES if t < end or end == self.PHASES[-1][0])
            if k:
                x += v * 0.05
            y = yy
            yaw = 0.02 * math.sin(0.7 * t)
            ego = {"x": x, "y": y, "yaw": yaw, "speed": v, "length": 2.5, "length_offset": 0.9}
            others = {"car_1": {"class": "car", "x": x + 25.0 + 3.0 * math.sin(0.05 * t), "y": -5.25,
                                "yaw": 0.0, "speed": 9.0 + math.sin(0.1 * t), "length": 4.5,
                                "length_offset": 1.4},
                      "car_2": {"class": "car", "x": x + 7.0, "y": y, "yaw": 0.0,
                                "speed": 0.5 if 300.0 <= t < 302.0 else v, "length": 4.5, "length_offset": 1.4},
                      "ped_1": {"class": "pedestrian", "x": x + 4.0, "y": y + 1.5, "yaw": 1.5, "speed": 1.2}}
            cols = [c for since, c in self.COLLISIONS if t >= since]
            signals = {"sl_1": "red" if 295.0 <= t < 310.0 else "green"}
            if k % 13 == 7:
                continue                                            # a dropped step: uneven time steps
            steps.append((t, ego, others, cols, signals))
            if k % 997 == 500:
                steps.append((t, ego, others, cols, signals))      # not after the last: ignored
        return steps

    def assert_same(self, a, b, where):
        ra, rb = a, b
        self.assertEqual(repr(ra), repr(rb), where)                 # every float's bits, key order

    def test_long_drive_matches_reference(self):
        steps = self.stream(1200.0)                                 # 20 simulated minutes
        ref = ReferenceLiveScore(self.ROUTE, CITY, [_StopLine(-110.0)])
        new = live.LiveScore(self.ROUTE, CITY, [_StopLine(-110.0)])
        checked = 0
        for k, (t, ego, others, cols, signals) in enumerate(steps):
            ref.add(t, ego, others, cols, signals)
            new.add(t, ego, others, cols, signals)
            if k in (0, 1, 2, 3, 4, 5, 6, 40) or k % 4000 == 0 or 5990 <= k <= 6010 and k % 10 == 0:
                self.assert_same(ref.result(), new.result(), "step %d" % k)
                self.assert_same(ref.result(final=True, timed_out=True), new.result(final=True, timed_out=True),
                                 "step %d, final" % k)
                checked += 1
            self.assert_bounded(new)
        self.assert_same(ref.result(final=True, timed_out=True), new.result(final=True, timed_out=True), "end")
        self.assertEqual(len(ref.events), len(new.events))
        r = new.result(final=True, timed_out=True)
        kinds = {i["kind"] for i in r["infractions"]}
        # the stream covers what the aggregates do
        self.assertTrue({"collision_pedestrian", "collision_static", "collision_vehicle", "red_light",
                         "wrong_way", "off_road", "min_speed", "agent_blocked"} <= kinds, kinds)
        self.assertTrue(r["route_finished"])
        self.assertEqual(r["route_ended_at"], 583.0)
        self.assertFalse(all(i["counted"] for i in r["infractions"]))
        self.assertEqual(new.unresolved_states, 0)
        self.assertGreater(checked, 12)

    def test_unfinished_and_short(self):
        """A drive that never finishes (scenario_timeout), result() from its first samples."""
        steps = self.stream(80.0)
        ref = ReferenceLiveScore(self.ROUTE, CITY)
        new = live.LiveScore(self.ROUTE, CITY)
        for k, (t, ego, others, cols, signals) in enumerate(steps):
            ref.add(t, ego, others, cols, signals)
            new.add(t, ego, others, cols, signals)
            if k < 12 or k % 97 == 0:
                self.assert_same(ref.result(), new.result(), "step %d" % k)
                self.assert_same(ref.result(True, True), new.result(True, True), "step %d" % k)
        self.assertIn("scenario_timeout", [i["kind"] for i in new.result(True, True)["infractions"]])

    def assert_bounded(self, ls):
        """Per-sample storage: only the four 8-byte arrays grow with the samples; every other
        container is bounded (the state window) or grows with events."""
        for name, v in vars(ls).items():
            if isinstance(v, array.array):
                self.assertIn(name, ("_t", "_speed", "_yaw", "_prog"))
                self.assertEqual(v.itemsize, 8)
                self.assertLessEqual(len(v), ls.n)
            elif isinstance(v, (list, dict, set, tuple, collections.deque)) and name not in ("route", "map"):
                self.assertLessEqual(len(v), live.STATE_WINDOW, name)
        self.assertLessEqual(len(ls._window), live.STATE_WINDOW)
        self.assertLessEqual(len(ls._stretches) + len(ls._ms_events), 16)
        for st in ls._stretches:
            self.assertLessEqual(len(st["sum"].partials), 64)
        self.assertLessEqual(len(ls._over.partials) + len(ls._off.partials), 128)


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
