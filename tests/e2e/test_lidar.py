"""End-to-end tests of the world engine's LiDARs (issue 27; engines/gazebo_grpc/systems/
lidar_sensors.h): a small SDF world (a ground plane, a box 4.5 m ahead of the sensor, a model
carrying a gpu_lidar) and a TF that reads the PointCloud datapack with
python/convoy_sensors/point_cloud.py and writes what it saw to a file.

Cloud: the box's returns lie at its face's range (noise off, within 2 cm), are labelled with
its class, the sensor's own model is not in them, and two runs give the same clouds bit for bit.
BadInput: zero samples, a negative range, an update rate above the step rate: the run stops
before it starts, the message names the model, link and sensor, no process is left.

Run with Debian's /usr/bin/python3 -m unittest test_lidar."""

import json
import os
import unittest

from e2e_util import REPO, E2ETestCase

EXIT_USER = 2  # the world engine refuses its world in initialize: the user's input (see BadInput)

LIDAR = """
        <sensor name="lidar" type="gpu_lidar">
          <pose>0 0 0.5 0 0 0</pose>
          <update_rate>{rate}</update_rate>
          <lidar>
            <scan>
              <horizontal><samples>{samples}</samples><resolution>1</resolution>
                <min_angle>-0.6</min_angle><max_angle>0.6</max_angle></horizontal>
              <vertical><samples>5</samples><resolution>1</resolution>
                <min_angle>-0.1</min_angle><max_angle>0.1</max_angle></vertical>
            </scan>
            <range><min>{range_min}</min><max>40</max><resolution>0.01</resolution></range>
          </lidar>
        </sensor>"""

WORLD = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="lidar_test">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <model name="ground">
      <static>true</static>
      <link name="link">
        <collision name="c"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></collision>
        <visual name="v"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></visual>
      </link>
    </model>
    <model name="crate">
      <static>true</static>
      <pose>5 0 1 0 0 0</pose>
      <link name="body">
        <collision name="c"><geometry><box><size>1 3 2</size></box></geometry></collision>
        <visual name="v"><geometry><box><size>1 3 2</size></box></geometry></visual>
      </link>
      <plugin name="convoy_class" filename="convoy_class"><class>barrier</class></plugin>
    </model>
    <model name="sensor_car">
      <static>true</static>
      <pose>0 0 0.5 0 0 0</pose>
      <link name="lidar_link">
        <inertial><mass>1</mass></inertial>
        <visual name="v"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></visual>
        <!-- a part of the sensor's own model in its view (-0.46 rad, beside the crate): its
             returns are left out -->
        <visual name="mirror"><pose>2 -1 0.5 0 0 0</pose>
          <geometry><box><size>0.3 0.3 1</size></box></geometry></visual>{lidar}
      </link>
    </model>
  </world>
</sdf>
"""

TF = """
import hashlib, json, os, sys
sys.path.insert(0, {python!r})
from nrp_core import *
from convoy_sensors.point_cloud import points, instances

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seen.jsonl")

@EngineDataPack(keyword="scan", id=DataPackIdentifier("sensor_car::lidar_link::lidar", "gazebo"))
@TransceiverFunction("gazebo")
def look(scan):
    if scan is None or scan.isEmpty():
        return []
    p = points(scan)
    gt = instances(scan)
    box = p[p["instance"] != 0]
    rec = {{"time_ns": scan.data.time_ns, "count": int(len(p)), "rings": scan.data.rings,
           "columns": scan.data.columns, "frame": scan.data.frame,
           "box_points": int(len(box)),
           "box_x": [float(box["x"].min()), float(box["x"].max())] if len(box) else None,
           "classes": sorted({{gt[int(i)][1] for i in box["instance"]}}),
           "models": sorted({{gt[int(i)][0] for i in box["instance"]}}),
           "labels": sorted({{int(l) for l in box["label"]}}),
           "sha": hashlib.sha256(bytes(scan.data.points)).hexdigest()}}
    with open(OUT, "a") as f:
        f.write(json.dumps(rec) + "\\n")
    return []
"""


class LidarCase(E2ETestCase):
    def experiment(self, rate=10, samples=721, range_min=0.3, timestep=0.05, timeout=0.5):
        lidar = LIDAR.format(rate=rate, samples=samples, range_min=range_min)
        self.write("world.sdf", WORLD.format(lidar=lidar))
        self.write("look.py", TF.format(python=os.path.join(REPO, "python")))
        self.write_config({"SimulationName": "lidar", "SimulationTimeout": timeout,
                           "EngineConfigs": [{"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                                              "GazeboWorldFile": "world.sdf", "GazeboRNGSeed": 7,
                                              "EngineTimestep": timestep}],
                           "DataPackProcessingFunctions": [{"Name": "look", "FileName": "look.py"}]})

    def seen(self):
        with open(os.path.join(self.dir, "seen.jsonl")) as f:
            return [json.loads(line) for line in f]


class Cloud(LidarCase):
    def run_once(self):
        self.experiment()
        path = os.path.join(self.dir, "seen.jsonl")
        if os.path.exists(path):
            os.remove(path)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, 0)
        self.assertNoEngineLeft()
        return self.seen()

    def test_returns_hit_the_box_at_its_range_with_its_class(self):
        seen = self.run_once()
        self.assertGreaterEqual(len(seen), 3)
        scans = {s["time_ns"]: s for s in seen}
        self.assertGreaterEqual(len(scans), 3)  # 10 Hz over 0.5 s
        last = seen[-1]
        self.assertEqual((last["rings"], last["columns"]), (5, 721))
        self.assertGreaterEqual(last["count"] * 32, 32 * 1024)  # the points travel as a blob
        self.assertEqual(last["frame"], "sensor_car::lidar_link::lidar")
        # The crate's face is 4.5 m ahead of the sensor (at 5 m, 1 m deep), 2 m tall and 3 m
        # wide: every ring sees it over about +-0.32 rad.
        self.assertGreater(last["box_points"], 1000)
        lo, hi = last["box_x"]
        self.assertAlmostEqual(lo, 4.5, delta=0.02)
        self.assertAlmostEqual(hi, 4.5, delta=0.02)
        self.assertEqual(last["classes"], ["barrier"])
        self.assertEqual(last["models"], ["crate"])  # not the sensor's own model, not the ground
        self.assertEqual(len(last["labels"]), 1)

    def test_two_runs_identical(self):
        a = [(s["time_ns"], s["sha"]) for s in self.run_once()]
        b = [(s["time_ns"], s["sha"]) for s in self.run_once()]
        self.assertTrue(a)
        self.assertEqual(a, b)


class BadInput(LidarCase):
    def check(self, *needles, **kw):
        self.experiment(**kw)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, EXIT_USER)
        self.assertStderrHas(r, "model 'sensor_car' link 'lidar_link' sensor 'lidar'", *needles)
        self.assertOneError(r)
        self.assertNoEngineLeft()
        self.assertFalse(os.path.exists(os.path.join(self.dir, "seen.jsonl")))

    def test_zero_samples(self):
        self.check("<samples>", "at least 1", samples=0)

    def test_negative_range(self):
        self.check("<range><min>", "-1", range_min=-1)

    def test_update_rate_above_the_step_rate(self):
        self.check("<update_rate>", "1000", rate=1000, timestep=0.01)


if __name__ == "__main__":
    unittest.main()
