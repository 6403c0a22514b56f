"""The road-user agents' tracks, bit for bit, against a golden recorded before their engines
became thin hosts over src/road_users (issue 26: "same tracks bit for bit").

Two experiments on the city map (experiments/city_traffic/city.xodr):
- Traffic: five vehicle_agents (two meeting at junction 100 with yielding, one with a route
  drawn from its Seed and ReactionTime, one from a StartPose onward, one behind a slow car
  with Respawn, one in the weather) and four pedestrian_agents (crosswalk, drawn route with
  mid-block crossings, StartPose onward, reversed crosswalk with Respawn), among a python_json
  slow car and a python_json lights program switching every signal.
- Commands: a vehicle_agent and a pedestrian_agent under a scripted sequence of scenario
  commands (speed, lane, untimed and timed trajectory, teleport, route) and back to their AI.

A TF records every agent's serialized RoadUser each step; the test compares, per agent, the
SHA-256 of the whole sequence and (to name the first step that differs) an 8-hex-digit hash of
each step with golden/agent_tracks.json. `CONVOY_REGEN_GOLDEN=1` rewrites the golden (only
from code whose tracks are meant to change).
"""

import hashlib
import json
import os
import unittest

from e2e_util import BIN_DIR, E2ETestCase

HERE = os.path.dirname(os.path.abspath(__file__))
GOLDEN = os.path.join(HERE, "golden", "agent_tracks.json")
CITY = os.path.join(os.path.dirname(os.path.dirname(HERE)), "experiments", "city_traffic",
                    "city.xodr")
AGENTS = [os.path.join(BIN_DIR, "convoy-engine-" + t) for t in ("vehicle_agent",
                                                                "pedestrian_agent")]

SLOW = """\
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("state")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        self._setDataPack("state", {"id": "slow", "category": "car", "model": "sedan",
                                    "x": 70.0 + 3.0 * t, "y": -1.75, "yaw": 0.0, "speed": 3.0,
                                    "vx": 3.0, "length": 4.5, "width": 1.8,
                                    "length_offset": 1.35, "time_ns": self._time_ns})
"""

LIGHTS = """\
from nrp_core.engines.python_json import EngineScript


class Script(EngineScript):
    def initialize(self):
        self._registerDataPack("traffic_lights")
        self._publish()

    def runLoop(self, timestep_ns):
        self._publish()

    def _publish(self):
        t = self._time_ns * 1e-9
        phase = int(t // 7.0) % 3
        a = ("green", "yellow", "red")[phase]
        b = ("red", "red_yellow", "green")[phase]
        signals = {str(i): (a if i % 2 else b) for i in range(1, 9)}
        self._setDataPack("traffic_lights", {"time_ns": self._time_ns, "signals": signals})
"""

TF = """\
import json
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks

_out = open({out!r}, "a")
AGENTS = {agents!r}
USERS = {users!r}

{decorators}
@TransceiverFunction({first!r})
def record(**dps):
    row = {{}}
    for n in AGENTS:
        if not dps[n].isEmpty():
            row[n] = dps[n].data.SerializeToString().hex()
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    users = [dps[n] for n in USERS]
    out = neighbour_datapacks(users, agents=AGENTS, radius=100.0)
    first = dps[AGENTS[0]]
    t = first.data.time_ns * 1e-9 if not first.isEmpty() else 0.0
{body}
    return out
"""

TRAFFIC_BODY = """\
    lights = dps["lights"]
    if not lights.isEmpty():
        for n in AGENTS:
            out.append(JsonDataPack("traffic_lights", n, data=lights.data))
    out.append(JsonDataPack("weather", "wet", data={"mu": 0.5, "visibility_m": 300.0}))
    out.append(JsonDataPack("weather", "p_seed",
                            data={"precipitation": 0.6, "precipitation_type": "rain"}))
"""

COMMANDS_BODY = """\
    v, p = {}, {}
    if 2.0 <= t < 4.0:
        v["speed"] = {"speed": 6.0 - (t - 2.0), "acceleration": -1.0}
        p["speed"] = {"speed": 2.0}
    elif 4.0 <= t < 7.0:
        v["lane"] = {"road": "2", "lane": -2, "from_lane": -1, "offset": 0.3,
                     "progress": min(1.0, (t - 4.0) / 2.0)}
        p["trajectory"] = {"polyline": [[40.0, -8.25], [60.0, -8.0], [80.0, -8.25]],
                           "length": 40.0}
    elif 7.0 <= t < 9.0:
        v["trajectory"] = {"polyline": [[60.0, -5.25], [120.0, -5.25], [150.0, -1.75]],
                           "length": 95.0}
        p["route"] = {"positions": [[90.0, -8.25], [110.0, -8.5]]}
    elif 9.0 <= t < 10.0:
        v["trajectory"] = {"x": 100.0 + 8.0 * (t - 9.0), "y": -1.75, "yaw": 0.0, "speed": 8.0}
        p["trajectory"] = {"x": 120.0, "y": -8.25 + 0.5 * (t - 9.0), "yaw": 1.57, "speed": 0.5}
    elif 10.0 <= t < 10.06:
        v["teleport"] = {"x": 60.0, "y": -1.75, "yaw": 0.0, "speed": 8.0}
        p["teleport"] = {"x": 50.0, "y": -8.25, "yaw": 0.0}
    elif 11.0 <= t < 14.0:
        v["route"] = {"positions": [[150.0, -1.75]]}
    out.append(JsonDataPack("command", "veh", data=v))
    out.append(JsonDataPack("command", "ped", data=p))
"""


def vehicle(name, **extra):
    e = {"EngineType": "vehicle_agent", "EngineName": name, "EngineTimestep": 0.05,
         "Map": CITY}
    e.update(extra)
    return e


def pedestrian(name, **extra):
    e = {"EngineType": "pedestrian_agent", "EngineName": name, "EngineTimestep": 0.05,
         "Map": CITY}
    e.update(extra)
    return e


def traffic():
    return [
        vehicle("a", Route={"from": "1:-1", "to": "2:-1"}, StartS=150.0, InitialSpeed=10.0,
                v0=10.0, LaneChanges=False),
        vehicle("b", Route={"from": "5:-1", "to": "4:-1"}, StartS=50.0, InitialSpeed=10.0,
                v0=10.0, LaneChanges=False),
        vehicle("c_seed", Route={}, Seed=3, ReactionTime=0.3, InitialSpeed=8.0),
        vehicle("d_pose", StartPose={"x": 30.0, "y": -1.9, "yaw": 0.05}, Seed=5,
                InitialSpeed=6.0),
        vehicle("e_mobil", Route={"from": "2:-1", "to": "2:-1"}, InitialSpeed=10.0, v0=12.0,
                Respawn=True, RespawnDelay=1.0),
        vehicle("wet", Route={"from": "3:-1", "to": "3:-1"}, InitialSpeed=12.0),
        pedestrian("p_cross", Route={"crosswalk": "2"}),
        pedestrian("p_seed", Route={}, Seed=7, SpeedSd=0.2, CriticalGapSd=0.5,
                   MidBlockProbability=0.5),
        pedestrian("p_pose", StartPose={"x": 40.0, "y": -8.0, "yaw": 0.1}, Seed=2),
        pedestrian("p_back", Route={"crosswalk": "2", "reverse": True}, Respawn=True,
                   RespawnDelay=0.5),
    ]


def commands():
    return [
        vehicle("veh", StartPose={"x": 20.0, "y": -1.75, "yaw": 0.0}, Seed=1, InitialSpeed=6.0),
        pedestrian("ped", StartPose={"x": 25.0, "y": -8.25, "yaw": 0.0}, Seed=4),
    ]


class Tracks(E2ETestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        for a in AGENTS:
            if not os.access(a, os.X_OK):
                raise unittest.SkipTest(os.path.basename(a) + " is not built")

    def record(self, engines, body, timeout, extra=()):
        out = os.path.join(self.dir, "tracks.jsonl")
        agents = [e["EngineName"] for e in engines]
        for name, text in extra:
            self.write(name + ".py", text)
            engines = engines + [{"EngineType": "python_json", "EngineName": name,
                                  "PythonFileName": name + ".py", "EngineTimestep": 0.05}]
        names = [e["EngineName"] for e in engines]
        ids = {n: "traffic_lights" if n == "lights" else "state" for n in names}
        decorators = "\n".join(
            '@EngineDataPack(keyword="%s", id=DataPackIdentifier("%s", "%s"))' % (n, ids[n], n)
            for n in names)
        users = [n for n in names if n != "lights"]
        self.write("tf.py", TF.format(out=out, agents=agents, users=users, first=agents[0],
                                      decorators=decorators, body=body))
        self.write_config({"SimulationName": "tracks", "SimulationTimeout": timeout,
                           "EngineConfigs": engines,
                           "DataPackProcessingFunctions": [{"Name": "record",
                                                            "FileName": "tf.py"}]})
        self.assertExit(self.run_convoy(timeout=240), 0)
        tracks = {n: [] for n in agents}
        with open(out) as f:
            for line in f:
                for n, hexdigest in json.loads(line).items():
                    tracks[n].append(hexdigest)
        return {n: {"steps": len(t),
                    "sha256": hashlib.sha256("".join(t).encode()).hexdigest(),
                    "per_step": [hashlib.sha256(s.encode()).hexdigest()[:8] for s in t]}
                for n, t in tracks.items()}

    def check(self, key, got):
        for n, t in got.items():
            self.assertGreater(t["steps"], 100, n)
        if os.environ.get("CONVOY_REGEN_GOLDEN") == "1":
            golden = {}
            if os.path.exists(GOLDEN):
                with open(GOLDEN) as f:
                    golden = json.load(f)
            golden[key] = got
            with open(GOLDEN, "w") as f:
                json.dump(golden, f, indent=0, sort_keys=True)
                f.write("\n")
            return
        with open(GOLDEN) as f:
            want = json.load(f)[key]
        self.assertEqual(sorted(got), sorted(want))
        for n in sorted(want):
            g, w = got[n], want[n]
            if g["sha256"] == w["sha256"]:
                continue
            first = next((i for i, (a, b) in enumerate(zip(g["per_step"], w["per_step"]))
                          if a != b), min(len(g["per_step"]), len(w["per_step"])))
            self.fail("%s: %s differs from the golden from step %d (of %d, golden %d)"
                      % (key, n, first, g["steps"], w["steps"]))

    def test_traffic(self):
        self.check("traffic", self.record(traffic(), TRAFFIC_BODY, 30.0,
                                          extra=[("slow", SLOW), ("lights", LIGHTS)]))

    def test_commands(self):
        self.check("commands", self.record(commands(), COMMANDS_BODY, 20.0))


if __name__ == "__main__":
    unittest.main()
