"""The pedestrian_agent engine: gap acceptance, lights, sidewalk walks, determinism, bad input.

Experiments built in each test on the city map (experiments/city_traffic/city.xodr). Its road
2 runs along +x from x = 14 to 186 with driving lanes -1, -2 (y = -1.75, -5.25, along +x) and
1, 2 (y = 1.75, 5.25, along -x), sidewalks -3 (y = -8.25) and 3 (y = 8.25); crosswalk 2 crosses
it at s = 2.75 (x = 16.75), next to traffic light 2 (lanes 1, 2). Cars are python_json engines
publishing a RoadUser as JSON at constant speed. A TF builds the pedestrian's neighbours with
python/convoy_traffic/neighbours.py, forwards the lights, and records every step's states to a
JSON-lines file.
"""

import json
import math
import os
import unittest

from e2e_util import BIN_DIR, E2ETestCase

PED = os.path.join(BIN_DIR, "convoy-engine-pedestrian_agent")
CITY = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                    "experiments", "city_traffic", "city.xodr")
CROSS_X = 16.75
CAR_FRONT = 1.35 + 2.25  # length_offset + length / 2

# A python_json car at constant speed v along yaw 0 or pi, from x0 on y.
CAR = """\
import math
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("state")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        d = math.cos({yaw})
        self._setDataPack("state", {{"id": {name!r}, "category": "car", "model": "sedan",
                                     "x": {x0} + d * {v} * t, "y": {y}, "yaw": {yaw},
                                     "speed": {v}, "vx": d * {v}, "length": 4.5, "width": 1.8,
                                     "length_offset": 1.35, "time_ns": self._time_ns}})
"""

# Signal states by time: [(from_s, {id: state})].
LIGHTS = """\
from nrp_core.engines.python_json import EngineScript

PROGRAM = {program!r}


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("traffic_lights")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        signals = {{}}
        for start, states in PROGRAM:
            if t >= start:
                signals = states
        self._setDataPack("traffic_lights", {{"time_ns": self._time_ns, "signals": signals}})
"""

TF = """\
import json
import math
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")

{decorators}
@TransceiverFunction("ped")
def neighbours({args}):
    dps = [{users}]
    users = road_users(dps)
    row = {{u.id: dict(x=u.x, y=u.y, yaw=u.yaw, speed=u.speed, lane=u.lane, road=u.road,
                       s=u.s, absent=u.absent, category=u.category, model=u.model,
                       walk_phase=u.walk_phase, time_ns=u.time_ns)
            for u in users}}
    if not ped.isEmpty():
        row["_digest"] = ped.data.SerializeToString().hex()
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    out = neighbour_datapacks(dps, agents=["ped"], radius=150.0)
{lights}
    return out
"""

FORWARD_LIGHTS = """\
    if not lights.isEmpty():
        out.append(JsonDataPack("traffic_lights", "ped", data=lights.data))"""

# A straight road with sidewalks on both sides and no crosswalk: no way across.
NO_CROSSWALK = """<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="4" name="plain"/>
  <road name="plain" length="100" id="1" junction="-1">
    <link/>
    <planView><geometry s="0" x="0" y="0" hdg="0" length="100"><line/></geometry></planView>
    <lanes>
      <laneSection s="0">
        <left>
          <lane id="1" type="driving" level="false"><link/><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>
          <lane id="2" type="sidewalk" level="false"><link/><width sOffset="0" a="2.5" b="0" c="0" d="0"/></lane>
        </left>
        <center><lane id="0" type="none" level="false"><link/></lane></center>
        <right>
          <lane id="-1" type="driving" level="false"><link/><width sOffset="0" a="3.5" b="0" c="0" d="0"/></lane>
          <lane id="-2" type="sidewalk" level="false"><link/><width sOffset="0" a="2.5" b="0" c="0" d="0"/></lane>
        </right>
      </laneSection>
    </lanes>
  </road>
</OpenDRIVE>
"""


# The same road with a crosswalk at s = 50 and its pedestrian light "p1" (type 1000002), and a
# vehicle light "v1" (type 1000001) at s = 45.
PED_LIGHT = NO_CROSSWALK.replace("""    </lanes>
  </road>""", """    </lanes>
    <objects>
      <object type="crosswalk" id="cw1" name="crosswalk" s="50" t="0" zOffset="0" hdg="0"
              orientation="none" length="3" width="7" height="0">
        <outline>
          <cornerRoad s="48.5" t="-3.5" dz="0" height="0"/>
          <cornerRoad s="51.5" t="-3.5" dz="0" height="0"/>
          <cornerRoad s="51.5" t="3.5" dz="0" height="0"/>
          <cornerRoad s="48.5" t="3.5" dz="0" height="0"/>
        </outline>
      </object>
    </objects>
    <signals>
      <signal s="50" t="-4.5" id="p1" name="ped" dynamic="yes" orientation="+" zOffset="2"
              country="OpenDRIVE" type="1000002" subtype="-1" value="-1"/>
      <signal s="45" t="-4.5" id="v1" name="car" dynamic="yes" orientation="+" zOffset="2.5"
              country="OpenDRIVE" type="1000001" subtype="-1" value="-1"/>
    </signals>
  </road>""")


def on_road(u):
    return u["road"] == "2" and u["lane"] in (-2, -1, 1, 2)


class PedCase(E2ETestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(PED, os.X_OK):
            raise unittest.SkipTest("convoy-engine-pedestrian_agent is not built")

    def experiment(self, ped=None, cars=(), program=None, timeout=30.0, timestep=0.05):
        """cars: (name, x0, y, yaw, v); program: the lights' [(from_s, {id: state})]."""
        out = os.path.join(self.dir, "stream.jsonl")
        p = {"EngineType": "pedestrian_agent", "EngineName": "ped", "EngineTimestep": timestep,
             "Map": CITY, "Route": {"crosswalk": "2"}, "SpeedSd": 0.0, "CriticalGapSd": 0.0}
        p.update(ped or {})
        engines = [p]
        names = ["ped"]
        for name, x0, y, yaw, v in cars:
            self.write(name + ".py", CAR.format(name=name, x0=x0, y=y, yaw=yaw, v=v))
            engines.append({"EngineType": "python_json", "EngineName": name,
                            "PythonFileName": name + ".py", "EngineTimestep": timestep})
            names.append(name)
        users = list(names)
        if program is not None:
            self.write("lights.py", LIGHTS.format(program=program))
            engines.append({"EngineType": "python_json", "EngineName": "lights",
                            "PythonFileName": "lights.py", "EngineTimestep": timestep})
            names.append("lights")
        decorators = "\n".join(
            '@EngineDataPack(keyword="%s", id=DataPackIdentifier("%s", "%s"))'
            % (n, "traffic_lights" if n == "lights" else "state", n) for n in names)
        self.write("tf.py", TF.format(out=out, decorators=decorators, args=", ".join(names),
                                      users=", ".join(users),
                                      lights=FORWARD_LIGHTS if program is not None else ""))
        self.write_config({"SimulationName": "ped", "SimulationTimeout": timeout,
                           "EngineConfigs": engines,
                           "DataPackProcessingFunctions": [{"Name": "neighbours",
                                                            "FileName": "tf.py"}]})
        return out

    def stream(self, path):
        with open(path) as f:
            return [json.loads(line) for line in f]

    def run_ok(self, out, timeout=120):
        r = self.run_convoy(timeout=timeout)
        self.assertExit(r, 0)
        return self.stream(out)


class GapAcceptance(PedCase):
    """A car on lane 1 (y = 1.75) drives towards the crosswalk along -x at 10 m/s."""

    def tta(self, car):
        return (car["x"] - CAR_FRONT - CROSS_X) / car["speed"]

    def crossing(self, x0, gap=4.0):
        out = self.experiment(ped={"CriticalGap": gap},
                              cars=[("car", x0, 1.75, 3.141592653589793, 10.0)], timeout=25.0)
        rows = [r for r in self.run_ok(out) if "ped" in r and "car" in r]
        os.remove(out)
        first = next(i for i, r in enumerate(rows) if on_road(r["ped"]))
        return rows, first

    def test_waits_while_the_time_to_arrival_is_below_its_gap(self):
        # The car reaches the crosswalk at 8.5 s; the pedestrian reaches the curb at 6.6 s.
        rows, first = self.crossing(CROSS_X + CAR_FRONT + 85.0)
        car = rows[first]["car"]
        self.assertLess(car["x"] - CAR_FRONT, CROSS_X, "it stepped out before the car passed")
        # It stood at the curb (not moving) while the car came, with TTA below its gap.
        waiting = [r for r in rows[:first] if abs(r["ped"]["speed"]) < 1e-9 and
                   r["car"]["x"] - CAR_FRONT > CROSS_X and r["ped"]["time_ns"] > 0]
        self.assertGreater(len(waiting), 20, "it never waited")
        # (It acts on the neighbours of the step before: 0.05 s older.)
        self.assertTrue(all(self.tta(r["car"]) < 4.0 + 0.06 for r in waiting))
        self.assertEqual(rows[-1]["ped"]["lane"], 3, "it crossed after the car")

    def test_crosses_when_the_time_to_arrival_is_above_its_gap(self):
        rows, first = self.crossing(CROSS_X + CAR_FRONT + 150.0)
        car = rows[first]["car"]
        self.assertGreater(car["x"] - CAR_FRONT, CROSS_X, "it waited for the car to pass")
        self.assertGreaterEqual(self.tta(car), 4.0)
        self.assertFalse([r for r in rows[:first] if abs(r["ped"]["speed"]) < 1e-9 and
                          r["ped"]["time_ns"] > 0], "it stopped without need")

    def test_a_larger_gap_makes_it_wait_for_the_same_car(self):
        # TTA about 8.5 s when it reaches the curb: accepted with gap 4, refused with gap 12.
        x0 = CROSS_X + CAR_FRONT + 130.0
        _, first_small = self.crossing(x0, gap=4.0)
        rows, first_large = self.crossing(x0, gap=12.0)
        self.assertLess(rows[first_large]["car"]["x"] - CAR_FRONT, CROSS_X)
        self.assertGreater(first_large, first_small)

    def test_stops_when_a_car_comes_close_while_crossing(self):
        # A car at 25 m/s on lane 2 (y = 5.25), out of its view (190 m) when it steps out at
        # 6.6 s, reaches the crossing at 15.6 s, as it is about to enter lane 2.
        out = self.experiment(ped={"CriticalGap": 3.0},
                              cars=[("fast", CROSS_X + CAR_FRONT + 390.0, 5.25,
                                     3.141592653589793, 25.0)], timeout=22.0)
        rows = [r for r in self.run_ok(out) if "ped" in r and "fast" in r]
        ys = [r["ped"]["y"] for r in rows]
        backs = [r for r in rows if r["ped"]["speed"] < -1e-9]
        stops = [r for r in rows if on_road(r["ped"]) and abs(r["ped"]["speed"]) < 1e-9]
        self.assertTrue(stops, "it did not stop on the road")
        self.assertFalse(backs, "no need to step back")
        # Never within 0.3 m of the car's side (y = 4.35) while the car passed it.
        # (Along -x, its box spans x - 3.6 .. x + 0.9.)
        passing = [r for r in rows if r["fast"]["x"] - CAR_FRONT - 0.5 < r["ped"]["x"] <
                   r["fast"]["x"] + 0.9 + 0.5]
        self.assertTrue(passing)
        for r in passing:
            self.assertLess(r["ped"]["y"] + 0.3, 4.35 - 0.3, r)
        self.assertTrue(all(on_road(r["ped"]) and r["ped"]["y"] > 3.0 for r in stops),
                        "it stopped at the lane's edge")
        self.assertGreater(ys[-1], 7.0, "it crossed in the end")

    def test_steps_back_when_a_car_appears_while_it_is_in_the_lane(self):
        # It sees only 12 m around it; a car at 8 m/s on lane 2 (y = 5.25) reaches the crossing
        # at 16 s and comes into view at about 15 s, when it has just entered lane 2's band.
        out = self.experiment(ped={"CriticalGap": 3.0, "NeighbourRadius": 12.0},
                              cars=[("slow", CROSS_X + CAR_FRONT + 8.0 * 16.0, 5.25,
                                     3.141592653589793, 8.0)], timeout=22.0)
        rows = [r for r in self.run_ok(out) if "ped" in r and "slow" in r]
        backs = [r for r in rows if r["ped"]["speed"] < -1e-9]
        self.assertTrue(backs, "it did not step back")
        self.assertTrue(all(on_road(r["ped"]) and r["ped"]["y"] > 3.0 for r in backs))
        passing = [r for r in rows if r["slow"]["x"] - CAR_FRONT - 0.5 < r["ped"]["x"] <
                   r["slow"]["x"] + 0.9 + 0.5]
        self.assertTrue(passing)
        for r in passing:  # no contact with the car's side (y = 4.35)
            self.assertLess(r["ped"]["y"] + 0.3, 4.35, r)
        self.assertGreater(rows[-1]["ped"]["y"], 7.0, "it crossed in the end")


class Lights(PedCase):
    def test_waits_while_the_crossed_road_has_green_and_crosses_on_red(self):
        out = self.experiment(program=[(0.0, {"2": "green"}), (12.0, {"2": "red"})],
                              timeout=25.0)
        rows = [r for r in self.run_ok(out) if "ped" in r]
        first = next(r for r in rows if on_road(r["ped"]))
        self.assertGreaterEqual(first["ped"]["time_ns"], 12e9)
        self.assertLess(first["ped"]["time_ns"], 13e9, "it went as soon as it could")
        self.assertEqual(rows[-1]["ped"]["lane"], 3)

    def test_a_pedestrian_light_rules_where_there_is_one(self):
        # The vehicle light is red all along (would let it go); it waits for its own green.
        self.write("pl.xodr", PED_LIGHT)
        out = self.experiment(ped={"Map": "pl.xodr", "Route": {"crosswalk": "cw1"}},
                              program=[(0.0, {"p1": "red", "v1": "red"}),
                                       (10.0, {"p1": "green", "v1": "red"})], timeout=20.0)
        rows = [r["ped"] for r in self.run_ok(out) if "ped" in r]
        first = next(u for u in rows if u["lane"] in (-1, 1))
        self.assertGreaterEqual(first["time_ns"], 10e9)
        self.assertLess(first["time_ns"], 11e9)
        self.assertTrue([u for u in rows if abs(u["speed"]) < 1e-9 and 0 < u["time_ns"] < 10e9])
        self.assertEqual(rows[-1]["lane"], 2)

    def test_yellow_is_not_red(self):
        out = self.experiment(program=[(0.0, {"2": "yellow"}), (9.0, {"2": "red"})],
                              timeout=15.0)
        rows = [r for r in self.run_ok(out) if "ped" in r]
        first = next(r for r in rows if on_road(r["ped"]))
        self.assertGreaterEqual(first["ped"]["time_ns"], 9e9)

    def test_red_from_the_start_crosses_without_stopping(self):
        out = self.experiment(program=[(0.0, {"2": "red"})], timeout=15.0)
        rows = [r for r in self.run_ok(out) if "ped" in r]
        self.assertFalse([r for r in rows if abs(r["ped"]["speed"]) < 1e-9 and
                          0 < r["ped"]["time_ns"] and not r["ped"]["absent"]])


class Sidewalk(PedCase):
    def test_walks_along_the_sidewalk_and_ends_absent(self):
        out = self.experiment(ped={"Route": {"from": "2:-3", "from_s": 20.0, "to": "2:-3",
                                             "to_s": 40.0}, "Speed": 1.5}, timeout=16.0)
        rows = [r["ped"] for r in self.run_ok(out) if "ped" in r]
        present = [u for u in rows if not u["absent"]]
        self.assertTrue(all(u["lane"] == -3 and u["road"] == "2" for u in present))
        # the sidewalk's centre is y = -8.25; walking east, it keeps 0.55 m to its right
        self.assertTrue(all(abs(u["y"] + 8.25 + 0.55) < 0.01 for u in present))
        self.assertAlmostEqual(present[0]["x"], 34.0, delta=0.1)
        self.assertAlmostEqual(present[-1]["x"], 54.0, delta=0.1)
        self.assertTrue(rows[-1]["absent"], "absent at its route's end")
        ends = [u["time_ns"] for u in rows if u["absent"]]
        self.assertAlmostEqual(min(ends) * 1e-9, 20.0 / 1.5, delta=0.1)
        self.assertEqual(present[1]["category"], "pedestrian")
        self.assertEqual(present[1]["model"], "walker")
        phases = [u["walk_phase"] for u in present]
        self.assertTrue(all(0 <= p < 1 for p in phases))
        self.assertGreater(len({round(p, 3) for p in phases}), 50, "the walking phase advances")

    def test_speed_is_drawn_per_pedestrian(self):
        speeds = []
        for seed in range(3):
            out = self.experiment(ped={"Route": {"from": "2:-3", "from_s": 20.0, "to": "2:-3",
                                                 "to_s": 40.0}, "Seed": seed, "SpeedSd": 0.2},
                                  timeout=2.0)
            rows = [r["ped"] for r in self.run_ok(out) if "ped" in r]
            speeds.append(rows[5]["speed"])
            os.remove(out)
        self.assertEqual(len(set(speeds)), 3, speeds)
        self.assertTrue(all(0.95 <= s <= 1.75 for s in speeds), speeds)

    def test_rain_makes_it_walk_faster(self):
        # The weather datapack's format (a python_json engine standing in for `weather`).
        self.write("weather.py", """\
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("weather")
        self._setDataPack("weather", {"precipitation": 0.5, "precipitation_type": "rain"})

    def runLoop(self, timestep_ns):
        pass
""")
        out = self.experiment(ped={"Route": {"from": "2:-3", "from_s": 20.0, "to": "2:-3",
                                             "to_s": 40.0}, "Speed": 1.0}, timeout=2.0)
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        cfg["EngineConfigs"].append({"EngineType": "python_json", "EngineName": "weather",
                                     "PythonFileName": "weather.py", "EngineTimestep": 0.05})
        cfg["DataPackProcessingFunctions"].append({"Name": "weather", "FileName": "wtf.py"})
        self.write("wtf.py", """\
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack


@EngineDataPack(keyword="w", id=DataPackIdentifier("weather", "weather"))
@TransceiverFunction("ped")
def weather(w):
    return [] if w.isEmpty() else [JsonDataPack("weather", "ped", data=w.data)]
""")
        self.write_config(cfg)
        rows = [r["ped"] for r in self.run_ok(out) if "ped" in r]
        self.assertAlmostEqual(rows[-1]["speed"], 1.1, places=6)


class Determinism(PedCase):
    def test_two_runs_give_the_same_stream(self):
        digests = []
        for _ in range(2):
            out = self.experiment(ped={"Route": {}, "Seed": 7, "SpeedSd": 0.2,
                                       "CriticalGapSd": 0.5, "MidBlockProbability": 0.5},
                                  cars=[("car", 150.0, 1.75, 3.141592653589793, 8.0)],
                                  timeout=8.0)
            rows = self.run_ok(out)
            digests.append([r.get("_digest") for r in rows])
            os.remove(out)
        self.assertEqual(digests[0], digests[1])
        self.assertGreater(len(digests[0]), 100)

    def test_mid_block_crossing_is_away_from_the_crosswalk(self):
        out = self.experiment(ped={"MidBlockProbability": 1.0}, timeout=25.0)
        rows = [r["ped"] for r in self.run_ok(out) if "ped" in r]
        xs = [u["x"] for u in rows if on_road(u)]
        self.assertTrue(xs, "it crossed")
        self.assertGreater(min(xs), CROSS_X + 10.0)
        self.assertEqual(rows[-1]["lane"], 3)


class BadInput(PedCase):
    def bad(self, ped, *needles):
        self.experiment(ped=ped, timeout=2.0)
        r = self.run_convoy()
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "pedestrian_agent", "ped", *needles)
        self.assertNoEngineLeft()
        return r

    def test_start_lane_that_does_not_exist(self):
        self.bad({"Route": {"from": "2:-7", "to": "2:3"}}, "Route.from", "lane -7")

    def test_start_lane_not_a_sidewalk(self):
        self.bad({"Route": {"from": "2:-1", "to": "2:3"}}, "Route.from", "driving lane",
                 "not a sidewalk")

    def test_missing_road(self):
        self.bad({"Route": {"from": "99:-3", "to": "2:3"}}, "Route.from", "road 99")

    def test_no_route(self):
        self.write("plain.xodr", NO_CROSSWALK)
        self.bad({"Map": "plain.xodr", "Route": {"from": "1:-2", "to": "1:2"}}, "Route",
                 "no route")

    def test_unknown_crosswalk(self):
        self.bad({"Route": {"crosswalk": "77"}}, "Route.crosswalk", "77")

    def test_placed_off_road(self):
        self.bad({"Route": {"to": "2:3"}, "Position": {"x": 100.0, "y": 60.0}}, "Position",
                 "(100.00, 60.00)", "not on a sidewalk")

    def test_placed_on_the_carriageway(self):
        self.bad({"Route": {"to": "2:3"}, "Position": {"x": 100.0, "y": -1.75}}, "Position",
                 "driving")

    def test_unknown_key_warns_by_name(self):
        self.experiment(ped={"Sped": 1.0}, timeout=0.5)
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertRegex(r.stderr, r"(?i)warning.*Sped")

    def test_unreadable_map(self):
        self.write("broken.xodr", "<OpenDRIVE><road")
        self.bad({"Map": "broken.xodr"}, "Map", "broken.xodr")


# A pedestrian that ignores traffic: walks across road 2 at x = 100 along +y at 1.3 m/s from
# y = -8.25 from the start.
WALKER = """\
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("state")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        y = min(-8.25 + 1.3 * t, 8.25)
        self._setDataPack("state", {"id": "walker", "category": "pedestrian", "model": "walker",
                                    "x": 100.0, "y": y, "yaw": 1.5708, "speed": 1.3,
                                    "length": 0.5, "width": 0.6, "time_ns": self._time_ns})
"""

CAR_TF = """\
import json
import math
from nrp_core import *
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")


@EngineDataPack(keyword="car", id=DataPackIdentifier("state", "car"))
@EngineDataPack(keyword="walker", id=DataPackIdentifier("state", "walker"))
@TransceiverFunction("car")
def neighbours(car, walker):
    users = road_users([car, walker])
    _out.write(json.dumps({{u.id: dict(x=u.x, y=u.y, speed=u.speed, absent=u.absent)
                           for u in users}}) + "\\n")
    _out.flush()
    return neighbour_datapacks([car, walker], agents=["car"], radius=150.0)
"""


class VehicleReacts(PedCase):
    def test_a_vehicle_agent_brakes_for_a_pedestrian_on_its_lane(self):
        # The vehicle_agent drives road 2's lane 1 along -x from x = 186 at 10 m/s; the walker
        # is in its path from t = 6.7 s to 8.7 s, when the car would pass x = 100 at 8.2 s.
        out = os.path.join(self.dir, "stream.jsonl")
        self.write("walker.py", WALKER)
        self.write("tf.py", CAR_TF.format(out=out))
        self.write_config({"SimulationName": "react", "SimulationTimeout": 20.0,
                           "EngineConfigs": [
                               {"EngineType": "vehicle_agent", "EngineName": "car",
                                "EngineTimestep": 0.05, "Map": CITY,
                                "Route": {"from": "2:1", "to": "2:1"}, "InitialSpeed": 10.0,
                                "v0": 10.0, "LaneChanges": False},
                               {"EngineType": "python_json", "EngineName": "walker",
                                "PythonFileName": "walker.py", "EngineTimestep": 0.05}],
                           "DataPackProcessingFunctions": [{"Name": "n", "FileName": "tf.py"}]})
        rows = [r for r in self.run_ok(out) if "car" in r and "walker" in r]
        # Along -x the car's front is 3.6 m ahead of its reference point.
        gaps = [r["car"]["x"] - 3.6 - r["walker"]["x"] for r in rows
                if -0.5 < r["walker"]["y"] < 4.0 and r["car"]["x"] > r["walker"]["x"]]
        self.assertTrue(gaps)
        self.assertGreater(min(gaps), 1.0, "it stopped short of the pedestrian")
        self.assertLess(min(r["car"]["speed"] for r in rows), 5.0, "it braked")
        self.assertLess(rows[-1]["car"]["x"], 90.0, "it went on once the lane was clear")


class Example(PedCase):
    def test_the_example_runs(self):
        root = os.path.dirname(os.path.dirname(CITY))
        ex = os.path.join(root, "pedestrians")
        for name in ("simulation_config.json", "neighbours_tf.py"):
            with open(os.path.join(ex, name)) as f:
                text = f.read()
            text = text.replace("../common/weather_tf.py",
                                os.path.join(root, "common", "weather_tf.py"))
            self.write(name, text.replace("../city_traffic/city.xodr", CITY))
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        self.assertNotRegex(r.stderr, r"(?i)warning", "every key of the example is known")
        rows = []
        with open(os.path.join(self.dir, "tracks.jsonl")) as f:
            rows = [json.loads(line) for line in f]
        self.assertGreater(len(rows), 1000)
        last = rows[-1]["users"]
        self.assertEqual(sum(1 for k in last if k.startswith("ped_")), 6)
        # Three of them crossed and left; none came within 2 m of a car's reference point.
        self.assertGreaterEqual(sum(1 for k, u in last.items() if k.startswith("ped_") and u[3]),
                                3)
        for row in rows:
            u = row["users"]
            for c in ("car_0", "car_1"):
                for p in u:
                    if p.startswith("ped_") and not u[p][3] and c in u and not u[c][3]:
                        d = ((u[c][0] - u[p][0]) ** 2 + (u[c][1] - u[p][1]) ** 2) ** 0.5
                        self.assertGreater(d, 2.0, (row["t"], c, p))


if __name__ == "__main__":
    unittest.main()


WALKERS_TF = """\
import json
import math
from nrp_core import *
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")


@EngineDataPack(keyword="a", id=DataPackIdentifier("state", "a"))
@EngineDataPack(keyword="b", id=DataPackIdentifier("state", "b"))
@TransceiverFunction("a")
def neighbours(a, b):
    users = road_users([a, b])
    _out.write(json.dumps({{u.id: [u.x, u.y, u.speed, u.absent] for u in users}}) + "\\n")
    return neighbour_datapacks([a, b], agents=["a", "b"], radius=50.0)
"""


class Walkers(PedCase):
    """Walkers on one sidewalk never overlap: oncoming ones pass on their right, a faster one
    keeps behind a slower one."""

    def walkers(self, a, b, timeout):
        out = os.path.join(self.dir, "walkers.jsonl")
        self.write("tf.py", WALKERS_TF.format(out=out))
        base = {"EngineType": "pedestrian_agent", "EngineTimestep": 0.05, "Map": CITY,
                "SpeedSd": 0.0, "CriticalGapSd": 0.0}
        self.write_config({
            "SimulationName": "walkers", "SimulationTimeout": timeout,
            "EngineConfigs": [dict(base, EngineName="a", **a), dict(base, EngineName="b", **b)],
            "DataPackProcessingFunctions": [{"Name": "tf", "FileName": "tf.py"}]})
        r = self.run_convoy()
        self.assertExit(r, 0)
        with open(out) as f:
            rows = [json.loads(l) for l in f]
        both = [r for r in rows if "a" in r and "b" in r and not r["a"][3] and not r["b"][3]]
        self.assertGreater(len(both), 20)
        # bodies 0.45 m wide, 0.3 m deep: apart by more than that at every step
        return min(math.hypot(r["a"][0] - r["b"][0], r["a"][1] - r["b"][1]) for r in both), rows

    def test_oncoming_walkers_pass_each_other(self):
        gap, rows = self.walkers(
            {"Route": {"from": "2:-3", "from_s": 20.0, "to": "2:-3", "to_s": 60.0}},
            {"Route": {"from": "2:-3", "from_s": 60.0, "to": "2:-3", "to_s": 20.0}}, 35.0)
        self.assertGreater(gap, 0.6)
        self.assertTrue(rows[-1]["a"][3] and rows[-1]["b"][3], "both arrived")

    def test_a_faster_walker_keeps_behind(self):
        gap, rows = self.walkers(
            {"Route": {"from": "2:-3", "from_s": 20.0, "to": "2:-3", "to_s": 60.0}, "Speed": 1.8},
            {"Route": {"from": "2:-3", "from_s": 23.0, "to": "2:-3", "to_s": 60.0}, "Speed": 1.0},
            15.0)
        self.assertGreater(gap, 0.6)
        late = [r for r in rows if "a" in r and "b" in r and not r["b"][3]][-1]
        self.assertLess(late["a"][0], late["b"][0], "a is still behind b")
