"""Unit tests of python/convoy_sensors/birds_eye.py: a scan drawn from above coloured by class,
and the run folder's PNG and .npy, rewritten at most once a period of the scans' time."""

import os
import struct
import tempfile
import unittest
from types import SimpleNamespace

import numpy as np

from convoy_sensors import birds_eye as be
from convoy_sensors import point_cloud as pc


def record(x, y, z, intensity, instance, flags=0):
    return struct.pack("<4f2I2HI", x, y, z, intensity, instance, 1 if instance else 0, 0, 0,
                       flags)


def message(t_s, records):
    raw = b"".join(records)
    return SimpleNamespace(time_ns=int(t_s * 1e9), point_step=32, fields=[], points=raw,
                           count=len(raw) // 32, frame="car::body::lidar",
                           instances={5: SimpleNamespace(model="car_1", class_name="car")})


class Render(unittest.TestCase):
    def test_pixels_by_class_and_position(self):
        m = message(0, [record(10, 0, 0, 0.5, 5),       # a car 10 m ahead: up
                        record(0, -10, 0, 1.0, 0),      # ground 10 m right: right, grey
                        record(-10, 0, 0, 0.2, 0, 1)])  # a rain return behind: down
        img = be.render(pc.points(m), {5: "car"}, size=200, metres=20)
        self.assertEqual(img.shape, (200, 200, 3))
        self.assertEqual(tuple(img[50, 100]), be.CLASS_COLOURS["car"])  # row 100 - 10 * 5
        self.assertEqual(tuple(img[100, 150]), (255, 255, 255))       # intensity 1
        self.assertEqual(tuple(img[150, 100]), be.WEATHER)
        self.assertEqual(tuple(img[100, 100]), (255, 255, 0))          # the sensor
        self.assertEqual(int(img[0:40, 0:40].sum()), 0)

    def test_points_outside_are_left_out(self):
        m = message(0, [record(100, 100, 0, 1.0, 5)])
        img = be.render(pc.points(m), {}, size=100, metres=10)
        img[47:54, 49:52] = 0  # the sensor's mark
        self.assertEqual(int(img.sum()), 0)


class RunFolder(unittest.TestCase):
    def test_png_and_npy_once_a_period(self):
        with tempfile.TemporaryDirectory() as d:
            view = be.RunFolderView("car::body::lidar", period=1.0, size=100, run_dir=d)
            self.assertTrue(view.update(message(0.0, [record(1, 0, 0, 0.5, 5)])))
            png = os.path.join(d, "lidar_car_body_lidar.png")
            with open(png, "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
            self.assertFalse(view.update(message(0.5, [record(2, 0, 0, 0.5, 5)])))
            self.assertTrue(view.update(message(1.0, [record(3, 0, 0, 0.5, 5),
                                                      record(4, 0, 0, 0.5, 0)])))
            saved = np.load(os.path.join(d, "lidar_car_body_lidar.npy"))
            self.assertEqual(saved["x"].tolist(), [3.0, 4.0])
            self.assertEqual(view.scans, 3)
            self.assertFalse(view.update(message(2.0, [])))  # an empty scan draws nothing


if __name__ == "__main__":
    unittest.main()
