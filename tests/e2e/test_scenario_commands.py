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
from test_pedestrian_agent import NO_CROSSWALK

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


if __name__ == "__main__":
    unittest.main()
