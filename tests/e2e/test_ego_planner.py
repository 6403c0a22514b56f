"""experiments/ego_planner: the ego's longitudinal planner (ACC, AEB) in front of the report's
PID waypoint follower on the Parkring.

- Pedestrian (ground-truth objects): at 30 km/h, a pedestrian steps into the ego's lane 30 m
  ahead; the ego stops at least 2 m before it, with no collision in the world's `collisions`
  datapack. A control run whose planner sees only 5 m ahead hits the pedestrian (the
  collision check can fail).
- ACC (ground truth): behind a slower car the ego settles at the leader's speed with a gap of
  at least its standstill distance, and no collision.
- Detections: the same pedestrian scene with the planner's detection input: Convoy's trained
  detector on the camera's images -> depth ranging -> tracker -> planner. The world's gap and
  collisions are checked as with ground truth.
- Logic (no simulation): frames, ranging, crossing prediction, episode counting, and a
  stop from 30 km/h against an ideal first-order car.
- Bad input: an unknown input source, a bad parameter, an unknown key, and an input TF that
  does not match the configured source each end with a message naming the engine and key,
  and a non-zero exit.

Ground-truth distances come from the road user's own record (pedestrian.json, leader.json):
the ego's front to the road user along the ego's axis, from the world engine's RoadUser."""

import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

from e2e_util import CONVOY, REPO

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_traffic import ego_planner as ep  # noqa: E402

EXAMPLE = os.path.join(REPO, "experiments", "ego_planner")


def variant(tmp, config, planner=None, **top):
    """The example's config with absolute paths (run from a temp folder); `planner` replaces
    the planner's parameter file."""
    with open(os.path.join(EXAMPLE, config)) as f:
        c = json.load(f)
    c.update(top)
    for e in c["EngineConfigs"]:
        for k in ("GazeboWorldFile", "PythonFileName"):
            if k in e:
                e[k] = os.path.join(EXAMPLE, e[k])
        if e["EngineName"] == "planner" and planner is not None:
            path = os.path.join(tmp, "planner.json")
            with open(path, "w") as f:
                json.dump(planner, f)
            e["EngineEnvParams"] = ["CONVOY_EGO_PLANNER_CONFIG=" + path]
    for fn in c["DataPackProcessingFunctions"]:
        fn["FileName"] = os.path.join(EXAMPLE, fn["FileName"])
    path = os.path.join(tmp, "simulation_config.json")
    with open(path, "w") as f:
        json.dump(c, f)
    return path


def run(config, run_dir, cwd=EXAMPLE):
    return subprocess.run([CONVOY, "run", "-c", config, "--run-dir", run_dir, "-q"], cwd=cwd,
                          capture_output=True, text=True, timeout=240)


def load(run_dir, name):
    with open(os.path.join(run_dir, name)) as f:
        return json.load(f)


def planner_params(name):
    with open(os.path.join(EXAMPLE, name)) as f:
        return json.load(f)


EGO = {"id": "ego", "x": 0.0, "y": 0.0, "yaw": 0.0, "speed": 30 / 3.6, "yaw_rate": 0.0,
       "length": 4.0, "width": 1.8, "length_offset": 0.0}


def ped(lat, v_lat=0.0, lon=32.25, pid="p"):
    return {"id": pid, "class": "pedestrian", "lon": lon, "lat": lat, "length": 0.5,
            "width": 0.5, "v_lon": 0.0, "v_lat": v_lat, "source": "ground_truth"}


class Logic(unittest.TestCase):
    def params(self, **kw):
        return ep.parse_config(dict({"Input": "ground_truth"}, **kw))

    def test_road_users_in_the_ego_frame(self):
        ego = dict(EGO, x=5.0, y=5.0, yaw=math.pi / 2)
        objs = ep.objects_from_road_users(ego, [
            {"id": "ego", "x": 5.0, "y": 5.0},  # itself: skipped
            {"id": "a", "category": "car", "x": 5.0, "y": 15.0, "yaw": math.pi / 2,
             "speed": 3.0, "length": 4.5, "width": 1.8, "length_offset": 1.0},
            {"id": "b", "category": "pedestrian", "x": 3.0, "y": 5.0, "absent": True}])
        self.assertEqual([o["id"] for o in objs], ["a"])
        a = objs[0]
        self.assertAlmostEqual(a["lon"], 11.0)
        self.assertAlmostEqual(a["lat"], 0.0)
        self.assertAlmostEqual(a["v_lon"], 3.0)
        self.assertAlmostEqual(a["length"], 4.5)
        self.assertEqual(a["source"], "ground_truth")

    def test_detections_ranged_in_depth(self):
        import numpy as np
        w, h, hfov = 200, 100, math.pi / 2  # f = 100 px
        depth = np.full((h, w), 50.0, np.float32)
        depth[40:80, 140:160] = 10.0  # a person right of centre
        dets = [{"class": "person", "x_min": 140, "x_max": 160, "y_min": 40, "y_max": 80},
                {"class": "car", "x_min": 0, "x_max": 0, "y_min": 0, "y_max": 5}]  # empty
        objs = ep.objects_from_detections(dets, depth, w, h, hfov, cam_x=0.5)
        self.assertEqual(len(objs), 1)
        o = objs[0]
        self.assertEqual(o["class"], "pedestrian")
        self.assertAlmostEqual(o["lon"], 0.5 + 10.0 + 0.25)
        self.assertAlmostEqual(o["lat"], -(150 - 100) / 100 * 10.0)
        self.assertAlmostEqual(o["width"], 2.0)
        # the tracker turns a moving box into a velocity (ego standing)
        tr = ep.Tracker(alpha=1.0)
        tr.update([dict(o)], 0.0, 0.0)
        moved = tr.update([dict(o, lat=o["lat"] + 0.15)], 0.1, 0.0)
        self.assertAlmostEqual(moved[0]["v_lat"], 1.5)
        self.assertEqual(moved[0]["id"], "track0")
        # a pedestrian's range jumping 2 m in 0.1 s (the depth ranging, not motion) gives at
        # most a walker's speed
        jumped = tr.update([dict(o, lat=o["lat"] + 0.15, lon=o["lon"] - 2.0)], 0.2, 0.0)
        self.assertLessEqual(math.hypot(jumped[0]["v_lon"], jumped[0]["v_lat"]), ep.MAX_WALKER_SPEED + 1e-9)

    def test_crossing_prediction(self):
        pl = ep.Planner(self.params())
        self.assertTrue(pl.in_path(EGO, ped(0.5))[0])
        self.assertTrue(pl.in_path(EGO, ped(-2.3, 1.5))[0])     # stepping in
        self.assertFalse(pl.in_path(EGO, ped(-2.3, -1.5))[0])   # stepping away
        self.assertFalse(pl.in_path(EGO, ped(-2.3, 0.3))[0])    # below MinCrossingSpeed
        self.assertFalse(pl.in_path(EGO, ped(-9.0, 1.5))[0])    # enters after 4.9 s
        self.assertFalse(pl.in_path(EGO, ped(0.0, lon=-3.0))[0])  # behind

    def stop(self, objects_at, lag=0.55, t_end=15.0):
        """An ideal first-order car (time constant `lag`) at 30 km/h under the planner."""
        pl = ep.Planner(self.params())
        v, x, t, dt = 30 / 3.6, 0.0, 0.0, 0.02
        gaps = []
        while t < t_end:
            ego = dict(EGO, x=x, speed=v)
            objs = [dict(o, lon=o["lon"] - x) for o in objects_at(t)]
            cmd = pl.step(t, ego, objs)["speed"]
            v = max(0.0, v + (cmd - v) * dt / lag)
            x += v * dt
            t += dt
            gaps.extend(o["lon"] - 0.25 - 2.0 for o in objs)
        return pl, v, min(gaps)

    def test_stops_2_m_before_a_pedestrian_30_m_ahead(self):
        pl, v, gap = self.stop(lambda t: [ped(0.0, lon=32.25)])
        self.assertLess(v, 0.05)
        self.assertGreaterEqual(gap, 2.0)
        res = pl.result()
        self.assertEqual(res["ego_stops_for_pedestrians"], 1)
        self.assertTrue(res["ground_truth"])

    def test_one_event_per_episode_even_when_track_ids_change(self):
        pl, v, gap = self.stop(lambda t: [ped(0.0, lon=32.25, pid="track%d" % int(t * 3))])
        self.assertEqual(pl.result()["ego_stops_for_pedestrians"], 1)

    def test_aeb_when_the_car_ahead_brakes_hard(self):
        # following at 30 km/h, 10 m (bumper to bumper) behind a car that brakes at 8 m/s^2 to a stop at t = 1
        def car(t):
            tb = min(max(t - 1.0, 0.0), 30 / 3.6 / 8.0)
            s = 14.25 + 30 / 3.6 * min(t, 1.0) + 30 / 3.6 * tb - 4.0 * tb * tb
            v = 30 / 3.6 - 8.0 * tb if t >= 1.0 else 30 / 3.6
            return [{"id": "car", "class": "car", "lon": s, "lat": 0.0, "length": 4.5,
                     "width": 1.8, "v_lon": v, "v_lat": 0.0, "source": "ground_truth"}]
        pl, v, _ = self.stop(car, t_end=12.0)
        self.assertLess(v, 0.05)
        modes = [p["mode"] for p in pl.trace]
        self.assertIn("aeb", modes)
        self.assertGreaterEqual(pl.min_gap, 2.0)
        self.assertEqual(pl.result()["ego_stops_for_pedestrians"], 0)

    def test_config_errors_name_the_key(self):
        for cfg, needle in (({"Input": "radar"}, "key 'Input'"),
                            ({"StopMargin": 1.5}, "key 'StopMargin'"),
                            ({"TimeGap": True}, "key 'TimeGap'"),
                            ({"Bogus": 1}, "unknown key 'Bogus'"),
                            ({"Output": ""}, "key 'Output'")):
            with self.assertRaises(ep.PlannerConfigError) as cm:
                ep.parse_config(cfg, engine="engine 'planner'")
            self.assertIn("engine 'planner'", str(cm.exception))
            self.assertIn(needle, str(cm.exception))


class Pedestrian(unittest.TestCase):
    def check_stop(self, run_dir, source):
        ped = load(run_dir, "pedestrian.json")
        res = load(run_dir, "ego_planner.json")
        # the scene: 30 km/h, stepping out 30 m ahead
        self.assertGreater(ped["ego_speed_at_step_out_mps"], 30 / 3.6 - 0.2, ped)
        self.assertAlmostEqual(ped["ego_gap_at_step_out_m"], 30.0, delta=0.5)
        # the ego stopped at least 2 m before the pedestrian, without touching it
        self.assertLess(ped["ego_final_speed_mps"], 0.1, ped)
        self.assertGreaterEqual(ped["min_gap_m"], 2.0, ped)
        self.assertLess(ped["min_gap_m"], 6.0, ped)  # and it did not stop absurdly early
        self.assertEqual(ped["collisions"], [])
        # the planner's own record, labelled by its input
        self.assertEqual(res["input"], source)
        self.assertEqual(res["ground_truth"], source == "ground_truth")
        self.assertEqual(res["ego_stops_for_pedestrians"], 1, res["pedestrian_stop_events"])
        if source == "detections" and res["min_distance_to_pedestrian_stopped_m"] is None:
            # Convoy's detector names the pedestrian a car or truck once it fills the view a
            # few metres ahead: the planner then stops behind "a car" (the world's gap above
            # is what counts).
            self.assertIn(res["speed_trace"][-1]["lead_class"], ("car", "truck", "bus", "pedestrian"))
        else:
            self.assertGreaterEqual(res["min_distance_to_pedestrian_stopped_m"], 2.0)
        modes = {p["mode"] for p in res["speed_trace"]}
        self.assertIn("follow", modes)
        self.assertGreater(len(res["speed_trace"]), 150)
        return res

    def test_ground_truth_stop_and_determinism(self):
        with tempfile.TemporaryDirectory() as tmp:
            outs = []
            for i in range(2):
                rd = os.path.join(tmp, "run%d" % i)
                p = run("simulation_config.json", rd)
                self.assertEqual(p.returncode, 0, p.stderr[-3000:])
                with open(os.path.join(rd, "ego_planner.json")) as f:
                    outs.append(f.read())
            res = self.check_stop(os.path.join(tmp, "run0"), "ground_truth")
            # It stops by braking (IDM, or the emergency brake if the time to collision falls
            # under TtcAeb; on dry asphalt, mu 0.8, it need not).
            self.assertLessEqual({e["reason"] for e in res["pedestrian_stop_events"]}, {"aeb", "stopped"})
            self.assertEqual(outs[0], outs[1])  # same config, same run

    def test_control_a_planner_that_sees_5_m_hits_the_pedestrian(self):
        with tempfile.TemporaryDirectory() as tmp:
            params = planner_params("ego_planner.json")
            params["Range"] = 5.0
            rd = os.path.join(tmp, "run")
            p = run(variant(tmp, "simulation_config.json", params), rd)
            self.assertEqual(p.returncode, 0, p.stderr[-3000:])
            cols = load(rd, "pedestrian.json")["collisions"]
            self.assertEqual(len(cols), 1, cols)
            self.assertEqual({cols[0]["class_a"], cols[0]["class_b"]}, {"car", "pedestrian"})
            self.assertEqual({cols[0]["a"], cols[0]["b"]}, {"smart_car", "pedestrian"})

    def test_detection_input(self):
        with tempfile.TemporaryDirectory() as tmp:
            rd = os.path.join(tmp, "run")
            p = run("simulation_config_detector.json", rd)
            self.assertEqual(p.returncode, 0, p.stderr[-3000:])
            res = self.check_stop(rd, "detections")
            self.assertTrue(all(e["pedestrian"].startswith("track")
                                for e in res["pedestrian_stop_events"]))


class Acc(unittest.TestCase):
    def test_follows_a_slower_leader(self):
        with tempfile.TemporaryDirectory() as tmp:
            rd = os.path.join(tmp, "run")
            p = run("simulation_config_acc.json", rd)
            self.assertEqual(p.returncode, 0, p.stderr[-3000:])
            lead = load(rd, "leader.json")
            res = load(rd, "ego_planner.json")
            s0 = res["parameters"]["StandstillDistance"]
            v = lead["leader_speed_mps"]
            self.assertEqual(lead["collisions"], [])
            self.assertGreaterEqual(lead["min_gap_m"], s0, lead)
            # it first closed in (faster than the leader), then settled at its speed
            self.assertGreater(max(r["ego_speed_mps"] for r in lead["trace"]), v + 2.0)
            last = [r for r in lead["trace"] if r["t"] >= 30.0]
            self.assertGreaterEqual(len(last), 15)
            for r in last:
                self.assertAlmostEqual(r["ego_speed_mps"], v, delta=0.15, msg=r)
                self.assertGreaterEqual(r["gap_m"], s0)
            gaps = [r["gap_m"] for r in last]
            self.assertLess(max(gaps) - min(gaps), 0.3, gaps)  # steady
            # IDM's equilibrium gap at v: (s0 + vT) / sqrt(1 - (v/v0)^delta), within 10 %
            pr = res["parameters"]
            eq = (s0 + v * pr["TimeGap"]) / (1 - (v / pr["CruiseSpeed"]) ** pr["Delta"]) ** 0.5
            self.assertAlmostEqual(gaps[-1], eq, delta=0.1 * eq)
            self.assertEqual(res["ego_stops_for_pedestrians"], 0)


class BadInput(unittest.TestCase):
    def expect_error(self, params, *needles, config="simulation_config.json"):
        with tempfile.TemporaryDirectory() as tmp:
            p = run(variant(tmp, config, params, SimulationTimeout=1), os.path.join(tmp, "run"),
                    cwd=tmp)
            self.assertNotEqual(p.returncode, 0, p.stdout[-2000:])
            err = p.stderr + p.stdout
            self.assertIn("engine 'planner' (ego planner)", err)
            for n in needles:
                self.assertIn(n, err)

    def test_unknown_input_source(self):
        params = planner_params("ego_planner.json")
        params["Input"] = "lidar"
        self.expect_error(params, "key 'Input'", "unknown input source 'lidar'")

    def test_bad_parameter(self):
        params = planner_params("ego_planner.json")
        params["StopMargin"] = 1.0
        self.expect_error(params, "key 'StopMargin'", "out of range")
        params["StopMargin"] = "far"
        self.expect_error(params, "key 'StopMargin'", "expected a number")

    def test_unknown_key(self):
        params = planner_params("ego_planner.json")
        params["Cruisespeed"] = 5
        self.expect_error(params, "unknown key 'Cruisespeed'")

    def test_input_tf_does_not_match_the_source(self):
        params = planner_params("ego_planner.json")
        params["Input"] = "detections"
        self.expect_error(params, "key 'Input'", "sends 'ground_truth' objects")


if __name__ == "__main__":
    unittest.main()
