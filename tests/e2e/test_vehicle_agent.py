"""The vehicle_agent engine: IDM, MOBIL, red lights, determinism and bad input.

Experiments built in each test, on a straight OpenDRIVE road written here: 1000 m along +x
from (0, 0), two lanes driven with s (-1 at y = -1.75, -2 at y = -5.25, a broken line
between) and one the other way; optionally a traffic light at s = 150 for the lanes along s.
Other road users are python_json engines publishing a RoadUser as JSON at constant speed. A TF
builds the agent's neighbours with python/convoy_traffic/neighbours.py and records every
step's states to a JSON-lines file.
"""

import hashlib
import json
import math
import os
import unittest

from e2e_util import BIN_DIR, E2ETestCase

AGENT = os.path.join(BIN_DIR, "convoy-engine-vehicle_agent")
EXIT_USER, EXIT_ENGINE = 2, 3
W = 3.5
LENGTH = 1000.0

SIGNAL = """
    <signals>
      <signal s="150" t="-7.5" id="sig1" name="light" dynamic="yes" orientation="+" zOffset="2.5"
              country="OpenDRIVE" type="1000001" subtype="-1" value="-1"/>
    </signals>"""

XODR = """<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="4" name="two_lanes"/>
  <road name="main" length="{L}" id="1" junction="-1">
    <link/>
    <planView>
      <geometry s="0" x="0" y="0" hdg="0" length="{L}"><line/></geometry>
    </planView>
    <lanes>
      <laneSection s="0">
        <left><lane id="1" type="driving" level="false"><link/>
          <width sOffset="0" a="{w}" b="0" c="0" d="0"/></lane></left>
        <center><lane id="0" type="none" level="false"><link/>
          <roadMark sOffset="0" type="solid" color="standard"/></lane></center>
        <right>
          <lane id="-1" type="driving" level="false"><link/>
            <width sOffset="0" a="{w}" b="0" c="0" d="0"/>
            <roadMark sOffset="0" type="broken" color="standard"/></lane>
          <lane id="-2" type="driving" level="false"><link/>
            <width sOffset="0" a="{w}" b="0" c="0" d="0"/>
            <roadMark sOffset="0" type="solid" color="standard"/></lane>
        </right>
      </laneSection>
    </lanes>{signals}
  </road>
</OpenDRIVE>
"""

# A python_json road user at constant speed along +x.
CONSTANT = """\
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("state")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        self._setDataPack("state", {{"id": {name!r}, "category": "car", "model": "sedan",
                                     "x": {x0} + {v} * t, "y": {y}, "yaw": 0.0, "speed": {v},
                                     "vx": {v}, "length": 4.5, "width": 1.8,
                                     "length_offset": 1.35, "time_ns": self._time_ns}})
"""

TF = """\
import json
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")

{decorators}
@TransceiverFunction("car")
def neighbours({args}):
    dps = [{args}]
    users = road_users(dps)
    row = {{u.id: dict(x=u.x, y=u.y, yaw=u.yaw, speed=u.speed, acc=u.acceleration,
                       lane=u.lane, road=u.road, s=u.s, t=u.t, lights=u.lights, absent=u.absent,
                       length=u.length, length_offset=u.length_offset, time_ns=u.time_ns)
            for u in users}}
    if not car.isEmpty():
        row["_digest"] = car.data.SerializeToString().hex()
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    out = neighbour_datapacks(dps, agents=["car"], radius=150.0)
{lights}
    return out
"""


def front(u):
    return u["x"] + u["length_offset"] + 0.5 * u["length"]


def rear(u):
    return u["x"] + u["length_offset"] - 0.5 * u["length"]


def idm_acc(v, gap, vl, v0, T=1.5, s0=2.0, a=1.5, b=2.0, delta=4.0):
    s_star = s0 + max(0.0, v * T + v * (v - vl) / (2 * math.sqrt(a * b)))
    return a * (1 - (v / v0) ** delta - (s_star / max(gap, 0.01)) ** 2)


class AgentCase(E2ETestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(AGENT, os.X_OK):
            raise unittest.SkipTest("convoy-engine-vehicle_agent is not built")

    def experiment(self, agent=None, others=(), timeout=30.0, signal=False, lights="",
                   timestep=0.05):
        """others: (name, x0, y, v); lights: code adding to `out` in the TF."""
        self.write("road.xodr", XODR.format(L=LENGTH, w=W, signals=SIGNAL if signal else ""))
        out = os.path.join(self.dir, "stream.jsonl")
        car = {"EngineType": "vehicle_agent", "EngineName": "car", "EngineTimestep": timestep,
               "Map": "road.xodr", "Route": {"from": "1:-1", "to": "1:-1"}, "v0": 20.0}
        car.update(agent or {})
        engines = [car]
        names = ["car"]
        for name, x0, y, v in others:
            self.write(name + ".py", CONSTANT.format(name=name, x0=x0, y=y, v=v))
            engines.append({"EngineType": "python_json", "EngineName": name,
                            "PythonFileName": name + ".py", "EngineTimestep": timestep})
            names.append(name)
        decorators = "\n".join(
            '@EngineDataPack(keyword="%s", id=DataPackIdentifier("state", "%s"))' % (n, n)
            for n in names)
        self.write("tf.py", TF.format(out=out, decorators=decorators, args=", ".join(names),
                                      lights=lights))
        self.write_config({"SimulationName": "agent", "SimulationTimeout": timeout,
                           "EngineConfigs": engines,
                           "DataPackProcessingFunctions": [{"Name": "neighbours",
                                                            "FileName": "tf.py"}]})
        return out

    def stream(self, path):
        with open(path) as f:
            return [json.loads(line) for line in f]


class Idm(AgentCase):
    def test_steady_state_gap_behind_a_constant_speed_leader(self):
        v, v0, T, s0, delta = 10.0, 20.0, 1.5, 2.0, 4.0
        out = self.experiment(agent={"InitialSpeed": 15.0, "LaneChanges": False},
                              others=[("leader", 60.0, -1.75, v)], timeout=60.0)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if "car" in row and "leader" in row]
        self.assertGreater(len(rows), 1000)
        expected = (s0 + v * T) / math.sqrt(1 - (v / v0) ** delta)
        tail = rows[-200:]  # the last 10 s
        gaps = [rear(row["leader"]) - front(row["car"]) for row in tail]
        gap = sum(gaps) / len(gaps)
        self.assertLess(abs(gap - expected) / expected, 0.05, (gap, expected))
        self.assertLess(abs(tail[-1]["car"]["speed"] - v), 0.2)
        # It stayed in its lane, and says where it is.
        self.assertEqual({row["car"]["lane"] for row in rows}, {-1})
        self.assertEqual({row["car"]["road"] for row in rows}, {"1"})
        self.assertLess(max(abs(row["car"]["y"] + 1.75) for row in rows), 0.05)
        # Braking lights while it decelerates.
        braking = [row["car"] for row in rows if row["car"]["acc"] < -0.35]
        self.assertTrue(braking)
        self.assertTrue(all(u["lights"] & 2 for u in braking))

    def test_free_road_reaches_v0_and_leaves_at_the_route_end(self):
        out = self.experiment(agent={"InitialSpeed": 15.0, "v0": 25.0, "LaneChanges": False},
                              timeout=60.0, timestep=0.1)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        cars = [row["car"] for row in self.stream(out) if "car" in row]
        self.assertGreater(max(u["speed"] for u in cars), 24.0)
        self.assertTrue(cars[-1]["absent"], "the route ended: the agent is absent")
        self.assertGreater(cars[-1]["x"], LENGTH - 10)


class Weather(AgentCase):
    WEATHER = ('    w = JsonDataPack("weather", "car")\n'
               '    w.data["mu"] = {mu}\n'
               '    w.data["visibility_m"] = 20000.0\n'
               '    out.append(w)\n')

    def steady_gap(self, mu):
        out = self.experiment(agent={"InitialSpeed": 10.0, "LaneChanges": False},
                              others=[("leader", 40.0, -1.75, 10.0)], timeout=60.0,
                              lights=self.WEATHER.format(mu=mu))
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if "car" in row and "leader" in row]
        tail = rows[-200:]  # the last 10 s
        gaps = [rear(row["leader"]) - front(row["car"]) for row in tail]
        return sum(gaps) / len(gaps), tail[-1]["car"]["speed"]

    def test_gap_grows_on_a_wet_road(self):
        # IDM's steady gap (s0 + v T) / sqrt(1 - (v/v0)^4) with the weather's T and v0: dry
        # (mu 0.8) T 1.5 s, v0 20 m/s; wet (mu 0.5) T 1.78 s, v0 17 m/s.
        v = 10.0
        dry, v_dry = self.steady_gap(0.8)
        wet, v_wet = self.steady_gap(0.5)
        expected_dry = (2.0 + v * 1.5) / math.sqrt(1 - (v / 20.0) ** 4)
        expected_wet = (2.0 + v * 1.5 * 1.1875) / math.sqrt(1 - (v / 17.0) ** 4)
        self.assertLess(abs(dry - expected_dry) / expected_dry, 0.05, (dry, expected_dry))
        self.assertLess(abs(wet - expected_wet) / expected_wet, 0.05, (wet, expected_wet))
        self.assertGreater(wet, 1.15 * dry, (dry, wet))
        self.assertLess(abs(v_dry - v), 0.2)
        self.assertLess(abs(v_wet - v), 0.2)

    def test_slower_on_ice_and_in_fog(self):
        speeds = {}
        for label, mu, vis in (("dry", 0.8, 20000.0), ("ice", 0.1, 20000.0), ("fog", 0.8, 60.0)):
            code = self.WEATHER.format(mu=mu).replace("20000.0", repr(vis))
            out = self.experiment(agent={"InitialSpeed": 15.0, "v0": 25.0, "LaneChanges": False},
                                  timeout=40.0, timestep=0.1, lights=code)
            r = self.run_convoy(timeout=120)
            self.assertExit(r, 0)
            cars = [row["car"] for row in self.stream(out) if "car" in row and not row["car"]["absent"]]
            speeds[label] = max(u["speed"] for u in cars[-50:])
            os.remove(out)
        self.assertGreater(speeds["dry"], 24.0)
        self.assertLess(speeds["ice"], 0.7 * 25.0 + 0.3)   # 25 x (1 - 0.4 x 0.875) = 16.25
        self.assertGreater(speeds["ice"], 15.5)
        # Fog of 60 m: it can stop within 60 m (1.5 s + braking at 0.5 mu g): 17.0 m/s.
        grip = 0.5 * 0.8 * 9.81
        v_fog = grip * (-1.5 + math.sqrt(1.5 ** 2 + 2 * 60.0 / grip))
        self.assertLess(abs(speeds["fog"] - v_fog), 0.3, (speeds, v_fog))


class Respawn(AgentCase):
    def test_starts_again_at_its_start_after_the_delay(self):
        out = self.experiment(agent={"InitialSpeed": 15.0, "v0": 25.0, "LaneChanges": False,
                                     "Respawn": True, "RespawnDelay": 1.5},
                              timeout=90.0, timestep=0.1)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        cars = [row["car"] for row in self.stream(out) if "car" in row]
        first_gone = next(i for i, u in enumerate(cars) if u["absent"])
        back = next(i for i in range(first_gone, len(cars)) if not cars[i]["absent"])
        # absent at least RespawnDelay, then present again at its start, at InitialSpeed
        self.assertGreaterEqual(cars[back]["time_ns"] - cars[first_gone]["time_ns"], 1.5e9 - 1)
        self.assertLess(cars[back]["x"], 1.0)
        self.assertAlmostEqual(cars[back]["speed"], 15.0, delta=0.5)
        # and it drives the route again
        self.assertGreater(max(u["x"] for u in cars[back:]), LENGTH / 2)


class Mobil(AgentCase):
    def test_overtakes_a_slow_leader(self):
        out = self.experiment(agent={"InitialSpeed": 12.0, "v0": 15.0},
                              others=[("slow", 50.0, -1.75, 5.0)], timeout=25.0)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if "car" in row and "slow" in row]
        lanes = [row["car"]["lane"] for row in rows]
        self.assertIn(-2, lanes, "it changed to the other lane (-2, on its right)")
        passed = [row for row in rows if rear(row["car"]) > front(row["slow"]) + 5]
        self.assertTrue(passed, "it overtook the slow car")
        # The right indicator was on while it changed.
        first = lanes.index(-2)
        self.assertTrue(any(row["car"]["lights"] & 8 for row in rows[max(0, first - 40):first + 1]))
        # Never closer than 1 m to the slow car's back while in its lane.
        for row in rows:
            if row["car"]["lane"] == -1 and row["car"]["x"] < row["slow"]["x"]:
                self.assertGreater(rear(row["slow"]) - front(row["car"]), 1.0)

    def test_waits_for_a_safe_gap(self):
        b_safe = 1.0
        # A faster car in the other lane, coming from behind: the change must wait until it
        # would not make that car brake harder than b_safe.
        out = self.experiment(agent={"InitialSpeed": 12.0, "v0": 15.0, "b_safe": b_safe},
                              others=[("slow", 50.0, -1.75, 5.0), ("fast", -35.0, -5.25, 14.0)],
                              timeout=25.0)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if all(k in row for k in ("car", "slow", "fast"))]
        changes = [i for i in range(1, len(rows))
                   if rows[i]["car"]["lights"] & 12 and not rows[i - 1]["car"]["lights"] & 12]
        self.assertTrue(changes, "it changed lanes")
        for i in changes:
            car, fast = rows[i]["car"], rows[i]["fast"]
            if front(fast) < rear(car):  # the fast car is the new follower
                acc = idm_acc(fast["speed"], rear(car) - front(fast), car["speed"], 15.0)
                self.assertGreaterEqual(acc, -b_safe - 0.1, (i, car, fast))
        # Without the safety rule it would have changed earlier: it waited while the fast car
        # was close behind.
        t_change = rows[changes[0]]["car"]["time_ns"]
        os.rename(out, out + ".with_fast")
        out = self.experiment(agent={"InitialSpeed": 12.0, "v0": 15.0},
                              others=[("slow", 50.0, -1.75, 5.0)], timeout=25.0)
        self.assertExit(self.run_convoy(timeout=120), 0)
        alone = self.stream(out)
        first_alone = next(row["car"]["time_ns"] for row in alone
                           if "car" in row and row["car"]["lights"] & 12)
        self.assertGreater(t_change, first_alone)


LIGHT = """\
    t = car.data.time_ns * 1e-9 if not car.isEmpty() else 0.0
    out.append(JsonDataPack("traffic_lights", "car", {{"time_ns": 0, "signals": {{"sig1": "red" if t < {green_at} else "green"}}}}))
"""


class RedLight(AgentCase):
    def test_stops_before_the_stop_line_and_goes_on_green(self):
        out = self.experiment(agent={"InitialSpeed": 12.0, "v0": 14.0, "LaneChanges": False},
                              signal=True, lights=LIGHT.format(green_at=25.0), timeout=40.0)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        cars = [row["car"] for row in self.stream(out) if "car" in row]
        before = [u for u in cars if u["time_ns"] < 25e9]
        self.assertLess(max(front(u) for u in before), 150.0, "never past the stop line on red")
        stopped = [u for u in before if u["speed"] < 0.05]
        self.assertTrue(stopped, "it stopped")
        self.assertGreater(front(stopped[-1]), 140.0, "it stopped near the line, not far before")
        self.assertGreater(max(front(u) for u in cars), 250.0, "it went on at green")


class Determinism(AgentCase):
    def test_two_runs_give_the_same_stream(self):
        digests = []
        for _ in range(2):
            out = self.experiment(agent={"InitialSpeed": 12.0, "v0": 15.0, "ReactionTime": 0.3},
                                  others=[("slow", 50.0, -1.75, 5.0), ("fast", -35.0, -5.25, 14.0)],
                                  timeout=15.0)
            self.assertExit(self.run_convoy(timeout=120), 0)
            rows = [row["_digest"] for row in self.stream(out) if "_digest" in row]
            self.assertGreater(len(rows), 200)
            digests.append(hashlib.sha1("".join(rows).encode()).hexdigest())
            os.remove(out)
        self.assertEqual(digests[0], digests[1])


class BadInput(AgentCase):
    def bad(self, agent, *needles):
        self.experiment(agent=agent, timeout=2.0)
        r = self.run_convoy()
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "car", *needles)
        self.assertNoEngineLeft()
        return r

    def test_start_lane_that_does_not_exist(self):
        self.bad({"Route": {"from": "1:-3", "to": "1:-1"}}, "Route.from", "lane -3")

    def test_no_route(self):
        # Lane 1 runs against s, the other way: no route from -1 to it.
        self.bad({"Route": {"from": "1:-1", "to": "1:1"}}, "Route", "no route")

    def test_placed_off_the_route(self):
        self.bad({"StartS": 5000.0}, "StartS", "off its route")

    def test_placed_off_road(self):
        # 30 m north of the road (its lanes span y = -7 .. 3.5).
        self.bad({"Route": {"to": "1:-1"}, "Position": {"x": 100.0, "y": 30.0}},
                 "Position", "off-road", "(100.00, 30.00)")

    def test_placed_on_the_road_by_position(self):
        out = self.experiment(agent={"Route": {"to": "1:-1"}, "Position": {"x": 100.0, "y": -1.9},
                                     "InitialSpeed": 10.0, "LaneChanges": False}, timeout=2.0)
        self.assertExit(self.run_convoy(), 0)
        cars = [row["car"] for row in self.stream(out) if "car" in row]
        self.assertAlmostEqual(cars[0]["x"], 100.0, delta=0.5)
        self.assertAlmostEqual(cars[0]["y"], -1.75, delta=0.01)
        self.assertGreater(cars[-1]["x"], 115.0)

    def test_unknown_key_warns_by_name(self):
        self.experiment(agent={"Politeness": 0.5}, timeout=0.5)  # the key is "politeness"
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertRegex(r.stderr, r"(?i)warning.*Politeness")

    def test_bad_lane_syntax(self):
        self.bad({"Route": {"from": "main", "to": "1:-1"}}, "Route.from", "ROAD:LANE")

    def test_unreadable_map(self):
        self.write("broken.xodr", "<OpenDRIVE><road")
        self.bad({"Map": "broken.xodr"}, "Map", "broken.xodr")


CITY = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                    "experiments", "city_traffic", "city.xodr")

MULTI_TF = """\
import json
from nrp_core import *
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")

{decorators}
@TransceiverFunction({first!r})
def neighbours({args}):
    dps = [{args}]
    users = road_users(dps)
    _out.write(json.dumps({{u.id: dict(x=u.x, y=u.y, road=u.road, lane=u.lane, speed=u.speed,
                                       absent=u.absent) for u in users}}, sort_keys=True) + "\\n")
    _out.flush()
    return neighbour_datapacks(dps, agents={agents!r}, radius=120.0)
"""


class Junction(AgentCase):
    def junction_roads(self, junction):
        import xml.etree.ElementTree as ET
        return {r.get("id") for r in ET.parse(CITY).getroot().iter("road")
                if r.get("junction") == junction}

    def crossing(self, yielding):
        # Two cars 86 m from junction 100 at the same speed: one straight east (road 1 ->
        # 2), one north (road 5 -> 4); their paths cross inside the junction.
        agents = {"a": {"Route": {"from": "1:-1", "to": "2:-1"}, "StartS": 150.0},
                  "b": {"Route": {"from": "5:-1", "to": "4:-1"}, "StartS": 50.0}}
        engines = []
        for name, extra in sorted(agents.items()):
            e = {"EngineType": "vehicle_agent", "EngineName": name, "EngineTimestep": 0.05,
                 "Map": CITY, "InitialSpeed": 10.0, "v0": 10.0, "LaneChanges": False,
                 "JunctionYielding": yielding}
            e.update(extra)
            engines.append(e)
        out = os.path.join(self.dir, "stream.jsonl")
        names = sorted(agents)
        decorators = "\n".join(
            '@EngineDataPack(keyword="%s", id=DataPackIdentifier("state", "%s"))' % (n, n)
            for n in names)
        self.write("tf.py", MULTI_TF.format(out=out, decorators=decorators, first=names[0],
                                            args=", ".join(names), agents=names))
        self.write_config({"SimulationName": "junction", "SimulationTimeout": 30.0,
                           "EngineConfigs": engines,
                           "DataPackProcessingFunctions": [{"Name": "neighbours",
                                                            "FileName": "tf.py"}]})
        self.assertExit(self.run_convoy(timeout=120), 0)
        inside = self.junction_roads("100")
        both = []
        passed = {n: False for n in names}
        for row in self.stream(out):
            ins = [n for n in names if n in row and not row[n]["absent"]
                   and row[n]["road"] in inside]
            for n in ins:
                passed[n] = True
            if len(ins) > 1:
                both.append(row)
        return both, passed

    def test_crossing_paths_never_share_the_junction(self):
        both, passed = self.crossing(True)
        self.assertEqual(both, [], "both cars inside junction 100 at once")
        self.assertEqual(passed, {"a": True, "b": True}, "both crossed the junction")

    def test_without_yielding_they_would_meet(self):
        # The scenario is a real conflict: without yielding both are inside at once.
        both, _ = self.crossing(False)
        self.assertTrue(both)


class Example(AgentCase):
    def test_the_example_runs(self):
        import shutil
        src = os.path.join(os.path.dirname(CITY), "..", "vehicle_agents")
        for f in ("simulation_config.json", "lights.py", "neighbours_tf.py"):
            shutil.copy(os.path.join(src, f), self.dir)
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        cfg["SimulationTimeout"] = 45.0
        for fn in cfg["DataPackProcessingFunctions"]:  # shared TFs, relative to the example
            if fn["FileName"].startswith(".."):
                fn["FileName"] = os.path.normpath(os.path.join(src, fn["FileName"]))
        for e in cfg["EngineConfigs"]:
            if e["EngineType"] == "vehicle_agent":
                e["Map"] = CITY
        self.write_config(cfg)
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        last = [line for line in r.stdout.splitlines() if line.startswith("t=")][-1]
        self.assertIn("t= 45.0 s", last)
        # Every car reported, and some have finished their routes by then.
        for i in range(8):
            self.assertIn("car_%d " % i, last)
        self.assertIn("(gone)", last)
