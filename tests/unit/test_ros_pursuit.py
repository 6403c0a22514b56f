"""Unit tests of convoy_ros.pursuit (no ROS needed): the route's search and look-ahead, the
pure pursuit angle, the pedals, and a closed loop of the controller on a kinematic bicycle
that must follow a circle and a straight line.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_ros_pursuit"""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from convoy_ros.control import MAX_STEER, WHEELBASE, ControlModel  # noqa: E402
from convoy_ros.pursuit import (PurePursuit, Route, curve_speed, pedals,  # noqa: E402
                                pursuit_steer, yaw_of_quaternion)


def circle(radius, n=200):
    return [(radius * math.cos(2 * math.pi * i / n), radius * math.sin(2 * math.pi * i / n))
            for i in range(n)]


class RouteTest(unittest.TestCase):
    def test_closed_when_the_ends_meet(self):
        self.assertTrue(Route(circle(20)).closed)
        self.assertFalse(Route([(0, 0), (10, 0), (20, 0)]).closed)
        with self.assertRaises(ValueError):
            Route([(0, 0)])

    def test_nearest_searches_forward_and_wraps(self):
        r = Route(circle(20, 100))
        self.assertEqual(r.nearest(20, 0, 0, 99), 0)
        i = r.nearest(20, 0.1, 95)  # past the end of the list: unwrapped index
        self.assertEqual(i, 100)
        self.assertEqual(r.point(i), r.point(0))

    def test_ahead_interpolates_and_stops_at_an_open_end(self):
        r = Route([(0, 0), (10, 0), (10, 10)])
        self.assertEqual(r.ahead(0, 4.0), (4.0, 0.0))
        self.assertEqual(r.ahead(0, 15.0), (10.0, 5.0))
        self.assertEqual(r.ahead(0, 100.0), (10.0, 10.0))


class Geometry(unittest.TestCase):
    def test_yaw_of_quaternion(self):
        a = 0.7
        self.assertAlmostEqual(yaw_of_quaternion(0, 0, math.sin(a / 2), math.cos(a / 2)), a)

    def test_pursuit_steer(self):
        self.assertEqual(pursuit_steer(0, 0, 0, 5, 0), 0.0)
        left = pursuit_steer(0, 0, 0, 5, 1)
        self.assertGreater(left, 0)
        # the circle through the target: curvature 2 sin(alpha) / d
        alpha, d = math.atan2(1, 5), math.hypot(5, 1)
        self.assertAlmostEqual(left, math.atan(2 * WHEELBASE * math.sin(alpha) / d))
        self.assertEqual(pursuit_steer(0, 0, 0, -5, -0.1), -MAX_STEER)

    def test_pedals_and_curve_speed(self):
        self.assertEqual(pedals(0.0, 7.0, 0.02), (1.0, 0.0))
        self.assertEqual(pedals(7.0, 7.0, 0.02), (0.0, 0.0))
        self.assertEqual(pedals(8.0, 7.0, 0.02), (0.0, 1.0))
        # the last bit exactly: 0.03 m/s in 0.02 s at A_MAX = 3 is half throttle
        self.assertAlmostEqual(pedals(6.97, 7.0, 0.02)[0], 0.5)
        self.assertEqual(pedals(3.0, 7.0, 0.0), (0.0, 0.0))
        self.assertEqual(curve_speed(0.0, 7.0), 7.0)
        v = curve_speed(0.3, 20.0)
        self.assertAlmostEqual(v * v * math.tan(0.3) / WHEELBASE, 3.0)


def drive(route, steps, dt=0.02, start=(0.0, 0.0, 0.0), target=6.0):
    """The controller on a kinematic bicycle through ControlModel: the path of base_link."""
    driver, model = PurePursuit(route, target), ControlModel(dt)
    x, y, yaw = start
    v, path = 0.0, []
    for k in range(steps):
        throttle, brake, steer = driver.step(x, y, yaw, v, dt)
        v, steer = model.update({"stamp": (k + 1) * dt, "throttle": throttle, "brake": brake,
                                 "steer": steer})
        # base_link is mid-axle: advance the rear axle, then place base_link ahead of it
        rx, ry = x - 0.5 * WHEELBASE * math.cos(yaw), y - 0.5 * WHEELBASE * math.sin(yaw)
        rx, ry = rx + v * math.cos(yaw) * dt, ry + v * math.sin(yaw) * dt
        yaw += v * math.tan(steer) / WHEELBASE * dt
        x, y = rx + 0.5 * WHEELBASE * math.cos(yaw), ry + 0.5 * WHEELBASE * math.sin(yaw)
        path.append((x, y, v))
    return driver, path


class ClosedLoop(unittest.TestCase):
    def test_follows_a_circle_at_the_speed(self):
        r = 25.0
        driver, path = drive(Route(circle(r)), 3000, start=(r, 0.0, math.pi / 2))
        errors = [abs(math.hypot(x, y) - r) for x, y, _ in path[500:]]
        self.assertLess(max(errors), 0.6)
        self.assertAlmostEqual(path[-1][2], 6.0, delta=0.3)
        self.assertLessEqual(max(v for _, _, v in path), 6.0 + 1e-9)  # no overshoot
        self.assertGreater(driver.index, 200)  # more than a lap (unwrapped index)

    def test_reaches_a_line_and_stops_at_its_end(self):
        route = Route([(float(i), 2.0) for i in range(0, 80, 2)])
        driver, path = drive(route, 2500)
        self.assertTrue(driver.finished)
        self.assertLess(abs(path[-1][1] - 2.0), 0.2)
        self.assertLess(abs(path[-1][2]), 0.05)
        self.assertTrue(all(abs(y - 2.0) < 0.3 for x, y, _ in path if x > 30))


if __name__ == "__main__":
    unittest.main()
