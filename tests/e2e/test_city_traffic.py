"""experiments/city_traffic, shortened: the ego (camera, ground-truth-passthrough detector,
planner on ground-truth objects) among 20 vehicle agents, 10 pedestrian agents and SUMO's
traffic on the generated city map.

- Outputs: camera.mp4 with a frame per 1/30 s, birds_eye.png, and summary.json's
  participants, collisions (none), min_ttc_s, red_light_violations (none) and
  ego_stops_for_pedestrians (pedestrian 9 crosses mid-block in front of the ego at about 14 s).
- Determinism: two runs give the same tracks of every road user (SHA-1 of tracks.jsonl).
- Bad input: two participants placed on the same spot end the run with a message naming both
  and a non-zero exit, and leave no process behind.

- Density: 3 simulated minutes of the dense variant (every agent respawning, SUMO's flows
  doubled) without a contact among the participants; DensityLong (label `long`), the issue's
  10 minutes (about 100 s of wall time)."""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

from e2e_util import CONVOY, REPO

EXAMPLE = os.path.join(REPO, "experiments", "city_traffic")
SUMO_ENGINE = os.path.join(os.path.dirname(CONVOY), "convoy-engine-sumo")


def run(run_dir, seconds, *overrides):
    args = [CONVOY, "run", "-c", "simulation_config.json", "--run-dir", run_dir, "-q",
            "-o", "SimulationTimeout=%g" % seconds]
    for o in overrides:
        args += ["-o", o]
    return subprocess.run(args, cwd=EXAMPLE, capture_output=True, text=True, timeout=300)


def engine_index(name):
    with open(os.path.join(EXAMPLE, "simulation_config.json")) as f:
        return [e["EngineName"] for e in json.load(f)["EngineConfigs"]].index(name)


def processes_of(run_dir):
    """Live processes started for the run in run_dir (their environment names it)."""
    found = []
    key = ("CONVOY_RUN_DIR=" + run_dir).encode()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/environ" % entry, "rb") as f:
                if key in f.read().split(b"\0"):
                    found.append(int(entry))
        except OSError:
            continue
    return found


class CityCase(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.access(SUMO_ENGINE, os.X_OK):
            raise unittest.SkipTest("the sumo engine is not built (SUMO not found)")

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convoy-city-")
        self.addCleanup(shutil.rmtree, self.tmp, True)

    def summary(self, run_dir):
        with open(os.path.join(run_dir, "summary.json")) as f:
            return json.load(f)


class Outputs(CityCase):
    def test_a_short_run(self):
        d = os.path.join(self.tmp, "run")
        r = run(d, 22.0)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = self.summary(d)
        p = s["participants"]
        self.assertEqual(p["vehicle_agent"], 20)
        self.assertEqual(p["pedestrian_agent"], 10)
        self.assertEqual(p["sumo"], 1)
        self.assertGreater(p["sumo_vehicles"], 0)
        self.assertEqual(s["collisions"], [])
        self.assertEqual(s["red_light_violations"], 0)
        self.assertGreaterEqual(s["ego_stops_for_pedestrians"], 1)
        self.assertIsInstance(s["min_ttc_s"], float)
        self.assertGreater(s["min_ttc_s"], 0.5)
        # every road user was recorded: 20 + 10 agents, SUMO's vehicles and the ego
        self.assertGreaterEqual(s["road_users_seen"], 31 + p["sumo_vehicles"])
        # a 30 Hz camera for 22 s, a detection every third frame (10 Hz)
        import cv2
        v = cv2.VideoCapture(os.path.join(d, "camera.mp4"))
        frames = int(v.get(cv2.CAP_PROP_FRAME_COUNT))
        ok, img = v.read()
        self.assertTrue(ok)
        self.assertEqual(img.shape[:2], (480, 736))
        self.assertGreaterEqual(frames, 22 * 30 - 3)
        self.assertEqual(s["camera_frames"], frames)
        self.assertGreaterEqual(s["detector_frames"], 22 * 10 - 12)
        self.assertLessEqual(s["detector_frames"], 22 * 10 + 1)
        bird = cv2.imread(os.path.join(d, "birds_eye.png"))
        self.assertIsNotNone(bird)
        self.assertGreater(bird.shape[1], 1000)
        # the ego's track is drawn in yellow (BGR 0, 255, 255)
        yellow = ((bird[:, :, 0] < 40) & (bird[:, :, 1] > 215) & (bird[:, :, 2] > 215)).sum()
        self.assertGreater(yellow, 200)
        # the live score (score_tf.py) agrees with the score of the finished run folder
        sys.path.insert(0, os.path.join(REPO, "python"))
        from convoy_bench import runs
        after = runs.score_run(d)
        self.assertGreater(s["route_completion"], 5.0)
        self.assertAlmostEqual(s["route_completion"], after["route_completion"], delta=1.0)
        self.assertAlmostEqual(s["driving_score"], after["driving_score"], delta=1.0)
        self.assertEqual([i["kind"] for i in s["infractions"]], [i["kind"] for i in after["infractions"]])
        with open(os.path.join(d, "ego_planner.json")) as f:
            planner = json.load(f)
        self.assertTrue(planner["ground_truth"])
        self.assertGreaterEqual(planner["min_distance_to_pedestrian_stopped_m"], 2.0)


class Determinism(CityCase):
    def test_same_seeds_same_tracks(self):
        digests = []
        for name in ("a", "b"):
            d = os.path.join(self.tmp, name)
            r = run(d, 8.0)
            self.assertEqual(r.returncode, 0, r.stderr)
            digests.append(self.summary(d)["tracks_sha1"])
            with open(os.path.join(d, "tracks.jsonl")) as f:
                self.assertGreater(len(f.readlines()), 150)
        self.assertEqual(digests[0], digests[1])


class DensityCase(CityCase):
    def check_dense(self, seconds, min_sumo_vehicles, min_peak):
        """`seconds` of the dense scene (every agent respawning, SUMO's flows doubled): no
        contact among the participants, no red light run, SUMO kept feeding vehicles and the
        scene filled up (tracks.jsonl's peak of road users)."""
        d = os.path.join(self.tmp, "run")
        args = [CONVOY, "run", "-c", "simulation_config_density.json", "--run-dir", d, "-q",
                "-o", "SimulationTimeout=%g" % seconds]
        r = subprocess.run(args, cwd=EXAMPLE, capture_output=True, text=True, timeout=900)
        self.assertEqual(r.returncode, 0, r.stderr)
        s = self.summary(d)
        self.assertAlmostEqual(s["sim_time_s"], seconds, delta=0.1)
        self.assertEqual(s["collisions"], [])
        self.assertEqual(s["red_light_violations"], 0)
        self.assertGreater(s["participants"]["sumo_vehicles"], min_sumo_vehicles)
        with open(os.path.join(d, "tracks.jsonl")) as f:
            peak = max(len(json.loads(line)["users"]) for line in f)
        self.assertGreater(peak, min_peak)


class Density(DensityCase):
    """The first 3 simulated minutes of the dense scene (about 20 s of wall time): the 30
    agents and 60 of SUMO's vehicles, up to 78 road users at once (40 at the start)."""

    def test_three_minutes_without_a_collision(self):
        self.check_dense(180.0, 50, 65)


class DensityLong(DensityCase):
    """The issue's density test (ctest label `long`): 10 simulated minutes of the dense scene
    (about 190 of SUMO's vehicles, up to 140 road users at once; about 100 s of wall time),
    no contact among the participants and no red light run."""

    def test_ten_minutes_without_a_collision(self):
        self.check_dense(600.0, 150, 100)


class BadInput(CityCase):
    def test_two_participants_on_the_same_spot(self):
        # car_1 starts on car_0's lane at car_0's s
        d = os.path.join(self.tmp, "run")
        r = run(d, 5.0, "EngineConfigs/%d/StartS=140" % engine_index("car_1"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("road users 'car_0' and 'car_1' are placed on the same spot", r.stderr)
        self.assertIn("engine 'gazebo'", r.stderr)
        self.assertTrue(os.path.isdir(os.path.join(d, "logs")), "the logs are kept")
        time.sleep(0.5)
        self.assertEqual(processes_of(d), [], "processes left behind")


if __name__ == "__main__":
    unittest.main()
