"""Unit tests of python/convoy_traffic/route_path.py and the ego planner's route path
(issue 27: the planner's path follows the route ahead, not the ego's curvature)."""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from convoy_traffic import ego_planner as ep  # noqa: E402
from convoy_traffic.route_path import RoutePath  # noqa: E402

EGO = {"id": "ego", "x": 0.0, "y": 0.0, "yaw": 0.0, "speed": 8.0, "yaw_rate": 0.0,
       "length": 4.0, "width": 1.8, "length_offset": 0.0}


def car(x, y, vx=0.0, vy=0.0, cid="c"):
    """A car 4.5 x 1.8 aligned with +x at world (x, y): the ego is at the origin facing +x, so
    world and ego frames agree."""
    return {"id": cid, "class": "car", "lon": x, "lat": y, "length": 4.5, "width": 1.8,
            "v_lon": vx, "v_lat": vy, "source": "ground_truth"}


def lane_change_route():
    """Straight along y = 0, then over to y = 3.5 between x = 20 and 40, then straight."""
    return RoutePath([(-10, 0), (20, 0), (40, 3.5), (120, 3.5)])


class Path(unittest.TestCase):
    def test_locate_gives_arc_length_and_signed_offset(self):
        r = RoutePath([(0, 0), (10, 0), (10, 10)])
        self.assertEqual(r.length, 20.0)
        s, d = r.locate(5, 1)
        self.assertAlmostEqual(s, 5)
        self.assertAlmostEqual(d, 1)  # left of +x
        s, d = r.locate(11, 5)
        self.assertAlmostEqual(s, 15)
        self.assertAlmostEqual(d, -1)  # right of +y
        self.assertAlmostEqual(r.heading(15), math.pi / 2)

    def test_a_loop_is_read_at_the_pass_asked_for(self):
        r = RoutePath([(0, 0), (10, 0), (10, 10), (0, 10), (0, 0), (10, 0)])
        s, _ = r.locate(5, 0)
        self.assertAlmostEqual(s, 5)
        s, _ = r.locate(5, 0, 30, 50)
        self.assertAlmostEqual(s, 45)

    def test_too_few_points(self):
        with self.assertRaises(ValueError):
            RoutePath([(1, 1), (1, 1)])


class PlannerOnTheRoute(unittest.TestCase):
    def planner(self, route):
        return ep.Planner(ep.parse_config({"Input": "ground_truth"}), route)

    def test_a_car_the_route_passes_is_not_in_the_path(self):
        stopped = car(50, 0)  # in the ego's lane, but the route has moved over by then
        self.assertTrue(self.planner(None).in_path(EGO, stopped)[0])  # the old corridor
        self.assertFalse(self.planner(lane_change_route()).in_path(EGO, stopped)[0])

    def test_a_car_on_the_route_is_in_the_path_with_its_gap_along_it(self):
        ok, gap = self.planner(lane_change_route()).in_path(EGO, car(60, 3.5))
        self.assertTrue(ok)
        along = 20 + math.hypot(20, 3.5) + 20  # route length from the ego to the car
        self.assertAlmostEqual(gap, along - 2.25 - 2.0, places=6)

    def test_a_car_on_the_route_around_a_bend(self):
        # a left bend of radius 30 m starting at the ego; a car on it 40 m along
        pts = [(30 * math.sin(a / 100), 30 - 30 * math.cos(a / 100)) for a in range(0, 160)]
        route = RoutePath(pts)
        a = 40 / 30
        on_bend = car(30 * math.sin(a), 30 - 30 * math.cos(a))
        on_bend["lon"], on_bend["lat"] = 30 * math.sin(a), 30 - 30 * math.cos(a)
        self.assertFalse(self.planner(None).in_path(EGO, on_bend)[0])  # straight ahead: no
        self.assertTrue(self.planner(route).in_path(EGO, on_bend)[0])
        # and scenery beside the bend's outside stays out
        outside = car(30 * math.sin(a) * 1.2, (30 - 30 * math.cos(a)) - 6)
        self.assertFalse(self.planner(route).in_path(EGO, outside)[0])

    def test_near_field_uses_the_egos_heading(self):
        # 3 m ahead in the ego's lane while the route already bends away: still in the path
        route = RoutePath([(0, 0), (1, 0), (2, 4), (2, 40)])
        self.assertTrue(self.planner(route).in_path(EGO, car(7, 0))[0])

    def test_crossing_towards_the_route(self):
        pl = self.planner(lane_change_route())
        walker = {"id": "w", "class": "pedestrian", "lon": 60, "lat": 7.0, "length": 0.5,
                  "width": 0.5, "v_lon": 0.0, "v_lat": -1.5, "source": "ground_truth"}
        self.assertTrue(pl.in_path(EGO, walker)[0])  # 3.5 m left of the route, stepping in
        walker["v_lat"] = 1.5
        self.assertFalse(pl.in_path(EGO, walker)[0])  # walking away

    def test_result_says_which_path(self):
        self.assertEqual(self.planner(lane_change_route()).result()["path"], "route")
        self.assertEqual(self.planner(None).result()["path"], "curvature")


if __name__ == "__main__":
    unittest.main()
