"""End-to-end test of the ROS bridge's sensor topics (issue 27; engines/ros_bridge,
docs/ros.md): a small world whose box carries a LiDAR, an IMU and a GNSS receiver mounted by the
world engine's Sensors list; a TF sends their datapacks to the ros_bridge engine, and a rospy
node in another process (with a master the test starts; it answers each step on /cmd_vel, so
the run waits for it) records what arrives:
sensor_msgs/PointCloud2 on /convoy/points (fields x y z intensity instance label ring column
flags, the crate's returns at 4.5 m, frame renamed by SensorFrames), sensor_msgs/Imu on
/convoy/imu (+g up at rest), sensor_msgs/NavSatFix on /convoy/fix, stamped with sim time.

Run:  cd tests/e2e && /usr/bin/python3 -m unittest -v test_ros_sensors"""

import json
import os
import time
import unittest
import xmlrpc.client

from e2e_util import REPO
from test_ros import RosTestCase

WORLD = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="ros_sensors">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <spherical_coordinates><latitude_deg>48.2</latitude_deg><longitude_deg>16.37</longitude_deg>
      <elevation>180</elevation></spherical_coordinates>
    <model name="ground"><static>true</static><link name="link">
      <collision name="c"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></collision>
      <visual name="v"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></visual>
    </link></model>
    <model name="crate"><static>true</static><pose>5 0 1 0 0 0</pose><link name="body">
      <collision name="c"><geometry><box><size>1 3 2</size></box></geometry></collision>
      <visual name="v"><geometry><box><size>1 3 2</size></box></geometry></visual></link>
      <plugin name="convoy_class" filename="convoy_class"><class>barrier</class></plugin>
    </model>
    <model name="sensor_box"><static>true</static><pose>0 0 0.5 0 0 0</pose>
      <link name="body"><inertial><mass>1</mass></inertial>
        <visual name="v"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></visual>
      </link></model>
  </world>
</sdf>
"""

TF = """
import sys
sys.path.insert(0, {python!r})
from nrp_core import *

NAMES = {{"scan": "/convoy/points", "imu": "/convoy/imu", "gnss": "/convoy/fix"}}

@EngineDataPack(keyword="scan", id=DataPackIdentifier("sensor_box::body::lidar", "gazebo"))
@EngineDataPack(keyword="imu", id=DataPackIdentifier("sensor_box::body::imu", "gazebo"))
@EngineDataPack(keyword="gnss", id=DataPackIdentifier("sensor_box::body::gnss", "gazebo"))
@TransceiverFunction("ros")
def to_ros(scan, imu, gnss):
    out = []
    for key, dp in (("scan", scan), ("imu", imu), ("gnss", gnss)):
        if dp is None or dp.isEmpty():
            continue
        copy = type(dp)(NAMES[key], "ros")
        copy.data = dp.data
        out.append(copy)
    return out
"""

NODE = """
import json, sys, threading
import rospy
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Imu, NavSatFix, PointCloud2
import sensor_msgs.point_cloud2 as pc2

out = open(sys.argv[1], "a")
lock = threading.Lock()
seen, pending = set(), [False]

def answer():
    # Each step once the three topics are connected (their latched messages came): the run
    # waits for the listener instead of ending before ROS has connected it.
    with lock:
        if pending[0] and len(seen) == 3:
            pending[0] = False
            reply.publish(Twist())

def write(rec):
    with lock:
        seen.add(rec["topic"])
        out.write(json.dumps(rec) + "\\n")
        out.flush()
    answer()

def on_clock(m):
    with lock:
        pending[0] = True
    answer()

def on_points(m):
    pts = list(pc2.read_points(m, field_names=("x", "y", "z", "instance", "ring")))
    box = [p for p in pts if p[3] != 0]
    write({{"topic": "points", "stamp": m.header.stamp.to_sec(), "frame": m.header.frame_id,
           "fields": [f.name for f in m.fields], "width": m.width,
           "rings": sorted({{p[4] for p in pts}}),
           "box_x": [min(p[0] for p in box), max(p[0] for p in box)] if box else None}})

def on_imu(m):
    write({{"topic": "imu", "stamp": m.header.stamp.to_sec(), "frame": m.header.frame_id,
           "az": m.linear_acceleration.z, "ocov0": m.orientation_covariance[0]}})

def on_fix(m):
    write({{"topic": "fix", "stamp": m.header.stamp.to_sec(), "frame": m.header.frame_id,
           "lat": m.latitude, "lon": m.longitude, "alt": m.altitude}})

rospy.init_node("sensor_listener")
reply = rospy.Publisher("/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
rospy.Subscriber("/convoy/points", PointCloud2, on_points, tcp_nodelay=True)
rospy.Subscriber("/convoy/imu", Imu, on_imu, tcp_nodelay=True)
rospy.Subscriber("/convoy/fix", NavSatFix, on_fix, tcp_nodelay=True)
rospy.Subscriber("/clock", Clock, on_clock, tcp_nodelay=True)
rospy.spin()
"""


class Sensors(RosTestCase):
    def wait_for_subscriber(self, topic, within=15.0):
        deadline = time.monotonic() + within
        while time.monotonic() < deadline:
            with xmlrpc.client.ServerProxy(self.uri) as master:
                _, _, (pubs, subs, _) = master.getSystemState("/e2e")
            if any(t == topic for t, _ in subs):
                return
            time.sleep(0.1)
        self.fail("the listener did not subscribe to %s: %s" % (topic,
                                                                self.read_file("node.log")))

    def test_point_cloud_imu_and_fix_arrive(self):
        self.write("world.sdf", WORLD)
        self.write("to_ros.py", TF.format(python=os.path.join(REPO, "python")))
        self.write("listener.py", NODE.format())
        mount = {"Model": "sensor_box", "Link": "body"}
        self.write_config({
            "SimulationName": "ros_sensors", "SimulationTimeout": 1.0,
            "EngineConfigs": [
                {"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                 "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.05,
                 "Sensors": [
                     dict(mount, Type="gpu_lidar", Name="lidar", Pose=[0, 0, 0.5, 0, 0, 0],
                          HorizontalSamples=361, HorizontalMinAngle=-0.6,
                          HorizontalMaxAngle=0.6, VerticalSamples=5, VerticalMinAngle=-0.1,
                          VerticalMaxAngle=0.1, RangeMin=0.3, RangeMax=40),
                     dict(mount, Type="imu", Name="imu", UpdateRate=20),
                     dict(mount, Type="navsat", Name="gnss", UpdateRate=10)]},
                {"EngineType": "ros_bridge", "EngineName": "ros", "EngineTimestep": 0.05,
                 "StartMaster": False, "SyncTopic": "/cmd_vel", "SyncTimeout": 5,
                 "Subscribe": [{"Topic": "/cmd_vel", "Type": "geometry_msgs/Twist"}],
                 "SensorFrames": {"sensor_box::body::lidar": "velodyne"}}],
            "DataPackProcessingFunctions": [{"Name": "to_ros", "FileName": "to_ros.py"}]})
        self.start_master()
        seen_path = os.path.join(self.dir, "seen.jsonl")
        self.spawn(["/usr/bin/python3", os.path.join(self.dir, "listener.py"), seen_path],
                   "node.log")
        self.wait_for_subscriber("/convoy/fix")
        run_dir = os.path.join(self.dir, "run")
        r = self.run_env(["-q", "-c", os.path.join(self.dir, "simulation_config.json"),
                          "--run-dir", run_dir], timeout=120)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertNothingLeft(run_dir)
        time.sleep(1.0)  # the last messages reach the listener
        with open(seen_path) as f:
            seen = [json.loads(line) for line in f]
        by = {t: [s for s in seen if s["topic"] == t] for t in ("points", "imu", "fix")}
        self.assertTrue(all(by.values()), "missing topics: %s\n%s" % (
            {t: len(v) for t, v in by.items()}, self.read_file("node.log")))
        p = by["points"][-1]
        self.assertEqual(p["fields"], ["x", "y", "z", "intensity", "instance", "label", "ring",
                                       "column", "flags"])
        self.assertEqual(p["frame"], "velodyne")
        self.assertEqual(p["rings"], [0, 1, 2, 3, 4])
        self.assertAlmostEqual(p["box_x"][0], 4.5, delta=0.02)
        self.assertAlmostEqual(p["box_x"][1], 4.5, delta=0.02)
        stamps = sorted({s["stamp"] for s in by["points"]})
        self.assertIn(0.0, stamps)
        self.assertTrue(all(abs(s * 10 - round(s * 10)) < 1e-6 for s in stamps))  # 10 Hz scans
        imu = by["imu"][-1]
        self.assertEqual(imu["frame"], "sensor_box::body::imu")
        self.assertAlmostEqual(imu["az"], 9.8, delta=0.05)
        self.assertGreater(len({s["stamp"] for s in by["imu"]}), 3)
        fix = by["fix"][-1]
        self.assertAlmostEqual(fix["lat"], 48.2, delta=1e-5)
        self.assertAlmostEqual(fix["lon"], 16.37, delta=1e-5)
        self.assertAlmostEqual(fix["alt"], 180.5, delta=0.01)  # the link 0.5 m up


if __name__ == "__main__":
    unittest.main()
