"""The traffic_lights engine (signal phases per junction of an OpenDRIVE map).

Runs experiments/city_traffic/city.xodr (junctions 100 and 200; controllers 1001 (main road,
signals 1, 2) and 1002 (side road, signals 3, 4) at junction 100; 2001 (5, 6) and 2002 (7, 8) at
junction 200). A TF records each step's traffic_lights datapack to a JSON-lines file.
"""

import json
import os
import shutil
import unittest

from e2e_util import BIN_DIR, E2ETestCase

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CITY = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")
EXIT_ENGINE = 3
CONTROLLERS = {"100": {"1001": ["1", "2"], "1002": ["3", "4"]},
               "200": {"2001": ["5", "6"], "2002": ["7", "8"]}}

RECORD_TF = """\
import json
from nrp_core import *

_out = open({out!r}, "a")


@EngineDataPack(keyword="tl", id=DataPackIdentifier("traffic_lights", "lights"))
@TransceiverFunction("lights")
def record(tl):
    if not tl.isEmpty():
        _out.write(json.dumps(tl.data, sort_keys=True) + "\\n")
        _out.flush()
    return []
"""


class TrafficLightsCase(E2ETestCase):
    def experiment(self, timeout=30.0, **lights):
        shutil.copy(CITY, os.path.join(self.dir, "city.xodr"))
        out = os.path.join(self.dir, "lights.jsonl")
        self.write("tf.py", RECORD_TF.format(out=out))
        engine = {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": 0.5,
                  "Map": "city.xodr"}
        engine.update(lights)
        self.write_config({"SimulationName": "lights", "SimulationTimeout": timeout,
                           "EngineConfigs": [engine],
                           "DataPackProcessingFunctions": [{"Name": "record", "FileName": "tf.py"}]})
        return out

    def rows(self, path):
        with open(path) as f:
            return [json.loads(line) for line in f]

    def run_ok(self, out):
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = self.rows(out)
        self.assertGreater(len(rows), 10)
        return rows


class Phases(TrafficLightsCase):
    def test_cycle_follows_durations(self):
        out = self.experiment(timeout=30.0, Green=4.0, Yellow=1.0, AllRed=1.0,
                              Junctions={"200": {"Offset": 3.0, "Green": 2.0}})
        rows = self.run_ok(out)
        self.assertEqual(sorted(rows[0]["signals"]), sorted(str(i) for i in range(1, 9)))
        seen = set()
        for row in rows:
            t = row["time_ns"] / 1e9
            for junction, ctrls in CONTROLLERS.items():
                g, y, r = (2.0, 1.0, 1.0) if junction == "200" else (4.0, 1.0, 1.0)
                off = 3.0 if junction == "200" else 0.0
                turn = g + y + r
                pos = (t - off) % (2 * turn)
                k, within = int(pos // turn), pos % turn
                want = "green" if within < g else "yellow" if within < g + y else "red"
                for i, (cid, sigs) in enumerate(sorted(ctrls.items())):
                    for s in sigs:
                        expect = want if i == k else "red"
                        self.assertEqual(row["signals"][s], expect, (t, junction, s))
                        seen.add((s, expect))
                # No two conflicting controllers green (or yellow) at once.
                active = [cid for cid, sigs in ctrls.items()
                          if row["signals"][sigs[0]] != "red"]
                self.assertLessEqual(len(active), 1, (t, junction))
                ph = row["junctions"][junction]
                self.assertGreater(ph["remaining_s"], 0)
        for s in ("1", "3", "5", "7"):
            for state in ("green", "yellow", "red"):
                self.assertIn((s, state), seen)

    def test_explicit_program(self):
        out = self.experiment(timeout=10.0, Programs={"100": [
            {"Duration": 2.0, "Green": ["1001", "1002"]},  # a deliberately odd program
            {"Duration": 3.0, "RedYellow": ["1002"]}]})
        rows = self.run_ok(out)
        for row in rows:
            t = row["time_ns"] / 1e9
            if t % 5.0 < 2.0:
                self.assertEqual([row["signals"][s] for s in "13"], ["green", "green"], t)
            else:
                self.assertEqual([row["signals"][s] for s in "13"], ["red", "red_yellow"], t)

    def test_determinism(self):
        out = self.experiment(timeout=20.0, Green=3.0)
        first = self.run_ok(out)
        os.remove(out)
        second = self.run_ok(out)
        self.assertEqual(first, second)


SUMO_ENGINE = os.path.join(BIN_DIR, "convoy-engine-sumo")

SYNC_TF = """\
import json
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack

_out = open({out!r}, "a")


@EngineDataPack(keyword="tl", id=DataPackIdentifier("traffic_lights", "lights"))
@EngineDataPack(keyword="tin", id=DataPackIdentifier("traffic_lights_in", "lights"))
@EngineDataPack(keyword="st", id=DataPackIdentifier("traffic_lights", "sumo"))
@TransceiverFunction("lights")
def sync(tl, tin, st):
    row = {{}}
    if not tl.isEmpty():
        row["lights"] = tl.data
    if not st.isEmpty():
        row["sumo"] = st.data
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    out = []
    if not st.isEmpty():
        out.append(JsonDataPack("sumo_traffic_lights", "lights", st.data))
    if not tin.isEmpty():
        out.append(JsonDataPack("traffic_lights_in", "sumo", tin.data))
    return out
"""


class Sumo(TrafficLightsCase):
    """Both directions of the SUMO sync, end to end with the sumo engine on city.xodr."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(SUMO_ENGINE, os.X_OK):
            raise unittest.SkipTest("the sumo engine is not built (SUMO not found)")

    def sync(self, leader, timeout=40.0):
        shutil.copy(CITY, os.path.join(self.dir, "city.xodr"))
        out = os.path.join(self.dir, "sync.jsonl")
        self.write("tf.py", SYNC_TF.format(out=out))
        self.write_config({
            "SimulationName": "sync", "SimulationTimeout": timeout,
            "EngineConfigs": [
                {"EngineType": "traffic_lights", "EngineName": "lights", "EngineTimestep": 0.5,
                 "Map": "city.xodr", "Leader": leader, "Green": 6.0, "Yellow": 2.0,
                 "AllRed": 1.0},
                {"EngineType": "sumo", "EngineName": "sumo", "EngineTimestep": 0.5,
                 "OpenDriveFile": "city.xodr", "NetCacheDir": "netcache",
                 "TrafficLightsLeader": "external" if leader == "self" else "sumo"}],
            "DataPackProcessingFunctions": [{"Name": "sync", "FileName": "tf.py"}]})
        r = self.run_convoy()
        self.assertExit(r, 0)
        rows = self.rows(out)
        self.assertGreater(len(rows), 50)
        return rows

    @staticmethod
    def link_state(sumo, tls, from_edge):
        light = sumo["lights"][tls]
        idx = sorted({l["index"] for l in light["links"]
                      if l["from"].rsplit("_", 1)[0] == from_edge})
        return {light["state"][i] for i in idx}

    def test_self_leads_sumo(self):
        rows = self.sync("self")
        char = {"green": "G", "yellow": "y", "red": "r"}
        seen, matched = set(), 0
        # Edge "-1" is road 1 along s into junction 100 (signal 1); "4" road 4 against s
        # (signal 3). SUMO's state at a step follows the lights sent one or two steps before.
        for k, row in enumerate(rows):
            if "sumo" not in row or k < 3:
                continue
            for edge, sig in (("-1", "1"), ("4", "3")):
                states = self.link_state(row["sumo"], "100", edge)
                self.assertEqual(len(states), 1, (row["sumo"]["time_ns"], edge, states))
                recent = {char[rows[j]["lights"]["signals"][sig]] for j in range(k - 2, k + 1)}
                self.assertIn(next(iter(states)), recent, (row["sumo"]["time_ns"], edge))
                seen.add(next(iter(states)))
                matched += 1
        self.assertEqual(seen, {"G", "y", "r"})
        self.assertGreater(matched, 100)

    def test_sumo_leads(self):
        rows = self.sync("sumo", timeout=60.0)  # SUMO's own program: 42 s green, 3 s yellow
        seen = set()
        for k, row in enumerate(rows[1:], 1):
            prev = rows[k - 1].get("sumo")
            if not prev:
                continue
            sumo_state = {c.lower() for c in self.link_state(prev, "100", "-1")}
            mine = row["lights"]["signals"]["1"]
            self.assertEqual(row["lights"]["leader"], "sumo")
            if len(sumo_state) == 1:
                c = next(iter(sumo_state))
                want = {"g": "green", "y": "yellow", "r": "red", "u": "red_yellow"}[c]
                self.assertIn(mine, (want, rows[k - 1]["lights"]["signals"]["1"]))
            seen.add(mine)
        self.assertIn("green", seen)
        self.assertIn("red", seen)


class BadInput(TrafficLightsCase):
    def check(self, *needles):
        r = self.run_convoy()
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "lights", *needles)
        self.assertOneError(r)
        self.assertNoEngineLeft()

    def test_unknown_junction(self):
        self.experiment(Junctions={"999": {"Green": 5}})
        self.check("Junctions.999", "no junction")

    def test_negative_duration(self):
        self.experiment(Yellow=-1.0)
        self.check("Yellow", ">= 0")

    def test_negative_override(self):
        self.experiment(Junctions={"100": {"AllRed": -2}})
        self.check("Junctions.100.AllRed")

    def test_unknown_controller_in_program(self):
        self.experiment(Programs={"100": [{"Duration": 1, "Green": ["2001"]}]})
        self.check("Programs.100[0].Green", "2001")

    def test_bad_leader(self):
        self.experiment(Leader="carla")
        r = self.run_convoy()
        self.assertNotEqual(r.proc.returncode if hasattr(r, "proc") else r.code, 0)
        self.assertStderrHas(r, "Leader")
        self.assertNoEngineLeft()

    def test_bad_map(self):
        self.experiment()
        self.write("city.xodr", "<OpenDRIVE><road")
        self.check("Map", "city.xodr")


if __name__ == "__main__":
    unittest.main()
