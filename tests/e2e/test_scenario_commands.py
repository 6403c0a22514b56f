"""Scenario commands (docs/road_users.md, "Commands"): the `command` datapack into a
vehicle_agent and a pedestrian_agent, their StartPose, and the weather engine's
`weather_control` input.

A TF stands in for the scenario engine: each time the agent has stepped it computes the
command for the agent's next step from that step's end time (a Python function of the test,
`command(t, me)`, `me` the agent's last state as a dict) and sends it as the JSON datapack
`command`; it records every step's states (and the command sent) to a JSON-lines file.

Vehicle tests run on test_vehicle_agent's straight road: 1000 m along +x, lanes -1 (y = -1.75)
and -2 (y = -5.25) driven along +x, lane 1 (y = 1.75) the other way. Pedestrian tests run on
test_pedestrian_agent's 100 m road with sidewalks -2 (y = -4.75) and 2 (y = 4.75).
"""

import hashlib
import json
import math
import os
import unittest

from e2e_util import BIN_DIR, E2ETestCase
from test_vehicle_agent import CONSTANT, XODR, LENGTH, W, front, rear
from test_pedestrian_agent import CITY, NO_CROSSWALK

AGENT = os.path.join(BIN_DIR, "convoy-engine-vehicle_agent")
PED = os.path.join(BIN_DIR, "convoy-engine-pedestrian_agent")
EXIT_ENGINE = 3
DT = 0.05

TF = """\
import json
import math
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
from convoy_traffic.neighbours import neighbour_datapacks, road_users

_out = open({out!r}, "a")
DT = {dt!r}

{command}

{decorators}
@TransceiverFunction({agent!r})
def scenario({args}):
    dps = [{args}]
    users = road_users(dps)
    row = {{u.id: dict(x=u.x, y=u.y, yaw=u.yaw, speed=u.speed, acc=u.acceleration, lane=u.lane,
                       road=u.road, s=u.s, t=u.t, lights=u.lights, absent=u.absent,
                       walk_phase=u.walk_phase, length=u.length,
                       length_offset=u.length_offset, time_ns=u.time_ns)
            for u in users}}
    me = {agent}
    if not me.isEmpty():
        row["_digest"] = me.data.SerializeToString().hex()
    t = round((me.data.time_ns if not me.isEmpty() else 0) * 1e-9 + DT, 6)
    c = command(t, row.get({agent!r}))
    row["_t"] = t
    row["_cmd"] = c
    _out.write(json.dumps(row, sort_keys=True) + "\\n")
    _out.flush()
    out = neighbour_datapacks(dps, agents=[{agent!r}], radius=150.0)
    if c is not None:
        out.append(JsonDataPack("command", {agent!r}, c))
    return out
"""


class CommandCase(E2ETestCase):
    binary = AGENT

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        if not os.access(cls.binary, os.X_OK):
            raise unittest.SkipTest("%s is not built" % cls.binary)

    def experiment(self, command, agent=None, others=(), timeout=10.0, pedestrian=False):
        """command: Python source defining command(t, me) -> dict or None."""
        out = os.path.join(self.dir, "stream.jsonl")
        if pedestrian:
            self.write("road.xodr", NO_CROSSWALK)
            me = {"EngineType": "pedestrian_agent", "EngineName": "ped", "EngineTimestep": DT,
                  "Map": "road.xodr", "Route": {"from": "1:-2", "to": "1:-2"}, "SpeedSd": 0.0,
                  "Speed": 1.4}
        else:
            self.write("road.xodr", XODR.format(L=LENGTH, w=W, signals=""))
            me = {"EngineType": "vehicle_agent", "EngineName": "car", "EngineTimestep": DT,
                  "Map": "road.xodr", "Route": {"from": "1:-1", "to": "1:-1"}, "v0": 20.0,
                  "LaneChanges": False}
        me.update(agent or {})
        name = me["EngineName"]
        engines = [me]
        names = [name]
        for other, x0, y, v in others:
            self.write(other + ".py", CONSTANT.format(name=other, x0=x0, y=y, v=v))
            engines.append({"EngineType": "python_json", "EngineName": other,
                            "PythonFileName": other + ".py", "EngineTimestep": DT})
            names.append(other)
        decorators = "\n".join(
            '@EngineDataPack(keyword="%s", id=DataPackIdentifier("state", "%s"))' % (n, n)
            for n in names)
        self.write("tf.py", TF.format(out=out, dt=DT, command=command, decorators=decorators,
                                      agent=name, args=", ".join(names)))
        self.write_config({"SimulationName": "commands", "SimulationTimeout": timeout,
                           "EngineConfigs": engines,
                           "DataPackProcessingFunctions": [{"Name": "scenario",
                                                            "FileName": "tf.py"}]})
        return out

    def rows(self, path, name="car"):
        """Every step's state of `name` (time_ns > 0), each with the command that was sent for
        that step ("cmd")."""
        with open(path) as f:
            rows = [json.loads(line) for line in f]
        sent = {round(r["_t"], 6): r["_cmd"] for r in rows}
        out = []
        for r in rows:
            if name in r and r[name]["time_ns"] > 0:
                u = dict(r[name])
                u["t"] = round(u["time_ns"] * 1e-9, 6)
                u["cmd"] = sent.get(u["t"])
                out.append(u)
        return out

    def run_ok(self):
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        return r

    def assertContinuous(self, rows, i, max_speed=25.0, max_dv=0.5):
        """No jump between rows i-1 and i: position within the distance it can drive in a
        step, speed within what it can change in one."""
        a, b = rows[i - 1], rows[i]
        step = math.hypot(b["x"] - a["x"], b["y"] - a["y"])
        self.assertLess(step, max_speed * DT + 1e-6, (a, b))
        self.assertLess(abs(b["speed"] - a["speed"]), max_dv, (a, b))


class VehicleSpeed(CommandCase):
    def test_step_then_linear_profile_then_the_ai_resumes(self):
        command = """\
def command(t, me):
    if 2.0 <= t < 4.0:
        return {"time_ns": int(t * 1e9), "speed": {"speed": 5.0, "target_speed": 5.0, "acceleration": 0.0}}
    if 4.0 <= t < 6.0:
        return {"speed": {"speed": 5.0 + 5.0 * (t - 4.0), "target_speed": 15.0, "acceleration": 5.0}}
    if 7.0 <= t < 9.0:
        return {"speed": {"speed": 15.0 - 3.0 * (t - 7.0), "target_speed": 9.0, "acceleration": -3.0}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0}, timeout=11.0)
        self.run_ok()
        rows = self.rows(out)
        by_t = {u["t"]: u for u in rows}
        for u in rows:
            t = u["t"]
            if 2.0 <= t < 4.0 - 1e-9:
                self.assertEqual(u["speed"], 5.0, u)
            elif 4.0 <= t < 6.0 - 1e-9:
                self.assertAlmostEqual(u["speed"], 5.0 + 5.0 * (t - 4.0), places=9)
                self.assertEqual(u["acc"], 5.0)
                self.assertFalse(u["lights"] & 2, "no BRAKE while accelerating")
            elif 7.0 <= t < 9.0 - 1e-9:
                self.assertAlmostEqual(u["speed"], 15.0 - 3.0 * (t - 7.0), places=9)
                self.assertEqual(u["acc"], -3.0)
                self.assertTrue(u["lights"] & 2, "BRAKE while the profile decelerates")
        # The positions follow the commanded speeds (semi-implicit Euler: x += v dt).
        self.assertAlmostEqual(by_t[3.0]["x"] - by_t[2.5]["x"], 5.0 * 0.5, places=6)
        # After each command IDM resumes from the present speed: no jump.
        for t0 in (6.0, 9.0):
            i = next(k for k, u in enumerate(rows) if u["t"] == t0)
            self.assertIsNone(rows[i]["cmd"])
            self.assertLess(abs(rows[i]["speed"] - rows[i - 1]["speed"]), 1.5 * DT + 1e-9)
            self.assertContinuous(rows, i)
        # IDM free road: it accelerates towards v0 = 20 afterwards.
        self.assertGreater(rows[-1]["speed"], by_t[9.0]["speed"] + 1.0)
        self.assertEqual({u["lane"] for u in rows}, {-1})

    def test_obeyed_exactly_even_towards_a_leader(self):
        # A slow leader 40 m ahead: IDM would brake, the command keeps 10 m/s until the gap
        # is below IDM's minimum gap s0 (2 m).
        command = """\
def command(t, me):
    if t <= 6.8:
        return {"speed": {"speed": 10.0}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0},
                              others=[("leader", 40.0, -1.75, 5.0)], timeout=7.5)
        self.run_ok()
        with open(out) as f:
            rows = [json.loads(line) for line in f]
        both = [r for r in rows if "car" in r and "leader" in r and r["car"]["time_ns"] > 0]
        commanded = [r for r in both if r["car"]["time_ns"] <= 6.8e9 + 1]
        self.assertTrue(all(r["car"]["speed"] == 10.0 for r in commanded))
        gap = min(rear(r["leader"]) - front(r["car"]) for r in commanded)
        self.assertLess(gap, 2.0)


class VehicleLane(CommandCase):
    def test_lane_change_by_progress_then_on_in_the_new_lane(self):
        command = """\
def command(t, me):
    if 2.0 <= t <= 5.0:
        return {"lane": {"road": "1", "lane": -2, "from_lane": -1, "offset": 0.0,
                         "progress": (t - 2.0) / 3.0}}
    if 8.0 <= t <= 10.0:
        return {"lane": {"road": "1", "lane": -1, "from_lane": -2, "offset": 0.3,
                         "progress": (t - 8.0) / 2.0}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0}, timeout=14.0)
        self.run_ok()
        rows = self.rows(out)
        for u in rows:
            t = u["t"]
            if 2.0 <= t <= 5.0:
                p = (t - 2.0) / 3.0
                self.assertAlmostEqual(u["y"], -1.75 - 3.5 * p, places=5)
                if 0 < p < 1:
                    self.assertTrue(u["lights"] & 8, "right indicator while changing")
            elif 5.0 < t < 8.0:
                # (linear progress ends with a sideways speed: pure pursuit takes it up)
                self.assertAlmostEqual(u["y"], -5.25, delta=0.01)
                self.assertEqual(u["lane"], -2)
                self.assertFalse(u["lights"] & 12)
            elif 8.0 <= t <= 10.0:
                p = (t - 8.0) / 2.0
                self.assertAlmostEqual(u["y"], -5.25 + (3.5 + 0.3) * p, places=5)
                if 0 < p < 1:
                    self.assertTrue(u["lights"] & 4, "left indicator while changing")
        # Longitudinally IDM drove on (v0 20 from 10): not held at one speed.
        speeds = [u["speed"] for u in rows if 2.0 <= u["t"] <= 5.0]
        self.assertGreater(speeds[-1], speeds[0] + 1.0)
        # After the second change the AI steers back to the lane centre, smoothly.
        i = next(k for k, u in enumerate(rows) if u["t"] > 10.0)
        for k in range(i, len(rows)):
            self.assertContinuous(rows, k)
            self.assertLess(abs(rows[k]["y"] - rows[k - 1]["y"]), 0.1)
        self.assertAlmostEqual(rows[-1]["y"], -1.75, delta=0.05)
        self.assertEqual(rows[-1]["lane"], -1)
        self.assertFalse(rows[-1]["absent"])


class VehicleRoute(CommandCase):
    def test_route_through_positions_kept_after_the_command(self):
        command = """\
def command(t, me):
    if abs(t - 1.0) < 1e-6:
        return {"route": {"positions": [[300.0, -5.25], [600.0, -1.75]]}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 15.0, "v0": 25.0}, timeout=45.0)
        self.run_ok()
        rows = self.rows(out)
        lane_at = lambda x0: next(u["lane"] for u in rows if u["x"] >= x0)
        self.assertEqual(lane_at(100.0), -1)
        self.assertEqual(lane_at(280.0), -2)
        self.assertEqual(lane_at(320.0), -2)
        self.assertEqual(lane_at(590.0), -1)
        self.assertEqual(lane_at(700.0), -1)
        sent = [u for u in rows if u["cmd"]]
        self.assertEqual(len(sent), 1, "the route was sent once, and kept")
        for k in range(1, len(rows)):
            if not rows[k]["absent"]:
                self.assertContinuous(rows, k)
        # After its last position it goes on along the lane graph to the road's end.
        self.assertTrue(rows[-1]["absent"])


class VehicleTrajectory(CommandCase):
    def test_timed_trajectory_then_back_onto_its_lane(self):
        command = """\
_start = []
def command(t, me):
    if 2.0 <= t <= 4.0 + 1e-9:
        if not _start:
            _start.append(me["x"] + 10.0 * DT)
        u = t - 2.0
        return {"trajectory": {"x": _start[0] + 12.0 * u, "y": -1.75 + 1.0 * u,
                               "yaw": math.atan2(1.0, 12.0), "speed": math.hypot(12.0, 1.0)}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0, "v0": 10.0}, timeout=12.0)
        self.run_ok()
        rows = self.rows(out)
        timed = [u for u in rows if u["cmd"]]
        x0 = timed[0]["cmd"]["trajectory"]["x"]
        for u in timed:
            c = u["cmd"]["trajectory"]
            self.assertEqual((u["x"], u["y"], u["yaw"], u["speed"]),
                             (c["x"], c["y"], c["yaw"], c["speed"]))
        self.assertAlmostEqual(timed[-1]["y"], 0.25, places=6)  # over the centre line
        # Then the AI: on lane -1 (lane 1 at y > 0 runs the other way), no jumps.
        i = rows.index(timed[-1]) + 1
        for k in range(i, len(rows)):
            self.assertContinuous(rows, k)
        self.assertAlmostEqual(rows[-1]["y"], -1.75, delta=0.05)
        self.assertEqual(rows[-1]["lane"], -1)
        self.assertAlmostEqual(abs(rows[-1]["yaw"]), 0.0, delta=0.02)

    def test_untimed_trajectory_followed_at_its_own_speed(self):
        command = """\
_start = []
def command(t, me):
    if not _start:
        _start.append(me["x"])
    x0 = _start[0]
    if t >= 1.0 and me["x"] < x0 + 150.0:
        return {"trajectory": {"polyline": [[x0 + 5.0, -1.75], [x0 + 60.0, -5.25],
                                            [x0 + 200.0, -5.25]], "length": 195.1}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0, "v0": 12.0}, timeout=20.0)
        self.run_ok()
        rows = self.rows(out)
        followed = [u for u in rows if u["cmd"]]
        x0 = followed[0]["cmd"]["trajectory"]["polyline"][0][0] - 5.0
        self.assertGreater(len(followed), 100)
        # On the polyline's last leg (y = -5.25) once it has turned onto it.
        for u in followed:
            if u["x"] > x0 + 90.0:
                self.assertAlmostEqual(u["y"], -5.25, delta=0.2)
        # Its own IDM speed (v0 12 from 10).
        self.assertAlmostEqual(followed[-1]["speed"], 12.0, delta=0.3)
        # Afterwards it stays in lane -2, where it is.
        i = rows.index(followed[-1]) + 1
        for k in range(i, len(rows)):
            self.assertContinuous(rows, k)
        self.assertEqual(rows[-1]["lane"], -2)
        self.assertAlmostEqual(rows[-1]["y"], -5.25, delta=0.05)


class VehicleTeleport(CommandCase):
    def test_teleport_once_then_on_from_there(self):
        command = """\
def command(t, me):
    if abs(t - 3.0) < 1e-6:
        return {"teleport": {"x": 500.0, "y": -5.25, "yaw": 0.0, "speed": 8.0}}
    return None
"""
        out = self.experiment(command, agent={"InitialSpeed": 10.0}, timeout=6.0)
        self.run_ok()
        rows = self.rows(out)
        at = next(u for u in rows if u["t"] == 3.0)
        self.assertEqual((at["x"], at["y"], at["yaw"], at["speed"]), (500.0, -5.25, 0.0, 8.0))
        self.assertEqual(at["lane"], -2)
        after = [u for u in rows if u["t"] > 3.0]
        self.assertAlmostEqual(after[0]["x"], 500.0 + after[0]["speed"] * DT, places=6)
        self.assertLess(abs(after[0]["speed"] - 8.0), 1.5 * DT + 1e-9)
        for k in range(rows.index(after[0]) + 1, len(rows)):
            self.assertContinuous(rows, k)
        self.assertEqual({u["lane"] for u in after}, {-2})
        self.assertAlmostEqual(max(abs(u["y"] + 5.25) for u in after), 0.0, places=3)


class VehicleStartPose(CommandCase):
    def test_starts_at_its_pose_and_follows_the_lane_graph(self):
        out = self.experiment("def command(t, me):\n    return None\n",
                              agent={"Route": {}, "StartPose": {"x": 100.0, "y": -2.5, "yaw": 0.1},
                                     "InitialSpeed": 5.0}, timeout=10.0)
        self.run_ok()
        rows = self.rows(out)
        first = rows[0]
        # The first step from the pose: about 5 m/s x 0.05 s from (100, -2.5) along yaw 0.1.
        self.assertAlmostEqual(first["x"], 100.0 + 5.0 * DT * math.cos(0.1), delta=0.02)
        self.assertAlmostEqual(first["y"], -2.5 + 5.0 * DT * math.sin(0.1), delta=0.02)
        for k in range(1, len(rows)):
            self.assertContinuous(rows, k)
        self.assertEqual(rows[-1]["lane"], -1)
        self.assertAlmostEqual(rows[-1]["y"], -1.75, delta=0.05)

    def test_facing_the_other_way_it_takes_the_other_lane(self):
        out = self.experiment("def command(t, me):\n    return None\n",
                              agent={"Route": {}, "StartPose": {"x": 500.0, "y": -1.0,
                                                                "yaw": math.pi},
                                     "InitialSpeed": 5.0}, timeout=10.0)
        self.run_ok()
        rows = self.rows(out)
        self.assertEqual(rows[-1]["lane"], 1)
        self.assertAlmostEqual(rows[-1]["y"], 1.75, delta=0.05)
        self.assertLess(rows[-1]["x"], 480.0)

    def test_onward_through_the_city_by_seed(self):
        # On the city map from road 1 (west of junction 100), no Route: at each junction a
        # way drawn from Seed, the route planned on as it goes, until a map edge.
        seqs = {}
        for seed in (0, 1, 2, 3, 0):
            out = self.experiment("def command(t, me):\n    return None\n",
                                  agent={"Map": CITY, "Route": {}, "Seed": seed,
                                         "StartPose": {"x": -230.0, "y": -1.75, "yaw": 0.0},
                                         "InitialSpeed": 12.0, "v0": 13.9, "LaneChanges": True},
                                  timeout=70.0)
            self.run_ok()
            rows = self.rows(out)
            os.remove(out)
            present = [u for u in rows if not u["absent"]]
            for k in range(1, len(present)):
                self.assertContinuous(present, k, max_speed=15.0, max_dv=0.5)
            roads = []
            for u in present:
                if not roads or roads[-1] != u["road"]:
                    roads.append(u["road"])
            self.assertGreater(len(roads), 2, roads)  # through a junction at least
            if seed in seqs:
                self.assertEqual(seqs[seed], roads, "the same seed, the same way")
            seqs[seed] = roads
            # It drove more than its first plan's 600 m, or ended at a map edge.
            last = present[-1]
            travelled = sum(math.hypot(b["x"] - a["x"], b["y"] - a["y"])
                            for a, b in zip(present, present[1:]))
            at_edge = abs(last["x"]) > 440 or abs(last["y"]) > 140
            if os.environ.get("CONVOY_E2E_SHOW"):
                print(seed, roads, round(travelled), rows[-1]["absent"], last["x"], last["y"])
            self.assertTrue(travelled > 600.0 or (rows[-1]["absent"] and at_edge),
                            (seed, roads, travelled, last))
        if os.environ.get("CONVOY_E2E_SHOW"):
            print(seqs)
        self.assertGreater(len({tuple(v) for v in seqs.values()}), 1, seqs)

    def test_start_pose_with_route_to(self):
        out = self.experiment("def command(t, me):\n    return None\n",
                              agent={"Route": {"to": "1:-2"},
                                     "StartPose": {"x": 900.0, "y": -1.75, "yaw": 0.0},
                                     "InitialSpeed": 15.0}, timeout=10.0)
        self.run_ok()
        rows = self.rows(out)
        self.assertIn(-2, [u["lane"] for u in rows])
        self.assertTrue(rows[-1]["absent"], "at the end of road 1 (Route.to)")


class VehicleDeterminism(CommandCase):
    def test_two_runs_are_identical(self):
        command = """\
def command(t, me):
    c = {}
    if 1.0 <= t < 3.0:
        c["speed"] = {"speed": 8.0 + t, "acceleration": 1.0}
    if 2.0 <= t <= 4.0:
        c["lane"] = {"road": "1", "lane": -2, "from_lane": -1, "progress": (t - 2.0) / 2.0}
    if abs(t - 5.0) < 1e-6:
        c["route"] = {"positions": [[400.0, -1.75]]}
    if 7.0 <= t <= 8.0:
        c["trajectory"] = {"polyline": [[me["x"] + 10, -3.5], [me["x"] + 50, -3.5]]}
    return c or None
"""
        digests = []
        for _ in range(2):
            out = self.experiment(command, agent={"InitialSpeed": 10.0, "ReactionTime": 0.3},
                                  others=[("slow", 80.0, -1.75, 6.0)], timeout=10.0)
            self.run_ok()
            with open(out) as f:
                rows = [json.loads(line)["_digest"] for line in f if "_digest" in line]
            self.assertGreater(len(rows), 150)
            digests.append(hashlib.sha1("".join(rows).encode()).hexdigest())
            os.remove(out)
        self.assertEqual(digests[0], digests[1])


class VehicleBadCommand(CommandCase):
    def bad(self, cmd, *needles, agent=None):
        self.experiment("def command(t, me):\n    return %r if t >= 1.0 else None\n" % (cmd,),
                        agent=agent, timeout=3.0)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, EXIT_ENGINE)
        self.assertOneError(r)
        self.assertStderrHas(r, *needles)
        self.assertNoEngineLeft()
        self.assertLogsKept("car")
        return r

    def test_unknown_key(self):
        self.bad({"sped": {"speed": 3.0}}, "vehicle_agent 'car'", "command.sped", "unknown key")

    def test_wrong_type(self):
        self.bad({"speed": {"speed": "fast"}}, "command.speed.speed", "expected a number")

    def test_lane_not_on_the_road(self):
        self.bad({"lane": {"road": "1", "lane": -5, "from_lane": -1, "progress": 0.5}},
                 "command.lane.lane: road 1 has no lane -5")

    def test_unknown_road(self):
        self.bad({"lane": {"road": "7", "lane": -2, "from_lane": -1, "progress": 0.5}},
                 "command.lane.road: no road 7")

    def test_route_position_off_the_road(self):
        self.bad({"route": {"positions": [[400.0, -1.75], [100.0, 60.0]]}},
                 "command.route.positions[1]", "farther than 20 m")

    def test_not_json(self):
        self.bad([1, 2], "command", "expected a JSON object")

    def test_bad_start_pose(self):
        self.experiment("def command(t, me):\n    return None\n",
                        agent={"Route": {}, "StartPose": {"x": 100.0, "y": 90.0, "yaw": 0.0}})
        r = self.run_convoy(timeout=60)
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "car", "StartPose", "not within 50 m")
        self.assertNoEngineLeft()

    def test_start_pose_and_route_from(self):
        self.experiment("def command(t, me):\n    return None\n",
                        agent={"StartPose": {"x": 100.0, "y": -1.75, "yaw": 0.0}})
        r = self.run_convoy(timeout=60)
        self.assertNotEqual(r.code, 0)
        self.assertStderrHas(r, "car", "Route.from", "StartPose")
        self.assertNoEngineLeft()


class PedestrianCase(CommandCase):
    binary = PED

    def ped(self, command, agent=None, others=(), timeout=10.0):
        return self.experiment(command, agent=dict({"EngineName": "ped"}, **(agent or {})),
                               others=others, timeout=timeout, pedestrian=True)


class PedestrianSpeed(PedestrianCase):
    def test_walking_speed_and_walk_phase(self):
        command = """\
def command(t, me):
    if 1.0 <= t < 3.0:
        return {"speed": {"speed": 2.5}}
    return None
"""
        out = self.ped(command, timeout=5.0)
        self.run_ok()
        rows = self.rows(out, "ped")
        for u in rows:
            if 1.0 <= u["t"] < 3.0 - 1e-9:
                self.assertEqual(u["speed"], 2.5)
            elif u["t"] >= 3.0 or u["t"] < 1.0:
                self.assertAlmostEqual(u["speed"], 1.4, places=9)
        a = next(u for u in rows if u["t"] == 1.5)
        b = next(u for u in rows if u["t"] == 2.0)
        self.assertAlmostEqual(b["x"] - a["x"], 1.25, places=6)
        # walk_phase: the distance walked / StrideLength (1.4 m), mod 1.
        self.assertAlmostEqual((b["walk_phase"] - a["walk_phase"]) % 1.0, 1.25 / 1.4 % 1.0,
                               places=6)

    CROSS = """\
def command(t, me):
    c = {{}}
    if abs(t - 0.5) < 1e-6:
        c["route"] = {{"positions": [[3.0, -4.75], [3.0, 4.75], [10.0, 4.75]]}}
    if {commanded} and t >= 0.5:
        c["speed"] = {{"speed": 1.4}}
    return c or None
"""

    def crossing(self, commanded):
        # A car comes along lane -1 (y = -1.75) at 10 m/s, at x = 3 at t = 6.3 s.
        out = self.ped(self.CROSS.format(commanded=commanded),
                       agent={"CriticalGap": 4.0, "CriticalGapSd": 0.0},
                       others=[("car", -60.0, -1.75, 10.0)], timeout=22.0)
        self.run_ok()
        with open(out) as f:
            rows = [json.loads(line) for line in f]
        both = [r for r in rows if "ped" in r and "car" in r and r["ped"]["time_ns"] > 0]
        on_road = next(r for r in both if r["ped"]["y"] > -3.5)
        return both, on_road

    def test_route_across_the_road_waits_for_the_gap_on_its_own(self):
        both, on_road = self.crossing(False)
        self.assertGreater(rear(on_road["car"]), 3.5, "it stepped out after the car had passed")
        # Then it crossed, and walks on along the far sidewalk the way its route ended (+x).
        last = both[-1]["ped"]
        self.assertEqual(last["lane"], 2)
        self.assertGreater(last["x"], 10.0)
        self.assertAlmostEqual(last["y"], 4.75 - 0.55, delta=0.05)

    def test_with_a_speed_command_it_does_not_wait(self):
        both, on_road = self.crossing(True)
        self.assertLess(front(on_road["car"]), 0.0, "it stepped out before the car came")
        self.assertTrue(all(r["ped"]["speed"] == 1.4 for r in both if r["ped"]["time_ns"] > 0.5e9))


class PedestrianTrajectory(PedestrianCase):
    def test_timed_then_back_to_the_sidewalk(self):
        command = """\
_start = []
def command(t, me):
    if 1.0 <= t <= 3.0 + 1e-9:
        if not _start:
            _start.append((me["x"], me["y"]))
        x0, y0 = _start[0]
        u = t - 1.0
        return {"trajectory": {"x": x0 + 0.5 * u, "y": y0 + 2.0 * u, "yaw": math.atan2(2.0, 0.5),
                               "speed": math.hypot(0.5, 2.0)}}
    return None
"""
        out = self.ped(command, timeout=10.0)
        self.run_ok()
        rows = self.rows(out, "ped")
        timed = [u for u in rows if u["cmd"]]
        for u in timed:
            c = u["cmd"]["trajectory"]
            self.assertEqual((u["x"], u["y"], u["yaw"], u["speed"]),
                             (c["x"], c["y"], c["yaw"], c["speed"]))
        self.assertGreater(timed[-1]["y"], -1.5)  # on the road
        # walk_phase advanced with the distance moved.
        d = math.hypot(0.5, 2.0) * 1.0
        a = next(u for u in timed if abs(u["t"] - 2.0) < 1e-6)
        b = next(u for u in timed if abs(u["t"] - 3.0) < 1e-6)
        self.assertAlmostEqual((b["walk_phase"] - a["walk_phase"]) % 1.0, d / 1.4 % 1.0, places=6)
        # Then back onto sidewalk -2 (the nearest) and on to its destination (x = 100).
        i = rows.index(timed[-1]) + 1
        for k in range(i, len(rows)):
            self.assertContinuous(rows, k, max_speed=1.5, max_dv=1.5)
        self.assertEqual(rows[-1]["lane"], -2)
        self.assertGreater(rows[-1]["x"], timed[-1]["x"] + 3.0)
        self.assertAlmostEqual(rows[-1]["y"], -4.75 - 0.55, delta=0.05)

    def test_untimed_polyline(self):
        command = """\
_start = []
def command(t, me):
    if not _start:
        _start.append(me["x"])
    x0 = _start[0]
    if 1.0 <= t <= 12.0:
        return {"trajectory": {"polyline": [[x0 + 2.0, -4.75], [x0 + 6.0, -4.75], [x0 + 6.0, 0.0]],
                               "length": 10.0}}
    return None
"""
        out = self.ped(command, timeout=14.0)
        self.run_ok()
        rows = self.rows(out, "ped")
        followed = [u for u in rows if u["cmd"]]
        x0 = followed[0]["cmd"]["trajectory"]["polyline"][0][0] - 2.0
        for k in range(1, len(rows)):
            self.assertContinuous(rows, k, max_speed=1.5, max_dv=1.5)
        # At its own speed, then standing at the end while the command lasts.
        self.assertAlmostEqual(followed[10]["speed"], 1.4, places=6)
        end = followed[-1]
        self.assertAlmostEqual(end["x"], x0 + 6.0, delta=0.05)
        self.assertAlmostEqual(end["y"], 0.0, delta=0.05)
        self.assertEqual(end["speed"], 0.0)
        mid = [u for u in followed if u["y"] > -3.5 and u["y"] < -1.0]
        self.assertTrue(all(abs(u["x"] - (x0 + 6.0)) < 0.1 for u in mid))
        self.assertTrue(all(abs(abs(u["yaw"]) - math.pi / 2) < 0.1 for u in mid))


class PedestrianTeleport(PedestrianCase):
    def test_teleport_then_on_along_that_sidewalk(self):
        command = """\
def command(t, me):
    if abs(t - 2.0) < 1e-6:
        return {"teleport": {"x": 50.0, "y": 4.75, "yaw": 0.0}}
    return None
"""
        out = self.ped(command, timeout=6.0)
        self.run_ok()
        rows = self.rows(out, "ped")
        at = next(u for u in rows if u["t"] == 2.0)
        self.assertEqual((at["x"], at["y"], at["yaw"]), (50.0, 4.75, 0.0))
        after = [u for u in rows if u["t"] > 2.0]
        for k in range(rows.index(after[0]), len(rows)):
            self.assertContinuous(rows, k, max_speed=1.5, max_dv=1.5)
        # No way back across (no crosswalk): on along sidewalk 2 the way it faces.
        self.assertEqual({u["lane"] for u in after}, {2})
        self.assertGreater(after[-1]["x"], 54.0)
        self.assertAlmostEqual(after[-1]["y"], 4.75 - 0.55, delta=0.05)


class PedestrianStartPose(PedestrianCase):
    def test_starts_at_its_pose_and_walks_the_sidewalk(self):
        out = self.ped("def command(t, me):\n    return None\n",
                       agent={"Route": {}, "StartPose": {"x": 20.0, "y": -3.9, "yaw": 0.0}},
                       timeout=8.0)
        self.run_ok()
        rows = self.rows(out, "ped")
        # (easing 0.25 m sideways per m walked to its keep-right offset)
        self.assertLess(math.hypot(rows[0]["x"] - 20.0, rows[0]["y"] + 3.9),
                        1.4 * DT * math.hypot(1.0, 0.25) + 1e-6)
        for k in range(1, len(rows)):
            self.assertContinuous(rows, k, max_speed=1.5, max_dv=1.5)
        self.assertEqual(rows[-1]["lane"], -2)
        self.assertGreater(rows[-1]["x"], 25.0)

    def test_without_sidewalks_it_stands_until_commanded(self):
        command = """\
def command(t, me):
    if t >= 2.0:
        return {"speed": {"speed": 1.5},
                "trajectory": {"polyline": [[60.0, -9.0], [60.0, 9.0]], "length": 18.0}}
    return None
"""
        out = self.experiment(command, agent={"EngineType": "pedestrian_agent", "EngineName": "ped",
                                              "Route": {}, "v0": None, "LaneChanges": None,
                                              "StartPose": {"x": 60.0, "y": -9.0,
                                                            "yaw": math.pi / 2}},
                              timeout=8.0)
        # (the vehicle test road: no sidewalks; drop the vehicle keys)
        with open(os.path.join(self.dir, "simulation_config.json")) as f:
            cfg = json.load(f)
        for key in ("v0", "LaneChanges"):
            del cfg["EngineConfigs"][0][key]
        self.write_config(cfg)
        r = self.run_ok()
        self.assertRegex(r.stderr, "(?i)warning.*no sidewalk within 50 m")
        rows = self.rows(out, "ped")
        before = [u for u in rows if u["t"] < 2.0]
        self.assertTrue(all((u["x"], u["y"], u["speed"]) == (60.0, -9.0, 0.0) for u in before))
        self.assertAlmostEqual(rows[-1]["x"], 60.0, places=6)
        # commanded from the step ending at 2.0 s: 121 steps of 1.5 m/s x 0.05 s
        self.assertAlmostEqual(rows[-1]["y"], -9.0 + 1.5 * (8.0 - 2.0 + DT), delta=1e-6)


class PedestrianDeterminism(PedestrianCase):
    def test_two_runs_are_identical(self):
        command = """\
def command(t, me):
    if abs(t - 0.5) < 1e-6:
        return {"route": {"positions": [[3.0, -4.75], [3.0, 4.75], [10.0, 4.75]]}}
    if 5.0 <= t < 6.0:
        return {"speed": {"speed": 2.0}}
    if 8.0 <= t < 9.0:
        return {"trajectory": {"polyline": [[me["x"], me["y"]], [me["x"] + 3.0, 0.0]]}}
    return None
"""
        digests = []
        for _ in range(2):
            out = self.ped(command, others=[("car", -60.0, -1.75, 10.0)], timeout=12.0)
            self.run_ok()
            with open(out) as f:
                rows = [json.loads(line)["_digest"] for line in f if "_digest" in line]
            self.assertGreater(len(rows), 200)
            digests.append(hashlib.sha1("".join(rows).encode()).hexdigest())
            os.remove(out)
        self.assertEqual(digests[0], digests[1])


class PedestrianBadCommand(PedestrianCase):
    def bad(self, cmd, *needles):
        self.ped("def command(t, me):\n    return %r if t >= 1.0 else None\n" % (cmd,),
                 timeout=3.0)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, EXIT_ENGINE)
        self.assertOneError(r)
        self.assertStderrHas(r, "pedestrian_agent 'ped'", *needles)
        self.assertNoEngineLeft()
        self.assertLogsKept("ped")

    def test_lane_is_an_error(self):
        self.bad({"lane": {"road": "1", "lane": -1, "from_lane": -2, "progress": 0.5}},
                 "command.lane", "a pedestrian has no lane")

    def test_route_position_far_off(self):
        self.bad({"route": {"positions": [[50.0, 80.0]]}}, "command.route.positions[0]",
                 "farther than 20 m")

    def test_bad_polyline(self):
        self.bad({"trajectory": {"polyline": [[1.0, "a"]]}}, "command.trajectory.polyline[0]",
                 "expected numbers")


WEATHER_TF = """\
import json, os
from nrp_core import *
from nrp_core.data.nrp_json import JsonDataPack
_OUT = open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "weather.jsonl"), "a")
CONTROLS = {controls!r}


@EngineDataPack(keyword='weather', id=DataPackIdentifier('weather', 'weather'))
@TransceiverFunction("weather")
def control_tf(weather):
    if weather.isEmpty():
        return []
    _OUT.write(json.dumps(weather.data, sort_keys=True) + "\\n")
    _OUT.flush()
    c = CONTROLS.get("%.2f" % weather.data["time_s"])
    return [JsonDataPack("weather_control", "weather", c)] if c is not None else []
"""


class WeatherControl(E2ETestCase):
    def run_weather(self, controls, timeout=6.0, schedule=()):
        self.write("control_tf.py", WEATHER_TF.format(controls=controls))
        path = os.path.join(self.dir, "weather.jsonl")
        if os.path.exists(path):
            os.remove(path)
        self.write_config({"SimulationName": "w", "SimulationTimeout": timeout,
                           "EngineConfigs": [{"EngineType": "weather", "EngineName": "weather",
                                              "EngineTimestep": 0.1, "Seed": 2, "WindSpeed": 3.0,
                                              "Schedule": list(schedule)}],
                           "DataPackProcessingFunctions": [{"Name": "control_tf",
                                                            "FileName": "control_tf.py"}]})
        r = self.run_convoy(timeout=60)
        return r, path

    def test_a_step_and_a_transition_override_the_schedule(self):
        controls = {"1.00": {"Precipitation": 0.8, "Surface": "wet"},
                    "2.00": {"Visibility": 100.0, "TransitionTime": 2.0}}
        r, path = self.run_weather(controls, schedule=[{"Time": 5.0, "Precipitation": 0.1,
                                                        "WindSpeed": 9.0}])
        self.assertExit(r, 0)
        with open(path) as f:
            rows = [json.loads(line) for line in f]
        at = {"%.1f" % w["time_s"]: w for w in rows}
        self.assertEqual(at["1.0"]["precipitation"], 0.0)
        self.assertEqual(at["1.0"]["surface"], "dry")
        self.assertEqual(at["1.1"]["precipitation"], 0.8)   # from the step it arrived
        self.assertEqual(at["1.1"]["surface"], "wet")
        self.assertEqual(at["1.1"]["mu"], 0.5)
        self.assertAlmostEqual(at["2.0"]["visibility_m"], 20000.0, places=6)
        self.assertAlmostEqual(at["3.0"]["visibility_m"], math.sqrt(20000.0 * 100.0), places=6)
        self.assertAlmostEqual(at["4.0"]["visibility_m"], 100.0, places=6)
        self.assertTrue(at["4.0"]["fog"])
        # The Schedule's change at 5 s: precipitation stays the control's, wind still moves.
        self.assertEqual(at["5.5"]["precipitation"], 0.8)
        self.assertGreater(at["5.5"]["wind_speed_mps"], 5.0)
        # Deterministic: the same run again gives the same stream.
        shutil_rows = rows
        r, path = self.run_weather(controls, schedule=[{"Time": 5.0, "Precipitation": 0.1,
                                                        "WindSpeed": 9.0}])
        self.assertExit(r, 0)
        with open(path) as f:
            self.assertEqual([json.loads(line) for line in f], shutil_rows)

    def test_bad_control_names_the_key(self):
        r, _ = self.run_weather({"1.00": {"Surface": "mud"}}, timeout=2.0)
        self.assertExit(r, EXIT_ENGINE)
        self.assertOneError(r)
        self.assertStderrHas(r, "weather engine 'weather'", "weather_control.Surface",
                             "unknown surface \"mud\"")
        self.assertNoEngineLeft()

    def test_unknown_control_key(self):
        r, _ = self.run_weather({"1.00": {"Rain": 1.0}}, timeout=2.0)
        self.assertExit(r, EXIT_ENGINE)
        self.assertStderrHas(r, "weather_control.Rain", "unknown key")
        self.assertNoEngineLeft()


if __name__ == "__main__":
    unittest.main()
