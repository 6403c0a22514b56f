"""End-to-end tests of the world engine's IMUs and GNSS receivers (issue 27; engines/
gazebo_grpc/systems/nav_sensors.h, src/nav_sensors): a small SDF world placed on the Earth by
<spherical_coordinates>, a box dropped from 2 m carrying an IMU and a navsat, a static model
rolled 90 degrees carrying another IMU, and a TF that writes every reading to a file.

Readings: in free fall the accelerometer reads about 0 and, once the box rests on the ground,
+g upwards; the rolled IMU reads g on its y axis; the GNSS reads the box's position as WGS84
latitude and longitude (checked against an independent conversion) and its falling speed;
the accelerometer's noise has its SDF standard deviation; two runs read the same bit for bit.
BadInput: an IMU faster than the engine's step rate (the message names the model, link and
sensor), a latitude beyond the pole (the world and the field), a negative noise deviation
(libsdformat's message: the file, line and element): the run stops before it starts, no
process is left.

Run with Debian's /usr/bin/python3 -m unittest test_nav_sensors."""

import json
import math
import os
import statistics
import unittest

from e2e_util import REPO, E2ETestCase

EXIT_USER = 2  # the world engine refuses its world in initialize: the user's input
LAT0, LON0, ELEV0 = 48.2082, 16.3738, 171.0

NOISE = ("<noise type=\"gaussian\"><mean>0</mean><stddev>{stddev}</stddev>"
         "<bias_mean>0</bias_mean><bias_stddev>{bias_stddev}</bias_stddev></noise>")

IMU = """
        <sensor name="imu" type="imu">
          <update_rate>{rate}</update_rate>
          <imu><linear_acceleration><z>{noise}</z></linear_acceleration></imu>
        </sensor>"""

WORLD = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="nav_test">
    <physics type="ode"><max_step_size>0.001</max_step_size></physics>
    <spherical_coordinates>
      <surface_model>EARTH_WGS84</surface_model>
      <world_frame_orientation>ENU</world_frame_orientation>
      <latitude_deg>{lat}</latitude_deg><longitude_deg>{lon}</longitude_deg>
      <elevation>{elev}</elevation><heading_deg>0</heading_deg>
    </spherical_coordinates>
    <model name="ground">
      <static>true</static>
      <link name="link">
        <collision name="c"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></collision>
      </link>
    </model>
    <model name="box">
      <pose>300 -400 2 0 0 0</pose>
      <link name="body">
        <inertial><mass>10</mass></inertial>
        <collision name="c"><geometry><box><size>1 1 1</size></box></geometry></collision>{imu}
        <sensor name="gnss" type="navsat"><update_rate>20</update_rate></sensor>
      </link>
    </model>
    <model name="rolled">
      <static>true</static>
      <pose>0 5 1 1.5707963267948966 0 0</pose>
      <link name="body">
        <sensor name="imu" type="imu"/>
        <sensor name="gnss" type="navsat"/>
      </link>
    </model>
  </world>
</sdf>
"""

TF = """
import json, os
from nrp_core import *

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seen.jsonl")

@EngineDataPack(keyword="imu", id=DataPackIdentifier("box::body::imu", "gazebo"))
@EngineDataPack(keyword="rolled", id=DataPackIdentifier("rolled::body::imu", "gazebo"))
@EngineDataPack(keyword="gnss", id=DataPackIdentifier("box::body::gnss", "gazebo"))
@EngineDataPack(keyword="still", id=DataPackIdentifier("rolled::body::gnss", "gazebo"))
@TransceiverFunction("gazebo")
def look(imu, rolled, gnss, still):
    rec = {{}}
    for name, dp in (("imu", imu), ("rolled", rolled)):
        if dp is not None and not dp.isEmpty():
            d = dp.data
            rec[name] = {{"t": d.time_ns, "acc": list(d.linear_acceleration),
                          "gyro": list(d.angular_velocity), "q": list(d.orientation),
                          "frame": d.frame}}
    for name, dp in (("gnss", gnss), ("still", still)):
        if dp is None or dp.isEmpty():
            continue
        d = dp.data
        rec[name] = {{"t": d.time_ns, "lat": d.latitude_deg, "lon": d.longitude_deg,
                        "alt": d.altitude, "v": [d.velocity_east, d.velocity_north,
                                                 d.velocity_up]}}
    with open(OUT, "a") as f:
        f.write(json.dumps(rec) + "\\n")
    return []
"""


def wgs84(east, north, up):
    """An independent ENU -> geodetic conversion (WGS84, Bowring's iteration in Python)."""
    a, f = 6378137.0, 1 / 298.257223563
    e2 = f * (2 - f)
    lat0, lon0 = math.radians(LAT0), math.radians(LON0)

    def ecef(lat, lon, h):
        n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
        return ((n + h) * math.cos(lat) * math.cos(lon), (n + h) * math.cos(lat) * math.sin(lon),
                (n * (1 - e2) + h) * math.sin(lat))

    x0, y0, z0 = ecef(lat0, lon0, ELEV0)
    sl, cl, so, co = math.sin(lat0), math.cos(lat0), math.sin(lon0), math.cos(lon0)
    x = x0 - so * east - sl * co * north + cl * co * up
    y = y0 + co * east - sl * so * north + cl * so * up
    z = z0 + cl * north + sl * up
    p = math.hypot(x, y)
    lat = math.atan2(z, p * (1 - e2))
    for _ in range(10):
        n = a / math.sqrt(1 - e2 * math.sin(lat) ** 2)
        lat = math.atan2(z + e2 * n * math.sin(lat), p)
    return math.degrees(lat), math.degrees(math.atan2(y, x))


class NavCase(E2ETestCase):
    def experiment(self, stddev=0.05, bias_stddev=0, rate=100, timestep=0.01, timeout=1.5):
        imu = IMU.format(rate=rate, noise=NOISE.format(stddev=stddev, bias_stddev=bias_stddev))
        self.write("world.sdf", WORLD.format(lat=LAT0, lon=LON0, elev=ELEV0, imu=imu))
        self.write("look.py", TF.format())
        self.write_config({"SimulationName": "nav", "SimulationTimeout": timeout,
                           "EngineConfigs": [{"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                                              "GazeboWorldFile": "world.sdf", "GazeboRNGSeed": 3,
                                              "EngineTimestep": timestep}],
                           "DataPackProcessingFunctions": [{"Name": "look", "FileName": "look.py"}]})

    def run_once(self, **kw):
        self.experiment(**kw)
        path = os.path.join(self.dir, "seen.jsonl")
        if os.path.exists(path):
            os.remove(path)
        r = self.run_convoy(timeout=60)
        self.assertExit(r, 0)
        self.assertNoEngineLeft()
        with open(path) as f:
            return [json.loads(line) for line in f]


class Readings(NavCase):
    def test_free_fall_rest_roll_and_position(self):
        seen = self.run_once()
        imu = [s["imu"] for s in seen if "imu" in s]
        self.assertGreater(len(imu), 100)
        self.assertEqual(imu[-1]["frame"], "box::body::imu")
        # Dropped from 2 m (its bottom 1.5 m up): about 0.55 s of free fall, reading ~0.
        falling = [r["acc"][2] for r in imu if 0.1e9 <= r["t"] <= 0.45e9]
        resting = [r["acc"][2] for r in imu if r["t"] >= 1.0e9]
        self.assertLess(abs(statistics.mean(falling)), 0.1, falling)
        self.assertAlmostEqual(statistics.mean(resting), 9.8, delta=0.1)
        self.assertAlmostEqual(statistics.stdev(resting), 0.05, delta=0.02)  # its SDF noise
        for axis in (0, 1):  # level: nothing sideways, but the contacts' jitter
            self.assertLess(abs(statistics.mean(r["acc"][axis] for r in imu if r["t"] >= 1.0e9)),
                            0.05)
        self.assertEqual(len(imu[-1]["q"]), 4)
        rolled = [s["rolled"] for s in seen if "rolled" in s][-1]
        self.assertAlmostEqual(rolled["acc"][1], 9.8, delta=1e-6)
        self.assertAlmostEqual(rolled["acc"][2], 0.0, delta=1e-6)
        still = [s["still"] for s in seen if "still" in s][-1]
        lat, lon = wgs84(0, 5, 1)
        self.assertAlmostEqual(still["lat"], lat, delta=1e-8)  # ~1 mm
        self.assertAlmostEqual(still["lon"], lon, delta=1e-8)
        self.assertAlmostEqual(still["alt"], ELEV0 + 1, delta=0.001)
        gnss = [s["gnss"] for s in seen if "gnss" in s]
        lat, lon = wgs84(300, -400, 0.5)
        self.assertAlmostEqual(gnss[-1]["lat"], lat, delta=1e-7)  # ~1 cm: where it landed
        self.assertAlmostEqual(gnss[-1]["lon"], lon, delta=1e-7)
        self.assertAlmostEqual(gnss[-1]["alt"], ELEV0 + 0.5, delta=0.05)
        fall = [g for g in gnss if 0.2e9 <= g["t"] <= 0.4e9]
        self.assertTrue(fall)
        for g in fall:  # v = -g t while it falls
            self.assertAlmostEqual(g["v"][2], -9.8 * g["t"] * 1e-9, delta=0.15)

    def test_same_seed_same_readings(self):
        self.assertEqual(self.run_once(timeout=0.5), self.run_once(timeout=0.5))


class BadInput(NavCase):
    def assertRefused(self, r, *parts):
        self.assertExit(r, EXIT_USER)
        for p in parts:
            self.assertIn(p, r.stderr, r)
        self.assertNoEngineLeft()

    def test_negative_noise(self):  # libsdformat's own check: file, line and element
        self.experiment(bias_stddev=-1)
        self.assertRefused(self.run_convoy(timeout=60), "world.sdf:24: Error reading element "
                           "<bias_stddev>")

    def test_latitude_beyond_the_pole(self):
        self.experiment()
        world = os.path.join(self.dir, "world.sdf")
        with open(world) as f:
            text = f.read().replace("<latitude_deg>%s<" % LAT0, "<latitude_deg>95<")
        with open(world, "w") as f:
            f.write(text)
        self.assertRefused(self.run_convoy(timeout=60), "world 'nav_test': spherical_coordinates: "
                           "latitude_deg: 95")

    def test_rate_above_the_step_rate(self):
        self.experiment(rate=1000, timestep=0.01)
        self.assertRefused(self.run_convoy(timeout=60), "model 'box' link 'body' sensor 'imu': "
                           "<update_rate>: 1000 Hz is above the engine's step rate")


if __name__ == "__main__":
    unittest.main()
