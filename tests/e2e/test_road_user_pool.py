"""The road_user_pool engine (issue 26's pooled host): N vehicles in one engine process.

Runs: a pool of spawned and listed vehicles on tests/traffic_pool/data/grid3.xodr publishes one
convoy.data.RoadUsers datapack with every vehicle each step, which a TF reads; on the city map
its walkers (Pedestrians) come after the vehicles, category pedestrian, model walker.
Commands: a TF sends the pool scenario commands (CommandDataPack, the agents' contract): a
speed command holds a vehicle's speed, a teleport puts it at a pose, then IDM takes over; an
unknown id stops the run (exit 3).
TrafficLightsEngine: the traffic_lights engine's datapack, passed to the pool by a TF
(TrafficLightsDataPack), holds the main road of junction 100 (signals 1 and 2) red for the whole
run: no pooled vehicle leaves road 1's approach into the junction while some queue there; with
that road green they do leave it; a datapack without "signals", or with a state that is not a
string, stops the run (exit 3) naming the engine, the datapack and the signal.
BadInput: an unknown policy, two road users on one spot, a count the map cannot hold, a
destination with no path, and pedestrians the sidewalks cannot hold (Pedestrians,
PedestrianDensity) each stop the run with one message naming the road user or key and the
capacity, and leave no engine process behind.
"""

import json
import math
import os
import textwrap
import unittest

from e2e_util import REPO, E2ETestCase

GRID = os.path.join(REPO, "tests", "traffic_pool", "data", "grid3.xodr")
CITY = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")

TF = textwrap.dedent("""\
    import json
    from nrp_core import *

    _seen = {"steps": 0}


    @EngineDataPack(keyword="v", id=DataPackIdentifier("road_users", "pool"))
    @TransceiverFunction("pool")
    def count(v):
        if v.isEmpty():
            return []
        users = v.data.users
        _seen["steps"] += 1
        _seen["n"] = len(users)
        _seen["ids"] = len(set(u.id for u in users))
        _seen["mine"] = [[u.x, u.y, u.speed, u.road, u.lane] for u in users if u.id == "pool/mine"]
        _seen["moving"] = sum(1 for u in users if u.speed > 0.5)
        _seen["walkers"] = [[u.id, u.model, u.walk_phase, u.speed] for u in users
                            if u.category == "pedestrian"]
        with open(OUT, "w") as f:
            json.dump(_seen, f)
        return []
    """)


def pool_config(**engine):
    e = {"EngineType": "road_user_pool", "EngineName": "pool", "EngineTimestep": 0.05,
         "Map": GRID}
    e.update(engine)
    return {"SimulationName": "pool", "SimulationTimeout": 3.0, "EngineConfigs": [e]}


class Runs(E2ETestCase):
    def seen(self, **engine):
        """What the TF saw of a run of the pool configured with `engine`."""
        out = os.path.join(self.dir, "seen.json")
        self.write("tf.py", TF.replace("OUT", repr(out)))
        cfg = pool_config(**engine)
        cfg["DataPackProcessingFunctions"] = [{"Name": "count", "FileName": "tf.py"}]
        self.write_config(cfg)
        r = self.run_convoy()
        self.assertExit(r, 0)
        with open(out) as f:
            return json.load(f)

    def test_pool_publishes_every_vehicle(self):
        seen = self.seen(Count=40, Seed=3,
                         Vehicles=[{"Id": "mine", "Road": "90", "Lane": -1, "S": 20,
                                    "Speed": 5, "Policy": "idm"}])
        self.assertGreaterEqual(seen["steps"], 50)
        self.assertEqual(seen["n"], 41)
        self.assertEqual(seen["ids"], 41)
        self.assertEqual(len(seen["mine"]), 1)
        self.assertGreater(seen["moving"], 10)
        self.assertNoEngineLeft()


    def test_pool_publishes_its_walkers(self):
        seen = self.seen(Map=CITY, Count=20, Pedestrians=30, Seed=2)
        self.assertEqual(seen["n"], 50)
        walkers = seen["walkers"]
        self.assertEqual(len(walkers), 30)
        self.assertEqual(walkers[0][0], "pool/walker/0")
        self.assertEqual({w[1] for w in walkers}, {"walker"})
        self.assertTrue(all(0 <= w[2] < 1 for w in walkers))
        self.assertGreater(sum(1 for w in walkers if w[3] > 1.0), 10)  # walking, 1.2-1.5 m/s
        self.assertNoEngineLeft()


# The head of the command TFs: `me` is the pool's road user `mine`; each TF adds the rest.
COMMAND_TF_HEAD = """\
    import json, math
    from nrp_core import *
    from nrp_core.data.nrp_json import JsonDataPack

    _rows = []
    _line = []


    @EngineDataPack(keyword="v", id=DataPackIdentifier("road_users", "pool"))
    @TransceiverFunction("pool")
    def command(v):
        if v.isEmpty():
            return []
        me = {u.id: u for u in v.data.users}["pool/mine"]
"""

COMMAND_TF = textwrap.dedent(COMMAND_TF_HEAD + """\
        _rows.append([v.data.time_ns, me.speed, me.acceleration, me.lights, me.x, me.y])
        with open(OUT, "w") as f:
            json.dump(_rows, f)
        t = v.data.time_ns * 1e-9
        if t < 1.0:
            return [JsonDataPack("commands", "pool",
                                 {KEY: {"speed": {"speed": 2.0, "acceleration": -1.5}}})]
        if t < 1.04:
            return [JsonDataPack("commands", "pool",
                                 {"mine": {"teleport": {"x": 160.0, "y": 48.4, "yaw": 0.0}}})]
        return []
    """)


POLYLINE_TF = textwrap.dedent(COMMAND_TF_HEAD + """\
        if not _line:  # a line from where it stands, 1.5 m to its left from 10 m on
            c, s = math.cos(me.yaw), math.sin(me.yaw)
            _line.extend([[me.x + d * c - 1.5 * s * (d >= 10), me.y + d * s + 1.5 * c * (d >= 10)]
                          for d in (0.0, 5.0, 10.0, 20.0, 40.0, 60.0)])
        _rows.append([v.data.time_ns, me.x, me.y, me.speed])
        with open(OUT, "w") as f:
            json.dump({"line": _line, "rows": _rows}, f)
        return [JsonDataPack("commands", "pool",
                             {"mine": {"trajectory": {"polyline": _line}}})]
    """)


def distance_to_polyline(p, line):
    best = float("inf")
    for (ax, ay), (bx, by) in zip(line, line[1:]):
        dx, dy = bx - ax, by - ay
        t = max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy)))
        best = min(best, math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy))
    return best


class Commands(E2ETestCase):
    """A TF plays the scenario engine: `mine` is held at 2 m/s (BRAKE on, its acceleration
    published), then teleported (its published reference point exactly there), then back on
    IDM; the same commands give the same run; an unknown id stops the run (exit 3)."""

    def run_commands(self, key, tf=COMMAND_TF):
        """The pool with `mine` on road 90 and the command TF `tf`; its exit and what it wrote."""
        out = os.path.join(self.dir, "rows.json")
        self.write("tf.py", tf.replace("OUT", repr(out)).replace("KEY", repr(key)))
        cfg = pool_config(Count=10, Seed=3,
                          Vehicles=[{"Id": "mine", "Road": "90", "Lane": -1, "S": 20,
                                     "Speed": 8, "Policy": "idm"}])
        cfg["DataPackProcessingFunctions"] = [{"Name": "command", "FileName": "tf.py"}]
        self.write_config(cfg)
        r = self.run_convoy()
        if not os.path.exists(out):
            return r, []
        with open(out) as f:
            return r, json.load(f)

    def test_speed_teleport_and_back_to_idm(self):
        r, rows = self.run_commands("pool/mine")
        self.assertExit(r, 0)
        held = [row for row in rows if 0.1 < row[0] * 1e-9 <= 1.0]
        self.assertGreater(len(held), 15)
        for _, speed, acc, lights, _, _ in held:
            self.assertAlmostEqual(speed, 2.0, places=9)
            self.assertAlmostEqual(acc, -1.5, places=9)
            self.assertTrue(lights & 2)  # BRAKE
        put = [row for row in rows if 1.0 < row[0] * 1e-9 < 1.06]
        self.assertAlmostEqual(put[0][4], 160.0, places=6)
        self.assertAlmostEqual(put[0][5], 48.4, places=6)
        after = [row for row in rows if row[0] * 1e-9 > 1.2]
        self.assertGreater(after[-1][1], 2.5)  # IDM speeds it up again
        _, r2 = self.run_commands("pool/mine")
        self.assertEqual(rows, r2)  # same commands, same run
        self.assertNoEngineLeft()

    def test_untimed_trajectory(self):
        """An untimed trajectory through the engine: `mine` follows a polyline that shifts
        1.5 m to its left, and keeps to it."""
        r, seen = self.run_commands("pool/mine", POLYLINE_TF)
        self.assertExit(r, 0)
        line, rows = seen["line"], seen["rows"]
        self.assertGreater(len(rows), 40)
        late = [row for row in rows if row[0] * 1e-9 > 2.0]
        for _, x, y, _ in late:
            self.assertLess(distance_to_polyline((x, y), line), 0.5)
        start, end = rows[0], rows[-1]
        self.assertGreater(math.hypot(end[1] - start[1], end[2] - start[2]), 15.0)
        self.assertNoEngineLeft()

    def test_unknown_id(self):
        r, _ = self.run_commands("nobody")
        self.assertExit(r, 3)  # bad content, as for the agents
        self.assertOneError(r)
        self.assertStderrHas(r, "road_user_pool engine 'pool': datapack 'commands': no road "
                                "user 'nobody' in the pool")
        self.assertNoEngineLeft()


LIGHTS_TF = textwrap.dedent("""\
    import json
    from nrp_core import *
    from nrp_core.data.nrp_json import JsonDataPack

    _out = open(OUT, "w")


    @EngineDataPack(keyword="lights", id=DataPackIdentifier("traffic_lights", "lights"))
    @EngineDataPack(keyword="v", id=DataPackIdentifier("road_users", "pool"))
    @TransceiverFunction("pool")
    def lights_to_pool(v, lights):
        if not v.isEmpty():
            _out.write(json.dumps([[u.id, u.road, u.lane, u.speed] for u in v.data.users]) + "\\n")
            _out.flush()
        if lights.isEmpty():
            return []
        return [JsonDataPack("traffic_lights", "pool", SEND)]
    """)


def junction_roads(xodr):
    """Ids of the roads inside junctions."""
    import xml.etree.ElementTree as ET
    return {r.get("id") for r in ET.parse(xodr).getroot().findall("road")
            if r.get("junction") not in (None, "-1")}


class TrafficLightsEngine(E2ETestCase):
    """A pool on the city map obeying the traffic_lights engine (its program for junction 100:
    `green` controllers green, the others red, for the whole run)."""

    def run_lights(self, green, send="lights.data", seconds=30.0):
        out = os.path.join(self.dir, "rows.jsonl")
        self.write("tf.py", LIGHTS_TF.replace("OUT", repr(out)).replace("SEND", send))
        cfg = pool_config(Map=CITY, Count=60, Seed=4, TrafficLightsDataPack="traffic_lights")
        cfg["SimulationTimeout"] = seconds
        cfg["EngineConfigs"].append(
            {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": 0.05,
             "Map": CITY, "Programs": {"100": [{"Duration": 1000.0, "Green": green}]}})
        cfg["DataPackProcessingFunctions"] = [{"Name": "lights_to_pool", "FileName": "tf.py"}]
        self.write_config(cfg)
        r = self.run_convoy()
        rows = []
        if os.path.exists(out):
            with open(out) as f:
                rows = [json.loads(line) for line in f]
        return r, rows

    def left_road_1(self, rows):
        """How many times a pooled vehicle went from road 1's lanes -1/-2 (signals 1 and 2's
        approach into junction 100) into the junction, and the most standing there at once
        after 10 s."""
        inside = junction_roads(CITY)
        last, left, queued = {}, 0, 0
        for k, users in enumerate(rows):
            standing = 0
            for uid, road, lane, speed in users:
                was = last.get(uid)
                if was and was[0] == "1" and was[1] in (-1, -2) and road in inside:
                    left += 1
                if road == "1" and lane in (-1, -2) and speed < 0.1:
                    standing += 1
                last[uid] = (road, lane)
            if k >= 200:
                queued = max(queued, standing)
        return left, queued

    def test_red_approach_holds_its_vehicles(self):
        r, rows = self.run_lights(["1002"])  # the side roads green, the main road red
        self.assertExit(r, 0)
        self.assertGreater(len(rows), 550)
        left, queued = self.left_road_1(rows)
        self.assertEqual(left, 0)
        self.assertGreaterEqual(queued, 2)
        r, rows = self.run_lights(["1001"])  # the main road green: they leave it
        self.assertExit(r, 0)
        left, _ = self.left_road_1(rows)
        self.assertGreater(left, 0)
        self.assertNoEngineLeft()

    def bad_lights(self, send, *needles):
        r, _ = self.run_lights(["1001"], send=send, seconds=2.0)
        self.assertExit(r, 3)  # bad content, as for the agents
        self.assertOneError(r)
        self.assertStderrHas(r, "road_user_pool engine 'pool': datapack 'traffic_lights'", *needles)
        self.assertNoEngineLeft()

    def test_state_that_is_not_a_string(self):
        self.bad_lights('{"signals": {"1": 5}}', 'signals.1: expected "red", "yellow", "green", '
                        '"red_yellow" or "off", got 5')

    def test_no_signals(self):
        self.bad_lights('{"lights": {}}', 'expected {"signals": {"<signal id>": state}}')


class BadInput(E2ETestCase):
    def bad(self, *needles, **engine):
        self.write_config(pool_config(**engine))
        r = self.run_convoy()
        self.assertExit(r, 2)  # the user's input: UserError in the engine
        self.assertOneError(r)
        self.assertStderrHas(r, "road_user_pool engine 'pool'", *needles)
        self.assertNoEngineLeft()

    def test_unknown_policy(self):
        self.bad("road user 'v1': unknown policy 'teleport'",
                 Vehicles=[{"Id": "v1", "Road": "90", "Lane": -1, "S": 20,
                            "Policy": "teleport"}])

    def test_two_on_one_spot(self):
        self.bad("road user 'a' and road user 'b' are on one spot",
                 Vehicles=[{"Id": "a", "Road": "90", "Lane": -1, "S": 20},
                           {"Id": "b", "Road": "90", "Lane": -1, "S": 21}])

    def test_count_that_cannot_fit(self):
        self.bad("a count of 5000 cannot fit the network", Count=5000)

    def test_pedestrians_that_cannot_fit(self):
        self.bad("road user 'walker/", "a count of 100000 pedestrians cannot fit the map",
                 "km of sidewalk hold at most", Map=CITY, Pedestrians=100000)

    def test_pedestrian_density_that_cannot_fit(self):
        self.bad("PedestrianDensity 1000 pedestrians/km cannot fit the map", "city.xodr",
                 "km of sidewalk, which hold at most", Map=CITY, PedestrianDensity=1000)

    def test_route_with_no_path(self):
        self.bad("road user 'bus': no path from road '90' lane -1 to road 'nowhere' lane -1",
                 Vehicles=[{"Id": "bus", "Road": "90", "Lane": -1, "S": 20,
                            "To": {"Road": "nowhere", "Lane": -1}}])


if __name__ == "__main__":
    unittest.main()
