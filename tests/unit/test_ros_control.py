"""Unit tests of convoy_ros.control (no ROS needed): the longitudinal model's integration,
clamps and brake, the stamp bookkeeping of ControlModel, the Twist mapping and the joints.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_ros_control"""
import math
import os
import sys
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from convoy_ros import control  # noqa: E402
from convoy_ros.control import (A_MAX, B_MAX, MAX_STEER, V_MAX, V_REVERSE, WHEELBASE,  # noqa: E402
                                ControlModel, integrate_speed, joint_targets, twist_to_drive)


class IntegrateSpeed(unittest.TestCase):
    def test_throttle_accelerates_by_a_max(self):
        self.assertAlmostEqual(integrate_speed(0.0, 1.0, 0.0, False, 0.5), 0.5 * A_MAX)
        self.assertAlmostEqual(integrate_speed(2.0, 0.5, 0.0, False, 0.2), 2.0 + 0.1 * A_MAX)

    def test_no_pedal_holds_the_speed(self):
        self.assertEqual(integrate_speed(4.0, 0.0, 0.0, False, 1.0), 4.0)

    def test_brake_slows_to_standstill_never_past(self):
        self.assertAlmostEqual(integrate_speed(5.0, 0.0, 0.5, False, 0.1), 5.0 - 0.05 * B_MAX)
        self.assertEqual(integrate_speed(0.2, 0.0, 1.0, False, 1.0), 0.0)
        self.assertEqual(integrate_speed(-0.2, 0.0, 1.0, True, 1.0), 0.0)
        self.assertEqual(integrate_speed(0.0, 0.0, 1.0, False, 1.0), 0.0)

    def test_brake_wins_over_throttle(self):
        self.assertLess(integrate_speed(5.0, 1.0, 1.0, False, 0.1), 5.0)

    def test_reverse_accelerates_backwards(self):
        self.assertAlmostEqual(integrate_speed(0.0, 1.0, 0.0, True, 0.5), -0.5 * A_MAX)
        # braking while rolling backwards slows towards 0 too
        self.assertAlmostEqual(integrate_speed(-2.0, 0.0, 0.1, True, 1.0), -2.0 + 0.1 * B_MAX)

    def test_clamped_to_the_limits(self):
        self.assertEqual(integrate_speed(V_MAX, 1.0, 0.0, False, 10.0), V_MAX)
        self.assertEqual(integrate_speed(0.0, 1.0, 0.0, True, 100.0), -V_REVERSE)
        # pedals outside [0, 1] count as their nearest bound, a negative dt as 0
        self.assertAlmostEqual(integrate_speed(0.0, 7.0, -3.0, False, 0.1), 0.1 * A_MAX)
        self.assertEqual(integrate_speed(3.0, 1.0, 0.0, False, -1.0), 3.0)


class Model(unittest.TestCase):
    def msg(self, stamp, throttle=1.0, brake=0.0, steer=0.0, reverse=False):
        return {"stamp": stamp, "throttle": throttle, "brake": brake, "steer": steer,
                "reverse": reverse}

    def test_integrates_over_the_time_between_stamps(self):
        m = ControlModel(step_dt=0.02)
        self.assertAlmostEqual(m.update(self.msg(1.0))[0], 0.02 * A_MAX)  # first: step_dt
        self.assertAlmostEqual(m.update(self.msg(1.1))[0], 0.12 * A_MAX)
        self.assertAlmostEqual(m.update(self.msg(1.5))[0], 0.52 * A_MAX)

    def test_the_same_message_again_is_not_integrated(self):
        m = ControlModel()
        m.update(self.msg(1.0))
        v = m.update(self.msg(1.2))[0]
        self.assertEqual(m.update(self.msg(1.2))[0], v)
        self.assertEqual(m.update(self.msg(1.1))[0], v)  # older: held too

    def test_unstamped_messages_count_one_step_each(self):
        m = ControlModel(step_dt=0.05)
        for _ in range(4):
            v, _ = m.update(self.msg(0.0))
        self.assertAlmostEqual(v, 4 * 0.05 * A_MAX)

    def test_steer_clamped_and_missing_keys_are_zero(self):
        m = ControlModel()
        self.assertEqual(m.update(self.msg(0.1, steer=2.0))[1], MAX_STEER)
        self.assertEqual(m.update(self.msg(0.2, steer=-2.0))[1], -MAX_STEER)
        self.assertEqual(m.update({"stamp": 0.3}), (m.speed, 0.0))


class Twist(unittest.TestCase):
    def test_speed_and_bicycle_steer(self):
        v, steer = twist_to_drive({"linear": [5.0, 0, 0], "angular": [0, 0, 0.5]})
        self.assertEqual(v, 5.0)
        self.assertAlmostEqual(steer, math.atan(WHEELBASE * 0.5 / 5.0))

    def test_slow_speeds_steer_as_at_half_a_metre_per_second(self):
        _, steer = twist_to_drive({"linear": [0.0, 0, 0], "angular": [0, 0, 0.1]})
        self.assertAlmostEqual(steer, math.atan(WHEELBASE * 0.1 / 0.5))
        _, steer = twist_to_drive({"linear": [-0.2, 0, 0], "angular": [0, 0, -0.1]})
        self.assertAlmostEqual(steer, -math.atan(WHEELBASE * 0.1 / 0.5))

    def test_clamped(self):
        v, steer = twist_to_drive({"linear": [100.0, 0, 0], "angular": [0, 0, 100.0]})
        self.assertEqual((v, steer), (V_MAX, MAX_STEER))
        v, _ = twist_to_drive({"linear": [-100.0, 0, 0], "angular": [0, 0, 0]})
        self.assertEqual(v, -V_REVERSE)


class Joints(unittest.TestCase):
    def test_the_smart_cars_four_joints(self):
        j = joint_targets(6.0, 0.3)
        p = "smart_car_joint_plugin::"
        self.assertEqual(j, {p + "front_left_steering_joint": ("position", 0.3),
                             p + "front_right_steering_joint": ("position", 0.3),
                             p + "rear_left_wheel_joint": ("velocity", 6.0 / 0.3),
                             p + "rear_right_wheel_joint": ("velocity", 6.0 / 0.3)})
        self.assertEqual(control.WHEEL_RADIUS, 0.3)

    def test_steer_clamped(self):
        j = joint_targets(0.0, -1.0)
        self.assertEqual(j["smart_car_joint_plugin::front_left_steering_joint"],
                         ("position", -MAX_STEER))


if __name__ == "__main__":
    unittest.main()
