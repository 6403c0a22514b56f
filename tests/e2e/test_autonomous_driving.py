"""End-to-end tests of the autonomous-driving experiment: the smart car follows the Parkring
lane, two control-only runs give identical trajectories, and a run of "both" writes the
video, the bird's-eye plot and the summary.

Run with Debian's /usr/bin/python3 -m unittest test_autonomous_driving."""

import csv
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

from test_core import BIN_DIR, CONVOY

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
EXP = os.path.join(REPO, "experiments", "autonomous_driving")
WAYPOINTS = os.path.join(os.path.dirname(BIN_DIR), "share", "convoy", "models", "parkring_road",
                         "waypoints_lane-1.csv")


def cross_track(points, lane):
    def dist(p):
        best = 1e9
        for i in range(len(lane)):
            (ax, ay), (bx, by) = lane[i], lane[(i + 1) % len(lane)]
            dx, dy = bx - ax, by - ay
            t = max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / (dx * dx + dy * dy)))
            best = min(best, math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy))
        return best
    return [dist(p) for p in points]


class ControlOnly(unittest.TestCase):
    def run_control(self, seconds):
        d = tempfile.mkdtemp(prefix="convoy-ad-")
        self.addCleanup(shutil.rmtree, d, True)
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(EXP, "simulation_config_control.json"),
                            "--run-dir", os.path.join(d, "run"), "-o", "SimulationTimeout=%g" % seconds],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(d, "run", "trajectory.csv"), "rb") as f:
            return f.read()

    def test_car_follows_the_lane_and_runs_are_identical(self):
        a = self.run_control(25)
        b = self.run_control(25)
        self.assertEqual(a, b, "two control-only runs differ")
        rows = list(csv.DictReader(a.decode().splitlines()))
        self.assertEqual(len(rows), 1250)
        last = rows[-1]
        self.assertGreater(int(last["target_index"]), 55)  # ~130 m along the lane
        with open(WAYPOINTS) as f:
            lane = [(float(r["x"]), float(r["y"])) for r in csv.DictReader(f)]
        errors = cross_track([(float(r["x"]), float(r["y"])) for r in rows[::25]], lane)
        self.assertLess(sum(errors) / len(errors), 0.3)
        self.assertLess(max(errors), 1.0)


if __name__ == "__main__":
    unittest.main()


class Both(unittest.TestCase):
    def test_run_writes_video_plot_and_summary(self):
        d = tempfile.mkdtemp(prefix="convoy-ad-")
        self.addCleanup(shutil.rmtree, d, True)
        run = os.path.join(d, "run")
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(EXP, "simulation_config_both.json"),
                            "--run-dir", run, "-o", "SimulationTimeout=3"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        for name in ("camera.mp4", "birds_eye.png"):
            self.assertGreater(os.path.getsize(os.path.join(run, name)), 1000, name)
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        # the evaluator's fields
        self.assertIs(s["lap_completed"], False)  # 3 s is no lap
        self.assertLess(s["cross_track_error_m"]["max"], 1.0)
        self.assertGreater(s["physics_real_time_factor"], 0)
        self.assertGreater(s["camera_frames"], 80)  # 30 Hz for 3 s
        self.assertGreater(s["camera_frames_per_s"], 0)
        self.assertGreater(sum(s["detections_per_class"].values()), 0)
        # Convoy's trained detector by default, its classes from models/detector/classes.txt
        self.assertIs(s["detector_is_ground_truth"], False)
        self.assertTrue(set(s["detections_per_class"]) <= {"car", "truck", "bus", "pedestrian", "cyclist"},
                        s["detections_per_class"])
        self.assertGreater(s["detector_inference_ms_median"], 0)
        self.assertIn("detector_map50", s)
        # the coordinator's, added on top
        self.assertEqual(s["exit_code"], 0)
        self.assertAlmostEqual(s["sim_time_s"], 3.0)
        self.assertGreater(s["loop_wall_s"], 0)
        self.assertGreater(s["real_time_factor"], 0)

    def test_ground_truth_backend_scores_perfectly_and_says_so(self):
        d = tempfile.mkdtemp(prefix="convoy-ad-")
        self.addCleanup(shutil.rmtree, d, True)
        run = os.path.join(d, "run")
        with open(os.path.join(EXP, "simulation_config_both.json")) as f:
            det = [e["EngineName"] for e in json.load(f)["EngineConfigs"]].index("yolo_detector")
        r = subprocess.run([CONVOY, "run", "-q", "-c", os.path.join(EXP, "simulation_config_both.json"),
                            "--run-dir", run, "-o", "SimulationTimeout=1",  # 30 frames scored
                            "-o", "EngineConfigs/%d/Backend=ground_truth" % det],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        self.assertIs(s["detector_is_ground_truth"], True)
        self.assertEqual(s["detector_precision"], 1.0)  # ground truth scored against itself
        self.assertEqual(s["detector_recall"], 1.0)
        self.assertEqual(s["detector_map50"], 1.0)
        self.assertGreater(s["detector_scored_objects"], 0)  # something was scored
