"""The reference agent driving on its sensors (issue 27, part 4; docs/scenarios.md,
"Perception: ground truth or sensors").

Sensors: a one-task campaign over a suite scenario with `--perception sensors` (each task runs
`convoy run --scenario X --perception sensors`), 8 simulated seconds: the run uses the smart
car with the roof LiDAR, its planner's input is "sensors" (the planner engine stops the run if
its input TF sends another source), the LiDAR ranged the detector's boxes, and summary.json and
leaderboard.csv say "sensors".
BadInput: an unknown --perception, and --perception sensors with a user's --ego: exit 2 with a
message naming the option.

Run with Debian's /usr/bin/python3 -m unittest test_perception_sensors."""

import csv
import json
import os
import subprocess
import unittest

from e2e_util import CONVOY, REPO, E2ETestCase

SUITE = os.path.join(REPO, "benchmarks", "suite")
SCENARIO = "lead_brake"


class Sensors(E2ETestCase):
    def test_campaign_with_sensor_perception(self):
        suite = os.path.join(self.dir, "suite")
        os.makedirs(suite)
        with open(os.path.join(SUITE, SCENARIO + ".xosc")) as f:
            text = f.read().replace('filepath="../../', 'filepath="%s/' % REPO).replace(
                'path="catalogs"', 'path="%s"' % os.path.join(SUITE, "catalogs"))
        with open(os.path.join(suite, SCENARIO + ".xosc"), "w") as f:
            f.write(text)
        out = os.path.join(self.dir, "campaign")
        p = subprocess.run([CONVOY, "campaign", suite, "--workers", "1", "--out", out, "--seconds", "8",
                            "--perception", "sensors"],
                           cwd=self.dir, capture_output=True, text=True, timeout=240,
                           stdin=subprocess.DEVNULL)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        with open(os.path.join(out, "leaderboard.csv")) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 1)
        self.assertEqual(rows[0]["perception"], "sensors")
        self.assertNotEqual(rows[0]["driving_score"], "")
        run = os.path.join(out, "runs", "%s__s0__clear" % SCENARIO)
        with open(os.path.join(run, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(s["perception"], "sensors")
        self.assertIn("LiDAR", s["perception_label"])
        # the detector found the lead car and the LiDAR ranged its boxes
        self.assertGreater(s["perception_boxes"], 20)
        self.assertGreater(s["perception_ranged_by_lidar"], 0.8 * s["perception_boxes"])
        with open(os.path.join(run, "ego_planner.json")) as f:
            planner = json.load(f)
        self.assertEqual(planner["input"], "sensors")
        self.assertEqual(planner["path"], "route")
        with open(os.path.join(run, "scenario_config.json")) as f:
            cfg = json.load(f)
        ego = cfg["EngineConfigs"][0]["GazeboSDFModels"][0]["File"]
        self.assertTrue(ego.endswith(os.path.join("smart_car_lidar", "model.sdf")), ego)
        self.assertEqual([i for i in s["infractions"] if i["kind"].startswith("collision")], [])


class BadInput(E2ETestCase):
    def _run(self, *args):
        p = subprocess.run([CONVOY, "run", "-q", "--scenario", os.path.join(SUITE, SCENARIO + ".xosc"),
                            "--run-dir", self.run_dir] + list(args),
                           cwd=self.dir, capture_output=True, text=True, timeout=60,
                           stdin=subprocess.DEVNULL)
        return p.returncode, p.stderr

    def test_unknown_perception(self):
        code, err = self._run("--perception", "radar")
        self.assertEqual(code, 2, err)
        self.assertIn("--perception", err)
        self.assertIn("radar", err)

    def test_sensors_with_a_users_ego(self):
        frag = os.path.join(self.dir, "ego.json")
        with open(frag, "w") as f:
            json.dump({"EngineConfigs": [], "DataPackProcessingFunctions": []}, f)
        code, err = self._run("--perception", "sensors", "--ego", frag)
        self.assertEqual(code, 2, err)
        self.assertIn("--perception sensors", err)


if __name__ == "__main__":
    unittest.main()
