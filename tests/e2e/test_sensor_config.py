"""End-to-end tests of sensors mounted by the world engine's config (issue 27; "Sensors" in
engines/gazebo_grpc/schema.json, src/config/sensor_keys.h, engines/gazebo_grpc/sensor_config.h):
experiments/sensor_car, the smart car on the Parkring with a LiDAR, an IMU and a GNSS receiver
from its config's Sensors list, run for about a second.

Example: the datapacks reach the TF (sensors.csv has IMU and GNSS readings, rising in time;
the LiDAR's last scan, lidar_lidar.npy, has 16 rings and labelled returns), and the run folder
has the bird's-eye PNG. BadInput: a link or a model that does not exist, an unknown type, zero
samples, a negative range, a rate above the step rate: exit 2 before any engine starts, one
message naming the config's file and field and the model, link and sensor.

Run with Debian's /usr/bin/python3 -m unittest test_sensor_config."""

import json
import os
import unittest

import numpy as np

from e2e_util import REPO, E2ETestCase

EXAMPLE = os.path.join(REPO, "experiments", "sensor_car")
EXIT_CONFIG = 2


class SensorConfigCase(E2ETestCase):
    def experiment(self, edit=None, timeout=1.2):
        with open(os.path.join(EXAMPLE, "simulation_config.json")) as f:
            cfg = json.load(f)
        cfg["SimulationTimeout"] = timeout
        for e in cfg["EngineConfigs"]:
            for key in ("GazeboWorldFile", "PythonFileName"):
                if key in e:
                    e[key] = os.path.normpath(os.path.join(EXAMPLE, e[key]))
        for fn in cfg["DataPackProcessingFunctions"]:
            fn["FileName"] = os.path.normpath(os.path.join(EXAMPLE, fn["FileName"]))
        if edit:
            edit(cfg["EngineConfigs"][0]["Sensors"])
        self.write_config(cfg)


class Example(SensorConfigCase):
    def test_datapacks_reach_the_tf_and_the_png_the_run_folder(self):
        self.experiment()
        r = self.run_convoy(timeout=120)
        self.assertExit(r, 0)
        self.assertNoEngineLeft()
        rows = {"imu": [], "gnss": []}
        with open(os.path.join(self.run_dir, "sensors.csv")) as f:
            next(f)
            for line in f:
                kind, t, a, b, c = line.strip().split(",")
                rows[kind].append((float(t), float(a), float(b), float(c)))
        self.assertGreater(len(rows["imu"]), 20)
        self.assertGreater(rows["imu"][-1][0], 0.9)  # 50 Hz readings up to the end
        self.assertAlmostEqual(np.median([r[3] for r in rows["imu"]]), 9.8, delta=0.3)  # +g up
        self.assertGreater(len({r[0] for r in rows["gnss"]}), 5)  # 10 Hz
        png = os.path.join(self.run_dir, "lidar_lidar.png")
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        pts = np.load(os.path.join(self.run_dir, "lidar_lidar.npy"))
        self.assertGreater(len(pts), 1000)
        self.assertEqual(int(pts["ring"].max()), 15)  # the vlp16 preset
        self.assertGreater(int((pts["instance"] != 0).sum()), 100)  # trees, buildings, cars
        self.assertLessEqual(float(np.hypot(pts["x"], pts["y"]).max()), 80.01)  # RangeMax


class BadInput(SensorConfigCase):
    def check(self, index, key, value, *needles):
        def edit(sensors):
            sensors[index][key] = value
        self.experiment(edit)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, EXIT_CONFIG)
        self.assertStderrHas(r, "simulation_config.json: /EngineConfigs/0/Sensors/%d/" % index,
                             *needles)
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertFalse(os.path.exists(os.path.join(self.run_dir, "sensors.csv")))

    def test_link_that_does_not_exist(self):
        self.check(0, "Link", "roof", "Link: model 'smart_car' link 'roof' sensor 'lidar'",
                   "has no link 'roof' (links: base_link")

    def test_model_that_does_not_exist(self):
        self.check(2, "Model", "truck", "Model: model 'truck' link 'base_link' sensor 'gnss'",
                   "no model 'truck'")

    def test_unknown_type(self):
        self.check(1, "Type", "sonar", "Type: model 'smart_car' link 'base_link' sensor 'imu'",
                   "unknown type 'sonar'")

    def test_zero_samples(self):
        self.check(0, "VerticalSamples", 0, "sensor 'lidar'", "samples >= 1, got 0")

    def test_negative_range(self):
        self.check(0, "RangeMin", -1, "RangeMin: model 'smart_car'", "must be >= 0 m, got -1")

    def test_update_rate_above_the_step_rate(self):
        self.check(1, "UpdateRate", 100, "UpdateRate: model 'smart_car' link 'base_link' "
                   "sensor 'imu': 100 Hz is above the engine's step rate")


if __name__ == "__main__":
    unittest.main()
