"""Unit tests of the ego planner's lane changes (python/convoy_traffic/lane_change.py, lanes.py;
issue 27 item 4: pass a stopped vehicle by a lane change when the adjacent lane is free, with a
MOBIL-style safety check). Pure Python: a kinematic ego on a straight two-lane road."""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from convoy_traffic import ego_planner as ep  # noqa: E402
from convoy_traffic import lane_change as lc  # noqa: E402
from convoy_traffic.lanes import RouteLanes  # noqa: E402
from convoy_traffic.route_path import RoutePath  # noqa: E402

DT = 0.05
WHEELBASE = 2.5


def road(right_from=None, right_to=None, length=400.0):
    """A straight route along y = 0 (2 m points) with a lane at y = -3.5 between right_from and
    right_to (all along by default)."""
    route = RoutePath([(float(x), 0.0) for x in range(0, int(length) + 1, 2)])
    sides = []
    for x, _ in route.points:
        ok = (right_from is None or x >= right_from) and (right_to is None or x <= right_to)
        sides.append({"left": None, "right": -3.5 if ok else None})
    return route, RouteLanes(route, sides)


def to_ego(ego, u):
    """A world-frame road user {x, y, vx, length, width} in the ego's frame."""
    c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
    dx, dy = u["x"] - ego["x"], u["y"] - ego["y"]
    return {"id": u["id"], "class": u.get("class", "car"), "lon": c * dx + s * dy, "lat": -s * dx + c * dy,
            "length": u.get("length", 4.5), "width": u.get("width", 1.8),
            "v_lon": c * u["vx"], "v_lat": -s * u["vx"], "source": "ground_truth"}


def drive(users, seconds, lanes=True, params=None, x0=10.0, v_start=8.0, right_from=None, right_to=None):
    """Drives the ego (kinematic bicycle; the planner's speed, its steering while it changes lanes,
    else pure pursuit on the route as the follower) among `users` (world frame, moving along +x at
    vx). Returns (planner, ego trace [(t, x, y, speed)], minimum distance between box centres
    per user)."""
    route, rl = road(right_from, right_to)
    cfg = {"CruiseSpeed": 8.333}
    cfg.update(params or {})
    planner = ep.Planner(ep.parse_config(cfg), route, rl if lanes else None)
    ego = {"id": "ego", "x": x0, "y": 0.0, "yaw": 0.0, "speed": v_start, "yaw_rate": 0.0,
           "length": 3.5, "width": 1.6, "length_offset": 0.0}
    trace, closest = [], {}
    t = 0.0
    while t < seconds:
        objs = [to_ego(ego, u) for u in users]
        out = planner.step(t, ego, objs)
        steer = out["steer"]
        if steer is None:
            s_ego, _ = route.locate(ego["x"], ego["y"])
            steer = lc.steer_to(route, ego, s_ego, lambda s: 0.0, 7.0)
        v = ego["speed"] + max(-6.0, min(2.0, (out["speed"] - ego["speed"]) / 0.5)) * DT
        ego["speed"] = max(v, 0.0)
        ego["yaw_rate"] = ego["speed"] * math.tan(steer) / WHEELBASE
        ego["yaw"] += ego["yaw_rate"] * DT
        ego["x"] += ego["speed"] * math.cos(ego["yaw"]) * DT
        ego["y"] += ego["speed"] * math.sin(ego["yaw"]) * DT
        for u in users:
            u["x"] += u["vx"] * DT
            d = math.hypot(u["x"] - ego["x"], u["y"] - ego["y"])
            closest[u["id"]] = min(closest.get(u["id"], d), d)
        t += DT
        trace.append((t, ego["x"], ego["y"], ego["speed"]))
    return planner, trace, closest


def stopped(x=80.0):
    return {"id": "stopped", "x": x, "y": 0.0, "vx": 0.0}


class Decision(unittest.TestCase):
    def test_passes_a_stopped_car_in_the_free_lane_and_returns(self):
        planner, trace, closest = drive([stopped()], 25.0)
        kinds = [e["kind"] for e in planner.lc.events]
        self.assertEqual(kinds, ["out", "back"], planner.lc.events)
        self.assertEqual(planner.lc.events[0]["side"], "right")
        self.assertEqual(planner.lc.events[0]["passing"], "stopped")
        ys_beside = [y for _, x, y, _ in trace if 75.0 < x < 85.0]
        self.assertTrue(ys_beside and max(ys_beside) < -2.5, "beside the stopped car in the right lane")
        self.assertGreater(trace[-1][1], 120.0, "past the car")
        self.assertLess(abs(trace[-1][2]), 0.3, "back in its lane")
        self.assertGreater(closest["stopped"], 3.0)
        res = planner.result()
        self.assertEqual(res["lane_change"], "on")
        self.assertEqual(len(res["lane_changes"]), 2)

    def test_without_lanes_it_stops_behind(self):
        planner, trace, _ = drive([stopped()], 25.0, lanes=False)
        self.assertIsNone(planner.lc)
        self.assertLess(trace[-1][3], 0.1)
        self.assertLess(trace[-1][1], 80.0 - 4.5 / 2 - 1.75 - 2.0)
        self.assertLess(max(abs(y) for _, _, y, _ in trace), 0.05)

    def test_no_lane_beside_the_car_no_change(self):
        planner, trace, _ = drive([stopped()], 25.0, right_to=70.0)
        self.assertEqual(planner.lc.events, [])
        self.assertLess(trace[-1][3], 0.1)

    def test_a_pedestrian_is_not_passed(self):
        walker = {"id": "walker", "class": "pedestrian", "x": 80.0, "y": 0.0, "vx": 0.0,
                  "length": 0.5, "width": 0.5}
        planner, trace, _ = drive([walker], 25.0)
        self.assertEqual(planner.lc.events, [])
        self.assertLess(trace[-1][3], 0.1)

    def test_a_car_just_stopped_is_not_passed_before_pass_after(self):
        planner, _, _ = drive([stopped()], 25.0, params={"PassAfter": 60.0})
        self.assertEqual(planner.lc.events, [])

    def test_waits_for_a_car_in_the_target_lane_then_passes(self):
        # a faster car in the right lane comes from behind: the ego must let it by first
        fast = {"id": "fast", "x": -30.0, "y": -3.5, "vx": 11.0}
        planner, trace, closest = drive([stopped(75.0), fast], 35.0)
        out = [e for e in planner.lc.events if e["kind"] == "out"]
        self.assertEqual(len(out), 1, planner.lc.events)
        t_out = out[0]["t"]
        x_fast = -30.0 + 11.0 * t_out
        x_ego = next(x for t, x, _, _ in trace if t >= t_out)
        self.assertGreater(x_fast - 4.5 / 2, x_ego + 1.75, "it changed lanes only once the car was ahead")
        self.assertGreater(closest["fast"], 3.0)
        self.assertGreater(closest["stopped"], 3.0)
        self.assertGreater(trace[-1][1], 100.0, "then it passed")

    def test_camera_only_input_does_not_change_lanes(self):
        route, rl = road()
        planner = ep.Planner(ep.parse_config({"Input": "detections"}), route, rl)
        self.assertIsNone(planner.lc)
        self.assertIn("sees nothing behind", planner.lane_change)
        # sensor input has the LiDAR's objects all around (tests/unit/test_surround.py)
        self.assertEqual(ep.Planner(ep.parse_config({"Input": "sensors"}), route, rl).lane_change, "on")


class Mobil(unittest.TestCase):
    P = ep.parse_config({})

    def obj(self, s, d, v, oid="o"):
        return {"id": oid, "class": "car", "s": s, "d": d, "v": v, "length": 4.5}

    def test_new_follower_braking_harder_than_b_safe_is_unsafe(self):
        objs = [self.obj(60.0, 0.0, 0.0, "stopped"), self.obj(-8.0, -3.5, 14.0, "fast")]
        cur = lc.lane_neighbours(objs, 0.0, 1.75, 0.0, 1.75, 1.75)
        tgt = lc.lane_neighbours(objs, -3.5, 1.75, 0.0, 1.75, 1.75)
        safe, _ = lc.mobil(self.P, 8.0, 8.333, 3.5, cur, tgt)
        self.assertFalse(safe)
        # the same car 40 m back at the ego's speed can brake gently
        objs[1]["s"], objs[1]["v"] = -40.0, 8.0
        tgt = lc.lane_neighbours(objs, -3.5, 1.75, 0.0, 1.75, 1.75)
        safe, gain = lc.mobil(self.P, 8.0, 8.333, 3.5, cur, tgt)
        self.assertTrue(safe)
        self.assertGreater(gain, self.P["ChangeThreshold"])

    def test_a_car_beside_blocks(self):
        objs = [self.obj(1.0, -3.5, 8.0, "beside")]
        tgt = lc.lane_neighbours(objs, -3.5, 1.75, 0.0, 1.75, 1.75)
        self.assertTrue(tgt[2])
        safe, _ = lc.mobil(self.P, 8.0, 8.333, 3.5, lc.lane_neighbours([], 0.0, 1.75, 0.0, 1.75, 1.75), tgt)
        self.assertFalse(safe)

    def test_idm_free_road_and_standstill(self):
        self.assertAlmostEqual(lc.idm(self.P, 0.0, 8.333), self.P["MaxAcceleration"])
        self.assertLess(lc.idm(self.P, 8.0, 8.333, 5.0, 0.0), -self.P["SafeDeceleration"])

    def test_manoeuvre_offset_is_a_half_cosine(self):
        m = lc.Manoeuvre(10.0, 30.0, 0.0, -3.5)
        self.assertEqual(m.offset(5.0), 0.0)
        self.assertAlmostEqual(m.offset(20.0), -1.75)
        self.assertEqual(m.offset(31.0), -3.5)

    def test_route_lanes_availability(self):
        _, rl = road(right_from=50.0, right_to=150.0)
        self.assertEqual(rl.sides(100.0), [("right", -3.5)])
        self.assertEqual(rl.sides(20.0), [])
        self.assertTrue(rl.available(-3.5, 60.0, 140.0))
        self.assertFalse(rl.available(-3.5, 40.0, 140.0))
        self.assertFalse(rl.available(3.5, 60.0, 140.0))


class Flow(unittest.TestCase):
    def changer(self, limits=None, params=None):
        route, rl = road()
        if limits is not None:
            rl = RouteLanes(route, rl._sides, [limits] * len(route.points))
        cfg = {"CruiseSpeed": 8.333}
        cfg.update(params or {})
        return lc.LaneChanger(ep.parse_config(cfg), route, rl)

    def objs(self, *cars):
        return [{"id": "c%d" % i, "class": k, "s": s, "d": d, "v": v, "length": 4.5, "width": 1.8}
                for i, (k, s, d, v) in enumerate(cars)]

    EGO = {"length": 3.5, "length_offset": 0.0}

    def test_faster_traffic_ahead_raises_the_cruise_speed_up_to_the_limit(self):
        c = self.changer(limits=50 / 3.6)
        self.assertAlmostEqual(c.flow_speed(self.EGO, 100.0, self.objs(("car", 130.0, -3.5, 12.0))), 12.0)
        self.assertAlmostEqual(c.flow_speed(self.EGO, 100.0, self.objs(("car", 130.0, 0.0, 20.0))), 50 / 3.6)
        c = self.changer(limits=10.0)
        self.assertAlmostEqual(c.flow_speed(self.EGO, 100.0, self.objs(("car", 130.0, 0.0, 20.0))), 10.0)

    def test_slower_oncoming_far_behind_or_pedestrians_do_not(self):
        c = self.changer()
        for cars in [(("car", 130.0, 0.0, 5.0),), (("car", 130.0, 3.5, -12.0),), (("car", 130.0, 7.0, 12.0),),
                     (("car", 60.0, 0.0, 12.0),), (("car", 200.0, 0.0, 12.0),), (("pedestrian", 110.0, 0.0, 12.0),)]:
            self.assertAlmostEqual(c.flow_speed(self.EGO, 100.0, self.objs(*cars)), 8.333, msg=cars)

    def test_off_by_parameter(self):
        c = self.changer(params={"FollowFlow": 0})
        self.assertAlmostEqual(c.flow_speed(self.EGO, 100.0, self.objs(("car", 130.0, 0.0, 12.0))), 8.333)


REPO = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")


def odr_module():
    try:
        from convoy_scenario.roads import load_module
        load_module()
        return True
    except Exception:  # the OpenDRIVE module is built with Convoy (build/python)
        return False


@unittest.skipUnless(odr_module(), "the OpenDRIVE module _convoy_odr is not built")
class FromMap(unittest.TestCase):
    def test_the_city_roads_neighbour_lanes_and_limits(self):
        from convoy_scenario.roads import RoadMap
        xodr = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")
        # road 1's lane -1 eastbound (y = -1.75) from x = -200 through junction 100 (x = 0)
        route = RoutePath([(float(x), -1.75) for x in range(-200, 61, 2)])
        rl = RouteLanes.from_map(route, RoadMap.open(xodr), xodr)
        # lane -2 (y = -5.25) beside it, the same way; lane 1 on the left is the other way
        self.assertEqual([k for k, _ in rl.sides(50.0)], ["right"])
        self.assertAlmostEqual(rl.sides(50.0)[0][1], -3.5, places=3)
        self.assertEqual(rl.sides(200.0), [], "no lane change inside junction 100")
        self.assertTrue(rl.available(-3.5, 0.0, 150.0))
        self.assertFalse(rl.available(-3.5, 150.0, 230.0))
        self.assertAlmostEqual(rl.speed_limit(50.0), 50 / 3.6, places=3)


if __name__ == "__main__":
    unittest.main()
