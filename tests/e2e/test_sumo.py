"""The sumo engine (SUMO background traffic, libsumo in-process).

Experiments built in each test:
- a straight OpenDRIVE road written here: 200 m along +x from (1000, 500), one lane each way
  (3.5 m), converted by netconvert at initialize (cached in the test's folder); a vehicle
  drives it west to east from t = 0;
- a 3x3 grid with traffic lights made by netgenerate, for the lights.
A TF records each step's RoadUsers (and the lights) to a JSON-lines file.

Skipped when the sumo engine is not built (SUMO not installed).
"""

import json
import os
import subprocess
import unittest
import xml.etree.ElementTree as ET

os.environ.setdefault("SUMO_HOME", "/usr/share/sumo")  # netconvert / netgenerate need it

from e2e_util import BIN_DIR, E2ETestCase

SUMO_ENGINE = os.path.join(BIN_DIR, "convoy-engine-sumo")
EXIT_USER, EXIT_ENGINE = 2, 3
LANE_W = 3.5
X0, Y0, LENGTH = 1000.0, 500.0, 200.0

XODR = """<?xml version="1.0" encoding="UTF-8"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="4" name="straight"/>
  <road name="straight" length="{L}" id="1" junction="-1">
    <link/>
    <planView>
      <geometry s="0" x="{x0}" y="{y0}" hdg="0" length="{L}"><line/></geometry>
    </planView>
    <lanes>
      <laneSection s="0">
        <left><lane id="1" type="driving" level="false"><link/>
          <width sOffset="0" a="{w}" b="0" c="0" d="0"/></lane></left>
        <center><lane id="0" type="none" level="false"><link/></lane></center>
        <right><lane id="-1" type="driving" level="false"><link/>
          <width sOffset="0" a="{w}" b="0" c="0" d="0"/></lane></right>
      </laneSection>
    </lanes>
  </road>
</OpenDRIVE>
""".format(L=LENGTH, x0=X0, y0=Y0, w=LANE_W)

RECORD_TF = """\
import hashlib
import json
from nrp_core import *
from nrp_core.data.nrp_protobuf import RoadUserDataPack

_out = open({out!r}, "a")


@EngineDataPack(keyword="v", id=DataPackIdentifier("vehicles", "sumo"))
@EngineDataPack(keyword="tl", id=DataPackIdentifier("traffic_lights", "sumo"))
@TransceiverFunction("sumo")
def record(v, tl):
    row = {{"users": [], "lights": None}}
    if not v.isEmpty():
        row["t"] = v.data.time_ns
        row["digest"] = hashlib.sha1(v.data.SerializeToString()).hexdigest()  # every field
        row["users"] = [dict(id=u.id, category=u.category, model=u.model, absent=u.absent,
                             x=u.x, y=u.y, yaw=u.yaw, speed=u.speed, length=u.length,
                             length_offset=u.length_offset, lights=u.lights)
                        for u in v.data.users]
    if not tl.isEmpty():
        row["lights"] = tl.data
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    out = []
{extra}
    return out
"""

# An external road user: a stopped car whose rear axle is at x = X0 + 120, in the lane the
# SUMO vehicle drives.
OBSTACLE = """\
    u = RoadUserDataPack("external_road_users", "sumo")
    u.data.id = "ego"
    u.data.category = "car"
    u.data.x, u.data.y, u.data.yaw = {x}, {y}, 0.0
    u.data.length, u.data.width, u.data.length_offset = 4.5, 1.8, 1.35
    out.append(u)
"""

# The same obstacle as the JSON a python_json road user publishes (docs/road_users.md).
OBSTACLE_JSON = """\
    from nrp_core.data.nrp_json import JsonDataPack
    out.append(JsonDataPack("external_road_users", "sumo", {{"users": [
        {{"id": "ego", "category": "car", "x": {x}, "y": {y}, "yaw": 0.0, "length": 4.5,
          "width": 1.8, "length_offset": 1.35}}]}}))
"""

LIGHTS = """\
    from nrp_core.data.nrp_json import JsonDataPack
    out.append(JsonDataPack("traffic_lights_in", "sumo", {{"lights": {{{tls!r}: {state!r}}}}}))
"""


class SumoCase(E2ETestCase):
    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(SUMO_ENGINE, os.X_OK):
            raise unittest.SkipTest("the sumo engine is not built (SUMO not found: "
                                    "apt-get install sumo sumo-tools, then reconfigure)")

    def straight_road(self):
        """The .xodr, and the SUMO edge ids of its eastbound and westbound lanes."""
        xodr = self.write("straight.xodr", XODR)
        net = os.path.join(self.dir, "probe.net.xml")
        subprocess.run(["netconvert", "--opendrive-files", xodr, "-o", net], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        edges = [e for e in ET.parse(net).getroot().iter("edge")
                 if e.get("function") != "internal"]
        east = [e.get("id") for e in edges if e.get("from", "").endswith(".begin")]
        self.assertEqual(len(east), 1, [e.get("id") for e in edges])
        return xodr, east[0]

    def experiment(self, timeout=20.0, extra_tf="", sumo=None, routes=None):
        out = os.path.join(self.dir, "stream.jsonl")
        self.write("tf.py", RECORD_TF.format(out=out, extra=extra_tf))
        if sumo is None:
            xodr, east = self.straight_road()
            self.write("routes.rou.xml", routes or (
                '<routes><vType id="sedan" vClass="passenger" length="4.5"/>'
                '<vehicle id="v0" type="sedan" depart="0" departSpeed="max">'
                '<route edges="%s"/></vehicle></routes>' % east))
            sumo = {"OpenDriveFile": "straight.xodr", "NetCacheDir": "netcache",
                    "RouteFiles": ["routes.rou.xml"]}
        engine = {"EngineType": "sumo", "EngineName": "sumo", "EngineTimestep": 0.1}
        engine.update(sumo)
        self.write_config({"SimulationName": "sumo", "SimulationTimeout": timeout,
                           "EngineConfigs": [engine],
                           "DataPackProcessingFunctions": [{"Name": "record", "FileName": "tf.py"}]})
        return out

    def stream(self, path):
        with open(path) as f:
            return [json.loads(line) for line in f]


class Poses(SumoCase):
    def test_vehicle_on_the_xodr_lane_in_the_map_frame(self):
        out = self.experiment(timeout=12.0)
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if row["users"]]
        self.assertGreater(len(rows), 50)
        xs = []
        for row in rows:
            (u,) = row["users"]
            self.assertEqual(u["id"], "sumo/v0")
            self.assertEqual((u["category"], u["model"]), ("car", "sedan"))
            self.assertFalse(u["absent"])
            # Right-hand traffic: the eastbound lane's centre is half a lane right of the
            # reference line (y = Y0), in the .xodr's frame (netconvert's offset undone).
            self.assertAlmostEqual(u["y"], Y0 - LANE_W / 2, delta=0.05)
            self.assertAlmostEqual(u["yaw"], 0.0, delta=1e-3)
            self.assertGreaterEqual(u["x"], X0 - 4.5)
            self.assertLessEqual(u["x"], X0 + LENGTH)
            self.assertAlmostEqual(u["length_offset"], 4.5 * 0.25)
            xs.append(u["x"])
        self.assertEqual(xs, sorted(xs))
        self.assertGreater(xs[-1] - xs[0], 50)
        # The converted network is cached by the .xodr's content.
        self.assertEqual(len([f for f in os.listdir(os.path.join(self.dir, "netcache"))
                              if f.endswith(".net.xml")]), 1)

    def test_vehicle_that_left_is_absent_once(self):
        out = self.experiment(timeout=25.0)
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = self.stream(out)
        absent = [i for i, row in enumerate(rows) for u in row["users"] if u["absent"]]
        self.assertEqual(len(absent), 1, "the vehicle reached the road's end: absent once")
        self.assertTrue(all(not row["users"] for row in rows[absent[0] + 1:]))


class Determinism(SumoCase):
    def test_two_runs_give_the_same_stream(self):
        routes = ('<routes><flow id="f" begin="0" end="30" period="1.5" departSpeed="random" '
                  'departLane="random" from="%s" to="%s"/></routes>')
        streams = []
        for i in range(2):
            xodr, east = self.straight_road()
            out = self.experiment(timeout=15.0, routes=routes % (east, east))
            r = self.run_convoy()
            self.assertExit(r, 0)
            streams.append(self.stream(out))
            os.remove(out)
        self.assertGreater(max(len(row["users"]) for row in streams[0]), 3)
        self.assertEqual(streams[0], streams[1])


class ExternalRoadUsers(SumoCase):
    def test_sumo_vehicle_stops_behind_an_external_car(self, obstacle=OBSTACLE):
        stop_x = X0 + 120
        out = self.experiment(timeout=25.0, extra_tf=obstacle.format(x=stop_x, y=Y0 - LANE_W / 2))
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = [row for row in self.stream(out) if row["users"]]
        ids = {u["id"] for row in rows for u in row["users"]}
        self.assertEqual(ids, {"sumo/v0"}, "external road users are not published back")
        last = rows[-1]["users"][0]
        self.assertFalse(last["absent"])
        # Stopped behind the obstacle's rear bumper (rear axle + offset - half length).
        obstacle_rear = stop_x + 1.35 - 2.25
        front = last["x"] + 4.5 * 0.75
        self.assertLess(front, obstacle_rear)
        self.assertGreater(front, obstacle_rear - 15)
        self.assertLess(last["speed"], 0.1)
        self.assertTrue(last["lights"] & 2 or last["speed"] == 0.0)

    def test_external_car_as_json(self):
        self.test_sumo_vehicle_stops_behind_an_external_car(OBSTACLE_JSON)

    def test_external_car_off_the_network_is_warned_and_left_out(self):
        out = self.experiment(timeout=25.0, extra_tf=OBSTACLE.format(x=X0 + 50, y=Y0 + 900))
        r = self.run_convoy()
        self.assertExit(r, 0)
        log = self.read_log("sumo")  # a warning after Initialize goes to the engine's log
        self.assertRegex(log, r"warning: sumo engine 'sumo': external road user 'ego' cannot be put")
        self.assertEqual(log.count("cannot be put into SUMO"), 1, "warned once")
        # Nothing of it stays in SUMO: the SUMO vehicle drives the whole road.
        xs = [u["x"] for row in self.stream(out) for u in row["users"]]
        self.assertGreater(max(xs), X0 + 125)

    def test_without_the_external_car_it_drives_past(self):
        out = self.experiment(timeout=25.0)
        r = self.run_convoy()
        self.assertExit(r, 0)
        xs = [u["x"] for row in self.stream(out) for u in row["users"]]
        self.assertGreater(max(xs), X0 + 125)


class TrafficLights(SumoCase):
    def grid(self, leader, extra_tf=""):
        net = os.path.join(self.dir, "grid.net.xml")
        subprocess.run(["netgenerate", "--grid", "--grid.number=3", "--grid.length=100",
                        "--default-junction-type", "traffic_light", "--tls.green.time", "5", "-o", net], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tls = sorted(t.get("id") for t in ET.parse(net).getroot().iter("tlLogic"))
        self.assertTrue(tls)
        return self.experiment(timeout=40.0, extra_tf=extra_tf,
                               sumo={"NetFile": "grid.net.xml", "TrafficLightsLeader": leader}), tls

    def test_sumo_leads(self):
        out, tls = self.grid("sumo")
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = self.stream(out)
        lights = [row["lights"] for row in rows if row["lights"]]
        self.assertEqual(sorted(lights[-1]["lights"]), tls)
        self.assertEqual(lights[-1]["leader"], "sumo")
        states = {l["lights"][tls[0]]["state"] for l in lights}
        self.assertGreater(len(states), 1, "SUMO's program changes the lights")
        first = lights[-1]["lights"][tls[0]]
        self.assertEqual(len(first["state"]), 1 + max(link["index"] for link in first["links"]))

    def test_external_leads(self):
        net = os.path.join(self.dir, "grid.net.xml")
        subprocess.run(["netgenerate", "--grid", "--grid.number=3", "--grid.length=100",
                        "--default-junction-type", "traffic_light", "--tls.green.time", "5", "-o", net], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        logic = next(ET.parse(net).getroot().iter("tlLogic"))
        n = len(next(logic.iter("phase")).get("state"))
        forced = "r" * (n - 1) + "G"
        out, tls = self.grid("external", LIGHTS.format(tls=logic.get("id"), state=forced))
        r = self.run_convoy()
        self.assertExit(r, 0)
        lights = [row["lights"] for row in self.stream(out) if row["lights"]]
        self.assertEqual(lights[-1]["leader"], "external")
        # From the step after the first TF output on, SUMO shows the state it was given.
        held = [l["lights"][logic.get("id")]["state"] for l in lights[2:]]
        self.assertEqual(set(held), {forced})

    def test_unknown_light_is_an_error(self):
        out, tls = self.grid("external", LIGHTS.format(tls="no_such_tls", state="rG"))
        r = self.run_convoy()
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "sumo", "no_such_tls", "traffic_lights_in")
        self.assertOneError(r)
        self.assertNoEngineLeft()


PERSONS_TF = """\
import json
from nrp_core import *

_out = open({out!r}, "a")


@EngineDataPack(keyword="p", id=DataPackIdentifier("persons", "sumo"))
@TransceiverFunction("sumo")
def record(p):
    if not p.isEmpty():
        _out.write(json.dumps({{"t": p.data.time_ns, "users": [
            dict(id=u.id, category=u.category, model=u.model, absent=u.absent, x=u.x, y=u.y,
                 yaw=u.yaw, speed=u.speed, length=u.length, width=u.width)
            for u in p.data.users]}}) + "\\n")
        _out.flush()
    return []
"""


class Persons(SumoCase):
    """SUMO's persons as pedestrians (PersonsDataPack, sumo_persons.h): a person walks two
    edges of a grid with sidewalks and leaves."""

    def test_a_walker_is_a_pedestrian_that_moves_then_leaves_once(self):
        net = os.path.join(self.dir, "grid.net.xml")
        subprocess.run(["netgenerate", "--grid", "--grid.number=2", "--grid.length=40",
                        "--sidewalks.guess", "-o", net], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        edges = [e.get("id") for e in ET.parse(net).getroot().iter("edge")
                 if e.get("function") != "internal"]
        self.assertIn("A0A1", edges)
        self.write("walk.rou.xml", '<routes><vType id="walker" vClass="pedestrian" '
                   'width="0.5" length="0.3"/><person id="p0" type="walker" depart="0">'
                   '<walk edges="A0A1" speed="1.2"/></person></routes>')
        out = os.path.join(self.dir, "persons.jsonl")
        self.write("tf.py", PERSONS_TF.format(out=out))
        self.write_config({"SimulationName": "persons", "SimulationTimeout": 45.0,
                           "EngineConfigs": [{"EngineType": "sumo", "EngineName": "sumo",
                                              "EngineTimestep": 0.5, "NetFile": "grid.net.xml",
                                              "RouteFiles": ["walk.rou.xml"]}],
                           "DataPackProcessingFunctions": [{"Name": "record",
                                                            "FileName": "tf.py"}]})
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = self.stream(out)
        seen = [u for row in rows for u in row["users"] if not u["absent"]]
        self.assertGreater(len(seen), 20)
        first = seen[0]
        self.assertEqual((first["id"], first["category"], first["model"]),
                         ("sumo/p0", "pedestrian", "walker"))
        self.assertAlmostEqual(first["width"], 0.5)
        walking = [u for u in seen if u["speed"] > 0.5]
        self.assertTrue(walking)
        self.assertAlmostEqual(max(u["speed"] for u in walking), 1.2, delta=0.05)
        ys = [u["y"] for u in walking]  # A0A1 runs north
        self.assertGreater(ys[-1] - ys[0], 10)
        self.assertEqual(ys, sorted(ys))
        gone = [u for row in rows for u in row["users"] if u["absent"]]
        self.assertEqual(len(gone), 1)  # once, after it arrived
        self.assertEqual(rows[-1]["users"], [])


class BadInput(SumoCase):
    def test_missing_net_file(self):
        self.experiment(sumo={"NetFile": "nowhere.net.xml"})
        r = self.run_convoy()
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "NetFile", "nowhere.net.xml")
        self.assertOneError(r)
        self.assertNoEngineLeft()

    def test_bad_route_file(self):
        self.experiment()
        self.write("routes.rou.xml", "<routes><vehicle id='v' depart='0'><route edges='nope'/>"
                                     "</vehicle></routes>")
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "sumo", "RouteFiles", "nope")
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertLogsKept("sumo")

    def test_bad_xodr(self):
        self.experiment()
        self.write("straight.xodr", "<OpenDRIVE><road")
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "sumo", "OpenDriveFile", "straight.xodr")
        self.assertOneError(r)
        self.assertNoEngineLeft()

    def test_bad_sumo_option(self):
        self.experiment(sumo={"NetFile": "n.net.xml", "SumoOptions": ["--no-such-option", "1"]})
        subprocess.run(["netgenerate", "--grid", "--grid.number=2", "-o",
                        os.path.join(self.dir, "n.net.xml")], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "sumo", "SumoOptions", "no-such-option")
        self.assertOneError(r)
        self.assertNoEngineLeft()

    def test_unknown_key_warns_by_name(self):
        self.experiment(timeout=0.5)
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        cfg["EngineConfigs"][0]["RoutFiles"] = ["x"]
        self.write_config(cfg)
        r = self.run_convoy()
        self.assertExit(r, 0)
        self.assertRegex(r.stderr, r"(?i)warning.*RoutFiles")

    def test_neither_net_nor_xodr(self):
        self.experiment(sumo={})
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        for k in ("OpenDriveFile", "RouteFiles", "NetCacheDir"):
            cfg["EngineConfigs"][0].pop(k, None)
        self.write_config(cfg)
        r = self.run_convoy()
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "sumo", "NetFile", "OpenDriveFile")
        self.assertOneError(r)
        self.assertNoEngineLeft()


if __name__ == "__main__":
    unittest.main()
