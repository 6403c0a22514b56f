"""Unit tests of the detector's training code (tools/detector): the necks, the synthetic fog
and darkness of train.weather_augment and the input's gain (gain.py)."""
import os
import random
import sys
import tempfile
import unittest

import cv2
import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "tools", "detector"))

import torch  # noqa: E402
import gain  # noqa: E402
import model  # noqa: E402
import train  # noqa: E402


def dataset_image(folder, depth_mm):
    """A grey 40 x 30 image at folder/images/f.jpg with the given depth (uint16 mm) beside it."""
    os.makedirs(os.path.join(folder, "images"))
    os.makedirs(os.path.join(folder, "depth"))
    path = os.path.join(folder, "images", "f.jpg")
    cv2.imwrite(path, np.full((30, 40, 3), 60, np.uint8))
    cv2.imwrite(os.path.join(folder, "depth", "f.png"), depth_mm.astype(np.uint16))
    return path


class Necks(unittest.TestCase):
    def test_both_necks_give_the_same_output_layout(self):
        for neck in ("separable", "dense"):
            d = model.Detector(5, input_size=(128, 96), neck=neck).eval()
            out = d(torch.zeros(1, 3, 96, 128))
            self.assertEqual(tuple(out.shape), (1, 9, sum((128 // s) * (96 // s) for s in (8, 16, 32))))

    def test_the_separable_neck_is_depthwise_and_smaller(self):
        sep = model.Detector(5, neck="separable")
        dense = model.Detector(5, neck="dense")
        self.assertEqual(sep.fuse3[0].groups, sep.fuse3[0].in_channels)
        count = lambda m: sum(p.numel() for p in m.parameters())  # noqa: E731
        self.assertLess(count(sep), 0.6 * count(dense))

    def test_an_unknown_neck_is_named(self):
        with self.assertRaisesRegex(ValueError, "neck: 'wide'"):
            model.Detector(5, neck="wide")


class WeatherAugment(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="convoy-augment-")
        depth = np.full((30, 40), 2000, np.uint16)  # 2 m on the left half
        depth[:, 20:] = 65535  # nothing hit (the sky) on the right
        self.path = dataset_image(self.dir, depth)
        self.image = cv2.imread(self.path)[:, :, ::-1]
        self.shares = (train.FOG_SHARE, train.DARK_SHARE)

    def tearDown(self):
        train.FOG_SHARE, train.DARK_SHARE = self.shares
        import shutil
        shutil.rmtree(self.dir, True)

    def test_fog_leaves_near_pixels_and_turns_the_sky_to_fog(self):
        train.FOG_SHARE, train.DARK_SHARE = 1.0, 0.0
        out = train.weather_augment(self.image, self.path, random.Random(1)).astype(float)
        near, far = out[:, :20].mean(), out[:, 20:].mean()
        self.assertLess(abs(near - 60), 30)  # at most 12 % towards the fog at 2 m, V >= 60 m
        self.assertGreater(far, 0.6 * 0.75 * 255 - 1)  # the fog's colour, dimmed at most 40 %
        self.assertLess(np.ptp(out[:, 20:], axis=(0, 1)).max(), 1.5)  # uniform

    def test_darkness_darkens(self):
        train.FOG_SHARE, train.DARK_SHARE = 0.0, 1.0
        out = train.weather_augment(self.image, self.path, random.Random(2)).astype(float)
        self.assertLess(out.mean(), 0.5 * self.image.mean() + 3)

    def test_none_by_default_and_no_draw_then(self):
        rng = random.Random(5)
        self.assertIs(train.weather_augment(self.image, self.path, rng), self.image)
        self.assertEqual(rng.random(), random.Random(5).random())

    def test_the_same_seed_gives_the_same_image_and_most_samples_stay(self):
        train.FOG_SHARE, train.DARK_SHARE = 0.2, 0.15
        a = train.weather_augment(self.image, self.path, random.Random(7))
        b = train.weather_augment(self.image, self.path, random.Random(7))
        self.assertTrue(np.array_equal(a, b))
        rng = random.Random(0)
        kept = sum(train.weather_augment(self.image, self.path, rng) is self.image for _ in range(400))
        self.assertAlmostEqual(kept / 400, 1 - train.FOG_SHARE - train.DARK_SHARE, delta=0.07)

    def test_fog_without_a_depth_image_leaves_the_image(self):
        train.FOG_SHARE, train.DARK_SHARE = 1.0, 0.0
        os.remove(os.path.join(self.dir, "depth", "f.png"))
        self.assertIs(train.weather_augment(self.image, self.path, random.Random(1)), self.image)


class Gain(unittest.TestCase):
    def test_a_bright_image_is_left_as_it_is(self):
        day = np.full((20, 30, 3), 120, np.uint8)
        self.assertIs(gain.brighten(day, 90.0, 8.0), day)

    def test_a_dark_image_is_brought_to_the_target_mean(self):
        dusk = np.full((20, 30, 3), 30, np.uint8)
        dusk[0, 0] = 250
        out = gain.brighten(dusk, 90.0, 8.0)
        self.assertAlmostEqual(out.astype(float).mean(), 90.0, delta=1.5)
        self.assertEqual(out[0, 0, 0], 255)  # saturated

    def test_the_gain_stops_at_its_most(self):
        night = np.full((20, 30, 3), 5, np.uint8)
        self.assertEqual(int(gain.brighten(night, 90.0, 8.0)[3, 3, 1]), 40)
        black = np.zeros((4, 4, 3), np.uint8)
        self.assertEqual(int(gain.brighten(black, 90.0, 8.0).max()), 0)

    def test_model_json_gives_the_gain_or_none(self):
        self.assertEqual(gain.from_meta({"brighten": {"target_mean": 90, "max_gain": 8}}), (90.0, 8.0))
        self.assertIsNone(gain.from_meta({"input_width": 448}))

    def test_bad_brighten_arguments_are_named(self):
        import argparse
        ap = argparse.ArgumentParser()
        self.assertIsNone(train.parse_brighten("none", ap))
        self.assertEqual(train.parse_brighten("80,4", ap), (80.0, 4.0))
        for bad in ("80", "x,4", "300,4", "80,0.5"):
            with self.assertRaises(SystemExit), open(os.devnull, "w") as null:
                stderr, sys.stderr = sys.stderr, null
                try:
                    train.parse_brighten(bad, ap)
                finally:
                    sys.stderr = stderr


if __name__ == "__main__":
    unittest.main()
