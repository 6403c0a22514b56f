"""Unit tests of the player (python/convoy_scenario/player*.py: the scenario's default
controller) on a synthetic straight road, against hand-computed positions and speeds.

Run: cd tests/unit && /usr/bin/python3 -m unittest -v test_player (ctest: py_player)."""

import math
import os
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)

from convoy_scenario import model as m  # noqa: E402
from convoy_scenario.player import Player  # noqa: E402
from convoy_scenario.player_positions import resolve  # noqa: E402
from convoy_scenario.storyboard import ActionCommand, StepResult  # noqa: E402
from convoy_scenario.xmltree import ScenarioError  # noqa: E402

WIDTH = 3.5
LENGTH = 200.0


class StraightRoads:
    """Road "1" along +x from (0, 0), LENGTH m, lanes 1 (left, against s), -1 and -2, each
    WIDTH wide; road "2" follows road 1 (lanes -1, -2), 100 m further along x."""

    def _check(self, road, lane):
        if road not in ("1", "2") or lane not in ((1, -1, -2) if road == "1" else (-1, -2)):
            raise ScenarioError("no lane %s on road %s" % (lane, road))

    def _centre(self, lane):
        return (abs(lane) - 0.5) * WIDTH * (1 if lane > 0 else -1)

    def lane_info(self, road, lane, s):
        self._check(str(road), int(lane))
        return {"type": "driving", "width": WIDTH, "s0": 0.0,
                "s1": LENGTH if road == "1" else 100.0, "forward": lane < 0, "junction": "-1",
                "centre_t": self._centre(lane), "left": None, "right": None}

    def lane_pose(self, road, lane, s, t=0.0):
        self._check(str(road), int(lane))
        x0 = 0.0 if road == "1" else LENGTH
        y = self._centre(lane) + t
        return x0 + s, y, 0.0, 0.0 if lane < 0 else math.pi, 0.0

    def lanes_at(self, road, s):
        return [1, -1, -2] if road == "1" else [-1, -2]

    def next_lanes(self, road, lane, s):
        if road == "1" and lane < 0:
            return [{"road": "2", "lane": lane, "s": 0.0, "forward": True, "junction": "-1"}]
        return []

    def prev_lanes(self, road, lane, s):
        return []

    def locate(self, x, y, heading=None, max_distance=5.0, lane_types=None):
        if not (0 <= x <= LENGTH + 100.0) or not (-2 * WIDTH <= y <= WIDTH):
            return None
        road, s = ("1", x) if x <= LENGTH else ("2", x - LENGTH)
        lane = 1 if y > 0 else (-1 if y > -WIDTH else -2)
        return {"road": road, "lane": lane, "s": s, "t": y - self._centre(lane),
                "heading": 0.0 if lane < 0 else math.pi, "distance": 0.0}

    def route(self, a, b, ds=2.0):
        return {"segments": []}


def box():
    return m.BoundingBox((1.4, 0.0, 0.75), 4.5, 2.0, 1.5)


def scenario(inits, perf=None):
    perf = perf or m.Performance(70.0, 10.0, 10.0)
    veh = m.Vehicle("car", "car", box(), perf)
    ents = (m.Entity("A", "vehicle", veh), m.Entity("B", "vehicle", veh))
    return m.Scenario("t.xosc", m.FileHeader(1, 2, "", "", ""), (), None, None, ents,
                      tuple(m.InitAction(e, spec) for e, spec in inits), (), None)


def teleport(s, lane=-1, offset=0.0):
    return m.TeleportAction(m.LanePosition("1", str(lane), s, offset))


def speed(v, shape="step", dim="time", value=0.0):
    return m.SpeedAction(m.Dynamics(shape, dim, value), m.AbsoluteTargetSpeed(v))


def started(t, *specs):
    r = StepResult(t)
    for i, (actor, spec) in enumerate(specs):
        r.started.append(ActionCommand("act%d" % i, type(spec).__name__, actor, t, {}, spec))
    return r


def run(player, t0, t1, dt=0.05, first=None):
    t = t0
    player.advance(first or StepResult(t), t, dt)
    t += dt
    while t < t1 - 1e-9:
        player.advance(StepResult(t), t, dt)
        t += dt
    return t


class PlayerTest(unittest.TestCase):
    def make(self, perf=None, b_s=100.0):
        sc = scenario([("A", teleport(10.0)), ("A", speed(20.0)), ("B", teleport(b_s, -2))], perf)
        return Player(sc, StraightRoads(), ["A", "B"])

    def test_init_places_and_sets_speed(self):
        p = self.make()
        a = p.world()["A"]
        self.assertAlmostEqual(a["x"], 10.0)
        self.assertAlmostEqual(a["y"], -1.75)
        self.assertEqual((a["road"], a["lane"]), ("1", -1))
        self.assertAlmostEqual(a["speed"], 20.0)
        self.assertAlmostEqual(p.world()["B"]["speed"], 0.0)

    def test_default_controller_keeps_speed_along_lane(self):
        p = self.make()
        run(p, 0.0, 1.0)
        a = p.world()["A"]
        self.assertAlmostEqual(a["x"], 30.0, places=6)
        self.assertAlmostEqual(a["vx"], 20.0, places=6)
        self.assertAlmostEqual(a["odometer"], 20.0, places=6)

    def test_continues_onto_the_next_road(self):
        p = self.make()
        run(p, 0.0, 10.0)   # 10 + 200 m: 10 m into road 2
        a = p.world()["A"]
        self.assertEqual(a["road"], "2")
        self.assertAlmostEqual(a["x"], 210.0, places=4)
        self.assertAlmostEqual(a["s"], 10.0, places=4)

    def test_stops_at_the_end_of_the_road(self):
        p = self.make()
        run(p, 0.0, 16.0)   # 320 m wanted, 300 m of road
        a = p.world()["A"]
        self.assertTrue(a["end_of_road"])
        self.assertAlmostEqual(a["x"], LENGTH + 100.0, places=4)
        self.assertEqual(a["speed"], 0.0)

    def test_linear_speed_change_over_time(self):
        p = self.make()
        # 20 -> 10 m/s over 2 s: acts on the first step already (esmini's order)
        t = run(p, 0.0, 2.0, first=started(0.0, ("A", speed(10.0, "linear", "time", 2.0))))
        a = p.world()["A"]
        self.assertAlmostEqual(a["speed"], 10.0, places=6)
        # distance: sum of v(k dt + dt) dt = 2 s x 15 m/s - (20 - 10) x 0.05 / 2
        self.assertAlmostEqual(a["x"] - 10.0, 30.0 - 0.25, places=6)
        self.assertAlmostEqual(t, 2.0)

    def test_performance_limits_acceleration(self):
        p = self.make(perf=m.Performance(70.0, 2.0, 5.0))
        run(p, 0.0, 1.0, first=started(0.0, ("A", speed(10.0, "linear", "time", 1.0))))
        # the deceleration is capped at 5 m/s^2: the transition takes 2 s instead of 1
        self.assertAlmostEqual(p.world()["A"]["speed"], 15.0, places=6)

    def test_speed_over_distance(self):
        p = self.make()
        run(p, 0.0, 4.0, first=started(0.0, ("A", speed(0.0, "linear", "distance", 40.0))))
        a = p.world()["A"]
        self.assertAlmostEqual(a["speed"], 0.0, places=6)
        self.assertAlmostEqual(a["x"] - 10.0, 40.0 - 0.5, delta=0.6)

    def test_lane_change_over_time(self):
        p = self.make()
        lc = m.LaneChangeAction(m.Dynamics("linear", "time", 2.0), m.AbsoluteTargetLane("-2"))
        run(p, 0.0, 1.0, first=started(0.0, ("A", lc)))
        a = p.world()["A"]
        self.assertEqual(a["lane"], -2)
        self.assertAlmostEqual(a["y"], -1.75 - 1.75, places=6)   # half way
        self.assertLess(math.sin(a["yaw"]), 0)   # heading to the right (yaw in [0, 2 pi))
        run(p, 1.0, 2.0)
        a = p.world()["A"]
        self.assertAlmostEqual(a["y"], -5.25, places=6)
        self.assertAlmostEqual(a["yaw"] % (2 * math.pi), 0.0, places=6)
        # path length is speed x time: a little less progress along x than 40 m
        self.assertLess(a["x"] - 10.0, 40.0)
        self.assertGreater(a["x"] - 10.0, 39.5)

    def test_relative_lane_change_to_the_left(self):
        p = self.make()
        lc = m.LaneChangeAction(m.Dynamics("step", "time", 0.0), m.RelativeTargetLane("B", 1))
        run(p, 0.0, 0.05, first=started(0.0, ("A", lc)))
        self.assertEqual(p.world()["A"]["lane"], -1)   # B is on -2: one to its left is -1

    def test_timed_trajectory(self):
        p = self.make()
        verts = (m.Vertex(m.WorldPosition(50.0, -1.75), 0.0), m.Vertex(m.WorldPosition(60.0, -5.25), 1.0))
        tr = m.FollowTrajectoryAction("t", verts, m.Timing("relative", 1.0, 0.0))
        run(p, 0.0, 0.5, first=started(0.0, ("A", tr)))
        a = p.world()["A"]
        self.assertAlmostEqual(a["x"], 55.0, places=6)
        self.assertAlmostEqual(a["y"], -3.5, places=6)
        self.assertAlmostEqual(a["speed"], math.hypot(10, 3.5), places=6)

    def test_teleport_in_the_storyboard(self):
        p = self.make()
        run(p, 0.0, 0.05, first=started(0.0, ("B", teleport(150.0, 1))))
        b = p.world()["B"]
        self.assertAlmostEqual(b["x"], 150.0)
        self.assertAlmostEqual(b["y"], 1.75)
        self.assertAlmostEqual(b["yaw"], math.pi)

    def test_same_inputs_same_states(self):
        def once():
            p = self.make()
            lc = m.LaneChangeAction(m.Dynamics("sinusoidal", "distance", 30.0), m.AbsoluteTargetLane("-2"))
            run(p, 0.0, 3.0, first=started(0.0, ("A", lc), ("B", speed(5.0, "cubic", "time", 2.0))))
            return p.world()
        self.assertEqual(once(), once())


class PositionsTest(unittest.TestCase):
    """Positions resolved by the player (player_positions.py)."""

    def setUp(self):
        sc = scenario([("A", teleport(10.0)), ("A", speed(20.0)), ("B", teleport(100.0, -2))])
        self.p = Player(sc, StraightRoads(), ["A", "B"])

    def test_relative_lane_position(self):
        pos = m.RelativeLanePosition("A", -1, ds=15.0, offset=0.5)
        x, y = self.p.resolve_xy(pos)
        self.assertAlmostEqual(x, 25.0)
        self.assertAlmostEqual(y, -5.25 + 0.5)     # one lane to the right (-2), 0.5 m left of its centre
        pos = m.RelativeLanePosition("A", 1, ds_lane=-5.0)
        self.assertEqual(resolve(pos, self.p.everyone, StraightRoads())["lane"], 1)   # lane 0 skipped

    def test_road_position_and_dict_round_trip(self):
        pos = m.RoadPosition("1", 50.0, -4.0)
        r = resolve(pos, self.p.everyone, StraightRoads())
        self.assertEqual((r["lane"], round(r["offset"], 6)), (-2, 1.25))   # -4 is in lane -2
        self.assertEqual(resolve(pos.as_dict(), self.p.everyone, StraightRoads()), r)

    def test_relative_object_position(self):
        x, y = self.p.resolve_xy(m.RelativeObjectPosition("B", 3.0, 1.0))
        self.assertAlmostEqual((x, y), (103.0, -5.25 + 1.0))

    def test_unknown_lane_is_an_error(self):
        with self.assertRaises(ScenarioError):
            self.p.resolve_xy(m.LanePosition("1", "-7", 5.0))


class ControllersTest(unittest.TestCase):
    def test_kinds(self):
        from convoy_scenario.controllers import agent_keys, kind
        self.assertEqual(kind(None), "default")
        self.assertEqual(kind(m.Controller("ACCController", None, (("timeGap", "1.5"),))), "driver")
        self.assertEqual(kind(m.Controller("myAcc", None, (("esminiController", "ACCController"),))), "driver")
        self.assertEqual(kind(m.Controller("convoy.agent")), "driver")
        self.assertEqual(kind(m.Controller("InteractiveController")), "external")
        self.assertEqual(kind(m.Controller("somethingElse")), "default")
        keys = agent_keys(m.Controller("ACCController", None, (("timeGap", "1.5"), ("convoy.v0", "12"))))
        self.assertEqual(keys, {"T": 1.5, "v0": 12.0})


if __name__ == "__main__":
    unittest.main()
