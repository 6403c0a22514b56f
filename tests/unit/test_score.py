"""Unit tests of convoy_bench (docs/scoring.md): the CARLA Leaderboard 2.0 driving score and the
nuPlan-style score against hand-computed values, the map lookups, and a synthetic city_traffic
run folder through the CLI.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_score
(ctest: py_score)."""

import json
import math
import os
import random
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PYTHON_DIR = os.path.join(REPO, "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)

from convoy_bench import nuplan, road_map, runs  # noqa: E402
from convoy_bench import score as sc  # noqa: E402

ROUTE = {"points": [[0.0, 0.0], [50.0, 0.0], [100.0, 0.0]]}  # 100 m along x


def straight(x_end, step=0.5, dt=0.05, speed=10.0, **flags):
    """Samples along the x axis from 0 to x_end every `step` m."""
    n = int(round(x_end / step))
    return [dict({"t": dt * k, "x": step * k, "y": 0.0, "yaw": 0.0, "speed": speed}, **flags)
            for k in range(n + 1)]


def drive(speed_fn, yaw_fn, T, dt):
    """Samples of a drive with speed(t) and yaw(t), positions integrated (Euler)."""
    n = int(round(T / dt))
    out, x, y = [], 0.0, 0.0
    for k in range(n + 1):
        t = k * dt
        v, yaw = speed_fn(t), yaw_fn(t)
        out.append({"t": t, "x": x, "y": y, "yaw": yaw, "speed": v})
        x += v * math.cos(yaw) * dt
        y += v * math.sin(yaw) * dt
    return out


def ev(t, kind, other=None, **extra):
    return dict({"t": t, "kind": kind, "other": other}, **extra)


class CarlaDrivingScore(unittest.TestCase):
    def test_no_infractions_ds_equals_rc(self):
        r = sc.score_drive(straight(80.0), ROUTE)
        self.assertEqual(r["route_completion"], 80.0)
        self.assertEqual(r["infraction_penalty"], 1.0)
        self.assertEqual(r["driving_score"], r["route_completion"])
        self.assertEqual(r["infractions"], [])
        self.assertFalse(r["route_finished"])

    def test_collisions_and_red_light(self):
        events = [ev(1.0, "collision_pedestrian", "ped_0"), ev(2.0, "collision_vehicle", "car_1"),
                  ev(3.0, "collision_vehicle", "car_2"), ev(3.5, "red_light", "4")]
        r = sc.score_drive(straight(80.0), ROUTE, events)
        self.assertEqual(r["route_completion"], 80.0)
        self.assertEqual(r["infraction_penalty"], 0.5 * 0.6 * 0.6 * 0.7)
        self.assertEqual(r["driving_score"], 80 * (0.5 * 0.6 * 0.6 * 0.7))
        self.assertAlmostEqual(r["driving_score"], 10.08, places=12)
        self.assertEqual([(i["kind"], i["penalty"]) for i in r["infractions"]],
                         [("collision_pedestrian", 0.5), ("collision_vehicle", 0.6),
                          ("collision_vehicle", 0.6), ("red_light", 0.7)])

    def test_same_other_twice_counts_twice(self):
        events = [ev(1.0, "collision_vehicle", "car_1"), ev(1.2, "collision_vehicle", "car_1")]
        r = sc.score_drive(straight(80.0), ROUTE, events)
        self.assertEqual(r["infraction_penalty"], 0.6 * 0.6)

    def test_every_fixed_penalty(self):
        for kind, p in (("collision_static", 0.65), ("stop_sign", 0.8), ("scenario_timeout", 0.7),
                        ("yield_emergency", 0.7), ("red_light", 0.7)):
            r = sc.score_drive(straight(80.0), ROUTE, [ev(1.0, kind)])
            self.assertEqual(r["infraction_penalty"], p, kind)
            self.assertEqual(r["driving_score"], 80.0 * p, kind)

    def test_scenario_timeout(self):
        r = sc.score_drive(straight(60.0), ROUTE, [ev(2.0, "scenario_timeout")])
        self.assertEqual(r["route_completion"], 60.0)
        self.assertEqual(r["driving_score"], 60.0 * 0.7)
        self.assertEqual(r["infractions"][0]["penalty"], 0.7)

    def test_min_speed_60_percent(self):
        r = sc.score_drive(straight(80.0), ROUTE, [ev(2.0, "min_speed", percentage=60.0)])
        self.assertAlmostEqual(r["infraction_penalty"], 0.88, places=15)
        self.assertEqual(r["infraction_penalty"], 1 - 0.3 * (1 - 60.0 / 100))
        self.assertEqual(r["infractions"][0]["percentage"], 60.0)
        self.assertEqual(sc.infraction_factor({"kind": "min_speed", "percentage": 120.0}), 1.0)

    def test_min_speed_computed_from_traffic(self):
        # 6 m/s against traffic at 10 m/s, 0.3 m per sample: checkpoints close at s = 25.2,
        # 50.4, 75.6 (more than 25 m past the last) and at the end (s / L > 0.95): four at 60 %.
        traj = straight(100.0, step=0.3, dt=0.05, speed=6.0)
        for s in traj:
            s["traffic_speed"] = 10.0
        r = sc.score_drive(traj, ROUTE)
        mins = [i for i in r["infractions"] if i["kind"] == "min_speed"]
        self.assertEqual([i["percentage"] for i in mins], [60.0] * 4)
        self.assertEqual([i["t"] for i in mins[:3]], [traj[84]["t"], traj[168]["t"], traj[252]["t"]])
        f = 1 - 0.3 * (1 - 0.6)
        self.assertEqual(r["infraction_penalty"], f * f * f * f)
        self.assertTrue(r["route_finished"])
        self.assertEqual(r["route_completion"], 100.0)

    def test_off_route_reduces_rc(self):
        traj = straight(100.0)
        for s in traj:
            if 20.0 < s["x"] <= 40.0:
                s["on_route"] = False
        r = sc.score_drive(traj, ROUTE)
        self.assertTrue(r["route_finished"])
        self.assertEqual(r["route_completion_raw"], 100.0)
        self.assertEqual(r["off_route_m"], 20.0)
        self.assertEqual(r["off_route_percentage"], 20.0)
        self.assertEqual(r["route_completion"], 80.0)
        self.assertEqual(r["driving_score"], 80.0)
        self.assertEqual(r["infraction_penalty"], 1.0)
        off = [i for i in r["infractions"] if i["kind"] == "off_route"]
        self.assertEqual(len(off), 1)
        self.assertEqual((off[0]["distance_m"], off[0]["penalty"], off[0]["t"]), (20.0, 1.0, traj[41]["t"]))

    def test_off_route_unfinished_is_route_length_in_lanes(self):
        traj = straight(60.0)
        for s in traj:
            if 10.0 < s["x"] <= 20.0:
                s["on_road"] = False
        r = sc.score_drive(traj, ROUTE)
        self.assertAlmostEqual(r["route_completion"], 100.0 * (60.0 - 10.0) / 100.0, places=12)
        self.assertEqual([i["kind"] for i in r["infractions"]], ["off_road"])
        self.assertEqual(r["nuplan_score"]["multipliers"]["drivable_area_compliance"], 0.0)

    def test_off_route_event_distance(self):
        r = sc.score_drive(straight(60.0), ROUTE, [ev(1.0, "off_route", distance_m=15.0)])
        self.assertAlmostEqual(r["route_completion"], 45.0, places=12)
        self.assertEqual(r["off_route_m"], 15.0)

    def test_wrong_way_is_outside_route_lanes(self):
        traj = straight(50.0)
        for s in traj:
            if s["x"] > 40.0:
                s["wrong_way"] = True
        r = sc.score_drive(traj, ROUTE)
        self.assertAlmostEqual(r["route_completion"], 40.0, places=12)
        self.assertEqual([i["kind"] for i in r["infractions"]], ["wrong_way"])

    def test_agent_blocked_ends_the_route(self):
        traj = [{"t": 0.5 * k, "x": 2.0 * k, "y": 0.0, "yaw": 0.0, "speed": 4.0} for k in range(16)]
        t0 = traj[-1]["t"]
        traj += [{"t": t0 + k, "x": 30.0, "y": 0.0, "yaw": 0.0, "speed": 0.0} for k in range(1, 201)]
        t1 = traj[-1]["t"]
        traj += [{"t": t1 + 0.5 * k, "x": 30.0 + 2.0 * k, "y": 0.0, "yaw": 0.0, "speed": 4.0} for k in range(1, 36)]
        r = sc.score_drive(traj, ROUTE, [ev(t0 + 100.0, "collision_vehicle", "car_9")])
        self.assertEqual(r["route_ended_at"], t0 + 181.0)  # first sample >= 180 s below 0.1 m/s
        self.assertEqual(r["route_completion"], 30.0)
        blocked = [i for i in r["infractions"] if i["kind"] == "agent_blocked"]
        self.assertEqual((len(blocked), blocked[0]["penalty"]), (1, 1.0))
        # a collision while the ego stands still is not its fault (CARLA's CollisionTest)
        hit = [i for i in r["infractions"] if i["kind"] == "collision_vehicle"][0]
        self.assertEqual((hit["counted"], hit["penalty"]), (False, 1.0))
        self.assertEqual(r["driving_score"], 30.0)

    def test_progress_does_not_go_back(self):
        traj = straight(50.0) + [{"t": 10.0 + k, "x": 50.0 - 5.0 * k, "y": 0.0, "yaw": math.pi, "speed": 5.0}
                                 for k in range(1, 5)]
        r = sc.score_drive(traj, ROUTE)
        self.assertEqual(r["route_completion"], 50.0)
        self.assertEqual(r["nuplan_score"]["ego_progress_m"], 30.0)

    def test_far_from_route_makes_no_progress(self):
        traj = [{"t": float(k), "x": 10.0 * k, "y": 40.0, "yaw": 0.0, "speed": 10.0} for k in range(8)]
        r = sc.score_drive(traj, ROUTE)
        self.assertEqual(r["route_completion"], 0.0)

    def test_determinism(self):
        traj = straight(100.0, step=0.3, speed=6.0)
        for i, s in enumerate(traj):
            s["traffic_speed"] = 7.0 + 0.01 * (i % 7)
            s["speed_limit"] = 5.5
            s["on_route"] = not (30.0 < s["x"] < 37.0)
        events = [ev(1.0 + 0.1 * k, kind, "o%d" % k) for k, kind in enumerate(
            ["collision_vehicle", "red_light", "collision_static", "stop_sign", "collision_pedestrian",
             "scenario_timeout", "yield_emergency"])] + [ev(2.0, "min_speed", percentage=73.3)]
        a = sc.score_drive(traj, ROUTE, events)
        b = sc.score_drive([dict(s) for s in traj], ROUTE, [dict(e) for e in events])
        self.assertEqual(json.dumps(a), json.dumps(b))
        rng = random.Random(7)
        for _ in range(5):
            shuffled = list(events)
            rng.shuffle(shuffled)
            c = sc.score_drive(traj, ROUTE, shuffled)
            self.assertEqual(c["driving_score"].hex(), a["driving_score"].hex())
            self.assertEqual(c["nuplan_score"]["score"].hex(), a["nuplan_score"]["score"].hex())
            self.assertEqual(json.dumps(c), json.dumps(a))

    def test_bad_inputs(self):
        with self.assertRaises(ValueError):
            sc.score_drive(straight(10.0)[:1], ROUTE)
        with self.assertRaises(ValueError):
            sc.score_drive(straight(10.0), ROUTE, [ev(1.0, "speeding")])
        with self.assertRaises(ValueError):
            sc.score_drive(list(reversed(straight(10.0))), ROUTE)
        with self.assertRaises(ValueError):
            sc.score_drive(straight(10.0), {"points": [[0, 0]]})
        with self.assertRaises(ValueError):
            sc.score_drive(straight(10.0), dict(ROUTE, length=90.0))
        self.assertEqual(sc.score_drive(straight(10.0), dict(ROUTE, length=100.0))["route_length_m"], 100.0)


class NuplanComfort(unittest.TestCase):
    def check(self, traj, metric, inside):
        metrics, ok = nuplan.comfort([s["t"] for s in traj], [s["speed"] for s in traj], [s["yaw"] for s in traj])
        self.assertEqual(metrics[metric]["within_bound"], inside, (metric, metrics[metric]))
        others = [k for k, v in metrics.items() if k != metric and not v["within_bound"]]
        self.assertEqual(others, [], metrics)
        self.assertEqual(ok, inside)
        r = sc.score_drive(traj, {"points": [[-1.0, 0.0], [200.0, 0.0]]})
        self.assertEqual(r["nuplan_score"]["weighted"]["ego_is_comfortable"], 1.0 if inside else 0.0)

    def test_lon_acceleration(self):
        for a, inside in ((2.39, True), (2.41, False)):
            traj = drive(lambda t: 2.0 + a * t, lambda t: 0.0, 2.0, 0.05)
            self.check(traj, "lon_acceleration", inside)
            metrics, _ = nuplan.comfort([s["t"] for s in traj], [s["speed"] for s in traj], [0.0] * len(traj))
            self.assertAlmostEqual(metrics["lon_acceleration"]["max"], a, places=9)

    def test_lon_deceleration(self):
        for a, inside in ((-4.04, True), (-4.06, False)):
            self.check(drive(lambda t: 12.0 + a * t, lambda t: 0.0, 2.0, 0.05), "lon_acceleration", inside)

    def test_lat_acceleration(self):
        for v, inside in ((5.4, True), (5.5, False)):  # 0.9 rad/s: 4.86 and 4.95 m/s2
            self.check(drive(lambda t: v, lambda t: 0.9 * t, 2.0, 0.05), "lat_acceleration", inside)

    def test_lon_jerk(self):
        for j, inside in ((4.12, True), (4.14, False)):
            self.check(drive(lambda t: 5.0 - 2.0 * t + 0.5 * j * t * t, lambda t: 0.0, 1.0, 0.05), "lon_jerk", inside)

    def test_jerk_magnitude(self):
        # lateral acceleration 5 m/s x (0.02 + alpha t): its rate 5 alpha = 8.3 and 8.45 m/s3
        for alpha, inside in ((1.66, True), (1.69, False)):
            self.check(drive(lambda t: 5.0, lambda t: 0.02 * t + 0.5 * alpha * t * t, 0.52, 0.02), "jerk", inside)

    def test_yaw_rate(self):
        for w, inside in ((0.94, True), (0.96, False)):
            self.check(drive(lambda t: 1.0, lambda t: w * t, 2.0, 0.05), "yaw_rate", inside)

    def test_yaw_acceleration(self):
        for alpha, inside in ((1.92, True), (1.94, False)):
            self.check(drive(lambda t: 1.0, lambda t: -0.85 * t + 0.5 * alpha * t * t, 0.9, 0.05),
                       "yaw_acceleration", inside)

    def test_savgol_matches_polynomials(self):
        t = [0.1 * k for k in range(30)]
        y = [1.0 + 2.0 * x - 3.0 * x * x for x in t]
        d = nuplan.savgol(y, 9, 2, 1, 0.1)
        for x, v in zip(t, d):
            self.assertAlmostEqual(v, 2.0 - 6.0 * x, places=9)
        self.assertEqual(nuplan.window_samples(0.7, 0.1, 100), 9)
        self.assertEqual(nuplan.window_samples(1.4, 0.05, 100), 29)
        self.assertEqual(nuplan.window_samples(1.4, 0.05, 20), 19)


class NuplanCollisions(unittest.TestCase):
    EGO = {"x": 10.0, "y": 0.0, "yaw": 0.0, "speed": 5.0, "length": 4.5, "width": 1.8, "length_offset": 0.0}

    def car(self, x, y, speed, yaw=0.0):
        return {"class": "car", "x": x, "y": y, "yaw": yaw, "speed": speed, "length": 4.5, "width": 1.8}

    def test_types(self):
        ego = self.EGO
        self.assertEqual(nuplan.collision_type(dict(ego, speed=0.0), self.car(14.0, 0.0, 3.0)), "stopped_ego")
        self.assertEqual(nuplan.collision_type(ego, self.car(6.8, 0.0, 8.0)), "active_rear")
        self.assertEqual(nuplan.collision_type(ego, self.car(14.0, 0.0, 2.0)), "active_front")
        self.assertEqual(nuplan.collision_type(ego, self.car(14.0, 0.0, 0.0)), "stopped_track")
        self.assertEqual(nuplan.collision_type(ego, self.car(9.0, 1.7, 5.0)), "active_lateral")
        self.assertEqual(nuplan.collision_type(ego, None, static=True), "stopped_track")
        self.assertEqual(nuplan.collision_type(ego, None), "unknown")
        self.assertFalse(nuplan.is_at_fault("stopped_ego", True))
        self.assertFalse(nuplan.is_at_fault("active_rear", True))
        self.assertFalse(nuplan.is_at_fault("active_lateral", False))
        self.assertTrue(nuplan.is_at_fault("active_lateral", True))
        self.assertTrue(nuplan.is_at_fault("active_front", False))
        self.assertTrue(nuplan.is_at_fault("stopped_track", False))

    def run_hit(self, ego_speed, other, kind="collision_vehicle", **sample_flags):
        traj = [dict(self.EGO, t=0.1 * k, x=10.0 + ego_speed * 0.1 * (k - 10), speed=ego_speed, **sample_flags)
                for k in range(21)]
        return sc.score_drive(traj, {"points": [[0.0, 0.0], [100.0, 0.0]]},
                              [ev(1.0, kind, "car_1", other_state=other)])

    def test_ego_stopped_not_at_fault(self):
        r = self.run_hit(0.0, self.car(14.0, 0.0, 3.0))
        n = r["nuplan_score"]
        self.assertEqual((n["collisions"][0]["type"], n["collisions"][0]["at_fault"]), ("stopped_ego", False))
        self.assertEqual(n["multipliers"]["no_ego_at_fault_collisions"], 1.0)
        self.assertFalse(r["infractions"][0]["counted"])

    def test_rear_ended_not_at_fault(self):
        n = self.run_hit(5.0, self.car(6.8, 0.0, 8.0))["nuplan_score"]
        self.assertEqual((n["collisions"][0]["type"], n["collisions"][0]["at_fault"]), ("active_rear", False))
        self.assertEqual(n["multipliers"]["no_ego_at_fault_collisions"], 1.0)
        self.assertEqual(n["weighted"]["time_to_collision_within_bound"], 1.0)

    def test_into_car_ahead_at_fault(self):
        r = self.run_hit(5.0, self.car(14.0, 0.0, 2.0))
        n = r["nuplan_score"]
        self.assertEqual((n["collisions"][0]["type"], n["collisions"][0]["at_fault"]), ("active_front", True))
        self.assertEqual(n["multipliers"]["no_ego_at_fault_collisions"], 0.0)
        self.assertEqual(n["score"], 0.0)
        self.assertEqual(n["min_ttc_s"], 0.0)
        self.assertEqual(r["infraction_penalty"], 0.6)

    def test_lateral_depends_on_lanes(self):
        n = self.run_hit(5.0, self.car(9.0, 1.7, 5.0))["nuplan_score"]
        self.assertEqual((n["collisions"][0]["type"], n["collisions"][0]["at_fault"]), ("active_lateral", False))
        n = self.run_hit(5.0, self.car(9.0, 1.7, 5.0), multiple_lanes=True)["nuplan_score"]
        self.assertEqual((n["collisions"][0]["type"], n["collisions"][0]["at_fault"]), ("active_lateral", True))

    def test_category_scores(self):
        self.assertEqual(nuplan.at_fault_collision_score({"object": 1}), 0.5)
        self.assertEqual(nuplan.at_fault_collision_score({"object": 2}), 0.0)
        self.assertEqual(nuplan.at_fault_collision_score({"vru": 1}), 0.0)
        self.assertEqual(nuplan.at_fault_collision_score({"vehicle": 1}), 0.0)
        self.assertEqual(nuplan.at_fault_collision_score({}), 1.0)
        n = self.run_hit(5.0, None, kind="collision_static")["nuplan_score"]
        self.assertEqual(n["multipliers"]["no_ego_at_fault_collisions"], 0.5)
        self.assertEqual(n["at_fault_collisions"], {"vru": 0, "vehicle": 0, "object": 1})
        self.assertEqual(nuplan.collision_category("collision_vehicle", "cyclist"), "vru")

    def test_each_other_counts_once(self):
        traj = [dict(self.EGO, t=0.1 * k, x=5.0 + 0.5 * k) for k in range(21)]
        r = sc.score_drive(traj, {"points": [[0.0, 0.0], [100.0, 0.0]]},
                           [ev(1.0, "collision_static", "pole"), ev(1.5, "collision_static", "pole")])
        self.assertEqual(r["nuplan_score"]["at_fault_collisions"]["object"], 1)
        self.assertEqual(r["infraction_penalty"], 0.65 * 0.65)  # CARLA counts both


class NuplanTTCAndOthers(unittest.TestCase):
    def ttc_run(self, values):
        traj = straight(40.0, step=0.5, dt=0.05, speed=10.0)
        for s, v in zip(traj, values * len(traj)):
            s["ttc"] = v
        return sc.score_drive(traj, ROUTE)["nuplan_score"]

    def test_ttc_bound(self):
        self.assertEqual(self.ttc_run([None, 1.0])["weighted"]["time_to_collision_within_bound"], 1.0)
        self.assertEqual(self.ttc_run([None, 0.9])["weighted"]["time_to_collision_within_bound"], 0.0)
        self.assertEqual(self.ttc_run([2.0, 0.95])["weighted"]["time_to_collision_within_bound"], 0.0)
        n = self.ttc_run([None, 0.96])
        self.assertEqual((n["weighted"]["time_to_collision_within_bound"], n["min_ttc_s"], n["ttc_available"]),
                         (1.0, 0.96, True))
        n = sc.score_drive(straight(40.0), ROUTE)["nuplan_score"]
        self.assertEqual((n["ttc_available"], n["min_ttc_s"]), (False, None))

    def test_ttc_projection(self):
        ego = {"x": 0.0, "y": 0.0, "yaw": 0.0, "speed": 10.0, "length": 4.0, "width": 2.0}
        ahead = {"class": "car", "x": 20.5, "y": 0.0, "yaw": 0.0, "speed": 0.0, "length": 4.0, "width": 2.0}
        self.assertEqual(nuplan.ttc_at(ego, [ahead]), 1.7)   # 16.5 m gap closed at 10 m/s
        self.assertEqual(nuplan.ttc_at(ego, [dict(ahead, speed=5.0, x=10.2)]), 1.3)  # 6.2 m at 5 m/s
        self.assertIsNone(nuplan.ttc_at(ego, [dict(ahead, y=5.0)]))
        self.assertIsNone(nuplan.ttc_at(ego, [dict(ahead, x=-20.5, speed=20.0)]))      # behind: not considered
        self.assertIsNone(nuplan.ttc_at(dict(ego, speed=0.0), [ahead]))
        crossing = {"class": "car", "x": 15.5, "y": -9.0, "yaw": math.pi / 2, "speed": 5.0, "length": 4.0, "width": 2.0}
        self.assertIsNone(nuplan.ttc_at(ego, [crossing]))             # 30.1 deg off: not ahead
        self.assertEqual(nuplan.ttc_at(ego, [crossing], wide=True), 1.3)

    def test_speed_limit_compliance(self):
        traj = straight(40.0, step=0.5, dt=0.05, speed=10.0)    # 81 samples, 4 s
        limits = [8.0 if k < 40 else None for k in range(len(traj))]
        n = sc.score_drive(traj, ROUTE, speed_limits=limits)["nuplan_score"]
        self.assertAlmostEqual(n["weighted"]["speed_limit_compliance"], 1.0 - 40 * 2.0 * 0.05 / (2.23 * 4.0), places=12)
        self.assertEqual(n["max_overspeed_mps"], 2.0)
        self.assertEqual(sc.score_drive(traj, ROUTE)["nuplan_score"]["weighted"]["speed_limit_compliance"], 1.0)

    def test_progress(self):
        n = sc.score_drive(straight(50.0), ROUTE)["nuplan_score"]
        self.assertEqual((n["ego_progress_m"], n["expert_progress_m"]), (50.0, 100.0))
        self.assertEqual(n["weighted"]["ego_progress_along_expert_route"], 0.5)
        n = sc.score_drive(straight(15.0), ROUTE)["nuplan_score"]
        self.assertEqual(n["multipliers"]["ego_is_making_progress"], 0.0)
        n = sc.score_drive(straight(20.0), dict(ROUTE, expert_progress_m=20.0))["nuplan_score"]
        self.assertEqual(n["weighted"]["ego_progress_along_expert_route"], 1.0)
        self.assertEqual(nuplan.progress_ratio(-3.0, 50.0), 0.0)
        self.assertEqual(nuplan.progress_ratio(1.0, 1.0), 1.0)

    def test_driving_direction(self):
        traj = straight(60.0, step=0.15, dt=0.05, speed=3.0)  # 3 m/s
        for s in traj:
            s["wrong_way"] = 20.0 < s["x"] <= 30.0               # 10 m against the lane: 3 m in 1 s
        n = sc.score_drive(traj, ROUTE)["nuplan_score"]
        self.assertEqual(n["multipliers"]["driving_direction_compliance"], 0.5)
        self.assertAlmostEqual(n["max_wrong_way_m_per_1s"], 3.15, places=9)  # 21 samples of 0.15 m
        fast = straight(60.0, step=0.5, dt=0.05, speed=10.0)
        for s in fast:
            s["wrong_way"] = s["x"] > 30.0
        self.assertEqual(sc.score_drive(fast, ROUTE)["nuplan_score"]["multipliers"]["driving_direction_compliance"], 0.0)

    def test_combination(self):
        traj = straight(50.0)
        n = sc.score_drive(traj, ROUTE)["nuplan_score"]
        self.assertEqual(n["score"], (5 * 0.5 + 5 * 1.0 + 4 * 1.0 + 2 * 1.0) / 16)


class CityMap(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.map = road_map.load(os.path.join(REPO, "experiments", "city_traffic", "city.xodr"))

    def test_locate(self):
        pts = [(-100.0, -1.75, 0.0), (-100.0, 1.75, math.pi), (-100.0, -12.0, 0.0), (0.0, -1.75, 0.0),
               (1.75, -60.0, math.pi / 2), (-100.0, 1.75, 0.0)]
        r = road_map.locate(self.map, *zip(*pts))
        self.assertEqual((r[0]["road"], r[0]["lane"], r[0]["on_road"], r[0]["junction"]), ("1", -1, True, False))
        self.assertAlmostEqual(r[0]["speed_limit"], 50 / 3.6, places=12)
        self.assertAlmostEqual(r[1]["heading"], math.pi, places=9)
        self.assertEqual((r[2]["road"], r[2]["on_road"]), (None, False))
        self.assertEqual((r[3]["road"], r[3]["junction"]), ("1000", True))   # straight on, junction 100
        self.assertAlmostEqual(r[3]["speed_limit"], 50 / 3.6, places=12)      # its roads' limit
        self.assertAlmostEqual(r[4]["speed_limit"], 30 / 3.6, places=12)
        self.assertEqual((r[5]["road"], r[5]["lane"]), ("1", 1))


def write_run(folder):
    """A small city_traffic run folder: the ego eastbound from x = -150 at 10 m/s for 5 s, a
    pedestrian standing by the road it hits at t = 2 s, a red light at t = 3 s."""
    rows = []
    for k in range(1, 101):
        t = round(0.05 * k, 3)
        ex = round(-150.0 + 10.0 * (t - 0.05), 3)
        users = [["car_3", "car", round(ex + 30.0, 3), -1.75, 0.0, 10.0, 4.5, 1.35],
                 ["ped_0", "pedestrian", -120.0, -8.8, 0.0, 0.0, 0.5, 0.0],
                 ["smart_car", "car", ex, -1.75, 0.0, 10.0, 3.2, -0.0]]
        rows.append({"t": t, "users": users, "signals": {"1": "red"}})
    with open(os.path.join(folder, "tracks.jsonl"), "w") as f:
        for r in rows:
            f.write(json.dumps(r, separators=(",", ":")) + "\n")
    summary = {"collisions": [{"t": 2.0, "a": "ped_0", "b": "smart_car", "class_a": "pedestrian",
                               "class_b": "car", "relative_speed_mps": 10.0},
                              {"t": 2.5, "a": "car_7", "b": "sumo/f0.0", "class_a": "car", "class_b": "car",
                               "relative_speed_mps": 3.0}],
               "red_light_violation_list": [{"t": 3.0, "id": "smart_car", "class": "car", "signal": "1"},
                                            {"t": 3.2, "id": "car_3", "class": "car", "signal": "1"}],
               "min_ttc_s": 2.5}
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump(summary, f)


class RunFolder(unittest.TestCase):
    def test_score_run_and_cli(self):
        with tempfile.TemporaryDirectory() as d:
            write_run(d)
            r = runs.score_run(d)
            env = dict(os.environ, PYTHONPATH=PYTHON_DIR)
            p = subprocess.run([sys.executable, "-m", "convoy_bench.score", d], capture_output=True, text=True, env=env)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertEqual(json.loads(p.stdout)["driving_score"], r["driving_score"])
            bad = subprocess.run([sys.executable, "-m", "convoy_bench.score", os.path.join(d, "none")],
                                 capture_output=True, text=True, env=env)
            self.assertEqual(bad.returncode, 2)
            self.assertIn("tracks.jsonl", bad.stderr)
        self.assertEqual(r["run"]["samples"], 100)
        self.assertTrue(r["run"]["route_csv"].endswith("ego_route.csv"))
        self.assertAlmostEqual(r["route_length_m"], 600.0, places=9)        # -150 .. 450
        self.assertAlmostEqual(r["route_completion"], 100.0 * 49.5 / 600.0, places=9)
        self.assertEqual([(i["kind"], i["other"], i["penalty"]) for i in r["infractions"]],
                         [("collision_pedestrian", "ped_0", 0.5), ("red_light", "1", 0.7)])
        self.assertAlmostEqual(r["driving_score"], 100.0 * 49.5 / 600.0 * 0.5 * 0.7, places=9)
        n = r["nuplan_score"]
        self.assertEqual([(c["type"], c["at_fault"], c["category"]) for c in n["collisions"]],
                         [("stopped_track", True, "vru")])
        self.assertEqual(n["score"], 0.0)
        self.assertEqual(n["min_ttc_s"], 0.0)
        self.assertEqual(n["multipliers"]["drivable_area_compliance"], 1.0)
        self.assertEqual(n["weighted"]["speed_limit_compliance"], 1.0)   # 10 m/s under 50 km/h

    def test_route_given(self):
        with tempfile.TemporaryDirectory() as d:
            write_run(d)
            route = os.path.join(d, "route.csv")
            with open(route, "w") as f:
                f.write("x,y,heading\n-150,-1.75,0\n-50,-1.75,0\n")
            r = runs.score_run(d, route_csv=route)
        self.assertAlmostEqual(r["route_completion"], 49.5, places=9)


if __name__ == "__main__":
    unittest.main()
