"""Unit tests of python/convoy_sensors/point_cloud.py: the 32-byte records of
src/lidar/point_cloud.h read as a numpy structured array without a copy."""

import struct
import unittest
from types import SimpleNamespace

import numpy as np

from convoy_sensors import point_cloud as pc

FIELDS = [("x", 0, "<f4"), ("y", 4, "<f4"), ("z", 8, "<f4"), ("intensity", 12, "<f4"),
          ("instance", 16, "<u4"), ("label", 20, "<u4"), ("ring", 24, "<u2"),
          ("column", 26, "<u2"), ("flags", 28, "<u4")]


def record(x, y, z, intensity, instance, label, ring, column, flags):
    # As the C++ struct lays it out (little-endian, no padding).
    return struct.pack("<4f2I2HI", x, y, z, intensity, instance, label, ring, column, flags)


def message(raw, with_fields=True):
    fields = [SimpleNamespace(name=n, offset=o, dtype=d) for n, o, d in FIELDS] if with_fields else []
    inst = {3: SimpleNamespace(model="box", class_name="barrier")}
    return SimpleNamespace(time_ns=100, point_step=32, fields=fields, points=raw, rings=2,
                           columns=4, count=len(raw) // 32, instances=inst)


class PointCloudView(unittest.TestCase):
    def setUp(self):
        self.raw = record(1.5, -2.0, 0.25, 0.5, 3, 8, 1, 2, 0) + record(0, 0, 3, 0.03, 0, 0, 0, 3, 1)

    def test_fields_and_values(self):
        p = pc.points(message(self.raw))
        self.assertEqual(p.dtype.itemsize, 32)
        self.assertEqual(len(p), 2)
        self.assertAlmostEqual(float(p["x"][0]), 1.5)
        self.assertAlmostEqual(float(p["y"][0]), -2.0)
        self.assertEqual(int(p["instance"][0]), 3)
        self.assertEqual(int(p["label"][0]), 8)
        self.assertEqual((int(p["ring"][0]), int(p["column"][0])), (1, 2))
        self.assertEqual(int(p["flags"][1]), 1)
        np.testing.assert_allclose(pc.xyz(message(self.raw))[1], [0, 0, 3])

    def test_no_copy_and_read_only(self):
        m = message(self.raw)
        p = pc.points(m)
        self.assertFalse(p.flags.owndata)
        self.assertFalse(p.flags.writeable)
        self.assertTrue(np.shares_memory(p, np.frombuffer(m.points, np.uint8)))

    def test_datapack_wrapper_and_default_layout(self):
        dp = SimpleNamespace(data=message(self.raw, with_fields=False))
        p = pc.points(dp)
        self.assertEqual(p.dtype, pc.DTYPE)
        self.assertEqual(pc.dtype_of(message(self.raw)), pc.DTYPE)
        self.assertEqual(pc.instances(dp), {3: ("box", "barrier")})

    def test_empty_and_bad_sizes(self):
        self.assertEqual(len(pc.points(message(b""))), 0)
        with self.assertRaises(ValueError):
            pc.points(message(self.raw[:40]))
        with self.assertRaises(TypeError):
            pc.points(SimpleNamespace(foo=1))


if __name__ == "__main__":
    unittest.main()
