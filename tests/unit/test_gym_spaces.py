"""Unit tests of convoy_gym.spaces (no simulation): the fallback Box, Discrete and Dict have
gymnasium's attributes, sample() is reproducible from seed() and lies in the space,
contains() checks shape, dtype and bounds.

Run: cd tests/unit && PYTHONPATH=../../python /usr/bin/python3 -m unittest -v test_gym_spaces"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from convoy_gym import spaces  # noqa: E402
from convoy_gym.spaces import Box, Dict, Discrete  # noqa: E402


class BoxTest(unittest.TestCase):
    def test_attributes(self):
        box = Box(low=np.array([-1.0, 0.0]), high=np.array([1.0, 5.0]), dtype=np.float32)
        self.assertEqual(box.shape, (2,))
        self.assertEqual(box.dtype, np.float32)
        self.assertEqual(box.low.dtype, np.float32)
        np.testing.assert_array_equal(box.high, [1.0, 5.0])
        scalar = Box(-2.0, 2.0, shape=(3, 4))
        self.assertEqual(scalar.shape, (3, 4))
        self.assertEqual(scalar.low.shape, (3, 4))

    def test_sample_seeded_and_inside(self):
        box = Box(low=np.array([-1.0, 0.0, -np.inf, 0.0]),
                  high=np.array([1.0, 5.0, np.inf, np.inf]), dtype=np.float32)
        box.seed(3)
        a = [box.sample() for _ in range(200)]
        box.seed(3)
        b = [box.sample() for _ in range(200)]
        np.testing.assert_array_equal(a, b)
        box.seed(4)
        self.assertFalse(np.array_equal(a[0], box.sample()))
        for x in a:
            self.assertEqual(x.shape, (4,))
            self.assertEqual(x.dtype, np.float32)
            self.assertTrue(box.contains(x), x)

    def test_seed_in_constructor(self):
        np.testing.assert_array_equal(Box(0.0, 1.0, shape=(5,), seed=9).sample(),
                                      Box(0.0, 1.0, shape=(5,), seed=9).sample())

    def test_contains(self):
        box = Box(low=np.array([-1.0, 0.0]), high=np.array([1.0, 5.0]), dtype=np.float32)
        self.assertTrue(box.contains(np.array([0.5, 5.0], dtype=np.float32)))
        self.assertTrue(box.contains([0.0, 0.0]))
        self.assertIn(np.array([0.0, 1.0], dtype=np.float32), box)
        self.assertFalse(box.contains(np.array([1.5, 1.0], dtype=np.float32)))
        self.assertFalse(box.contains(np.array([0.0, -0.1], dtype=np.float32)))
        self.assertFalse(box.contains(np.array([0.0, 1.0, 2.0], dtype=np.float32)))
        self.assertFalse(box.contains(np.array([0.0, 1.0])))  # float64 does not cast safely
        self.assertFalse(box.contains(["a", "b"]))

    def test_integer_box(self):
        box = Box(0, 3, shape=(6,), dtype=np.int64, seed=1)
        values = np.concatenate([box.sample() for _ in range(100)])
        self.assertEqual(values.dtype, np.int64)
        self.assertEqual(set(values.tolist()), {0, 1, 2, 3})

    def test_low_above_high(self):
        if spaces.USING_GYMNASIUM:
            self.skipTest("gymnasium's Box")
        with self.assertRaises(ValueError):
            Box(np.array([1.0]), np.array([0.0]))


class DiscreteTest(unittest.TestCase):
    def test_attributes_and_sample(self):
        d = Discrete(5, seed=2)
        self.assertEqual(d.n, 5)
        self.assertEqual(d.shape, ())
        self.assertEqual(d.dtype, np.int64)
        a = [d.sample() for _ in range(100)]
        d.seed(2)
        self.assertEqual(a, [d.sample() for _ in range(100)])
        self.assertEqual(set(int(v) for v in a), {0, 1, 2, 3, 4})
        self.assertTrue(all(d.contains(v) for v in a))

    def test_contains(self):
        d = Discrete(3, start=1)
        self.assertTrue(d.contains(1))
        self.assertTrue(d.contains(np.int64(3)))
        self.assertFalse(d.contains(0))
        self.assertFalse(d.contains(4))
        self.assertFalse(d.contains(1.5))
        self.assertFalse(d.contains("1"))


class DictTest(unittest.TestCase):
    def test_sample_contains_seed(self):
        space = Dict({"ego": Box(-1.0, 1.0, shape=(3,)), "lane": Discrete(3)})
        self.assertEqual(set(space.keys()), {"ego", "lane"})
        self.assertIs(space["lane"], space.spaces["lane"])
        space.seed(5)
        a = space.sample()
        space.seed(5)
        b = space.sample()
        np.testing.assert_array_equal(a["ego"], b["ego"])
        self.assertEqual(a["lane"], b["lane"])
        self.assertTrue(space.contains(a))
        self.assertFalse(space.contains({"ego": a["ego"]}))
        self.assertFalse(space.contains({"ego": a["ego"] * 3, "lane": a["lane"]}))


if __name__ == "__main__":
    unittest.main()
