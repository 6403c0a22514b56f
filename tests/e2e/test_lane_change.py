"""End-to-end test of the reference agent's lane change (issue 27 item 4): `convoy run --scenario
benchmarks/suite/stopped_vehicle.xosc` (the ego's route stays in its lane; a broken-down car
stands in it; a second car comes from behind in the right lane). The planner (python/
convoy_traffic/lane_change.py) must let the second car by, pass the standing car in the right
lane, steering itself (motor_tf.py applies its `steer`), and come back, without a collision.
The first 22 simulated seconds (the return ends by ~19 s).

Run with Debian's /usr/bin/python3; the binaries come from $CONVOY_BIN_DIR."""
import csv
import json
import math
import os
import shutil
import subprocess
import tempfile
import unittest

from e2e_util import CONVOY, REPO

XOSC = os.path.join(REPO, "benchmarks", "suite", "stopped_vehicle.xosc")


class StoppedVehicle(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="convoy_lane_change_")
        cls.run_dir = os.path.join(cls.tmp, "run")
        cls.proc = subprocess.run([CONVOY, "run", "-q", "--scenario", XOSC, "--run-dir", cls.run_dir,
                                   "-o", "SimulationTimeout=22"],
                                  capture_output=True, text=True, timeout=300)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def load(self, name):
        with open(os.path.join(self.run_dir, name)) as f:
            return json.load(f)

    def tracks(self):
        """{t: {entity: row}} of tracks.csv."""
        out = {}
        with open(os.path.join(self.run_dir, "tracks.csv")) as f:
            for r in csv.DictReader(f):
                out.setdefault(float(r["t"]), {})[r["entity"]] = r
        return out

    def test_passes_the_standing_car_after_the_other_one(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stderr)
        planner = self.load("ego_planner.json")
        self.assertEqual(planner["lane_change"], "on")
        changes = planner["lane_changes"]
        self.assertEqual([c["kind"] for c in changes], ["out", "back"], changes)
        self.assertEqual(changes[0]["side"], "right")
        self.assertEqual(changes[0]["passing"], "Stopped")
        tracks = self.tracks()
        t_out = changes[0]["t"]
        at = tracks[min(tracks, key=lambda t: abs(t - t_out))]
        # the car from behind was already ahead of the ego when it pulled out
        self.assertGreater(float(at["Passer"]["x"]) - float(at["Ego"]["x"]), 4.5)
        stopped_x = float(tracks[0.0]["Stopped"]["x"])
        beside = [r["Ego"] for r in tracks.values() if abs(float(r["Ego"]["x"]) - stopped_x) < 2.0]
        self.assertTrue(beside)
        self.assertTrue(all(r["lane"] == "-2" for r in beside), "beside the car in the right lane")
        last = tracks[max(tracks)]
        self.assertEqual(last["Ego"]["lane"], "-1", "back in its lane")
        self.assertLess(abs(float(last["Ego"]["y"]) + 1.75), 0.3)
        self.assertGreater(float(last["Ego"]["x"]), stopped_x + 20.0)
        # the broken-down car stood all along
        self.assertLess(abs(float(last["Stopped"]["x"]) - stopped_x), 3.0)
        closest = min(math.hypot(float(r["Ego"]["x"]) - float(r[k]["x"]), float(r["Ego"]["y"]) - float(r[k]["y"]))
                      for r in tracks.values() for k in ("Stopped", "Passer"))
        self.assertGreater(closest, 3.0)
        summary = self.load("summary.json")
        kinds = [e["kind"] for e in summary["infractions"]]
        self.assertFalse([k for k in kinds if k.startswith("collision")], kinds)
        self.assertNotIn("off_route", kinds)


if __name__ == "__main__":
    unittest.main()
