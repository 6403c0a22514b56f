"""Perception: the labelled-data export (COCO boxes, instance masks, depth), the training
tool's smoke run and ONNX export, and Convoy's shipped detector in OpenCV 4.6."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import cv2
import numpy as np

from e2e_util import BIN_DIR, REPO

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_perception.coco import rle_decode, rle_encode  # noqa: E402

PY = "/usr/bin/python3"
MAKE_DATASET = os.path.join(REPO, "tools", "dataset", "make_dataset.py")
TRAIN = os.path.join(REPO, "tools", "detector", "train.py")
PARKRING = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_control.json")
MODEL_DIR = os.path.join(REPO, "models", "detector")


def make_dataset(out, *args):
    r = subprocess.run([PY, MAKE_DATASET, PARKRING, "--out", out, "--build", os.path.dirname(BIN_DIR)]
                       + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
    if r.returncode != 0:
        raise AssertionError("make_dataset failed:\n" + r.stdout + r.stderr)
    with open(os.path.join(out, "annotations.json")) as f:
        return json.load(f)


class Dataset(unittest.TestCase):
    def test_coco_masks_match_the_boxes_and_depth_is_next_to_them(self):
        d = tempfile.mkdtemp(prefix="convoy-dataset-")
        self.addCleanup(shutil.rmtree, d, True)
        doc = make_dataset(d, "--runs", "2", "--seconds", "2", "--every", "30", "--seed", "7", "--randomize")
        self.assertEqual(len(doc["images"]), 2 * 3)  # 30 Hz, every 30th frame: t = 0, 1, 2 s; two runs
        self.assertEqual({img["seed"] for img in doc["images"]}, {7, 8})
        cats = {c["id"]: c["name"] for c in doc["categories"]}
        self.assertTrue({"car", "bus", "pedestrian"} <= set(cats.values()))
        classes = {cats[a["category_id"]] for a in doc["annotations"]}
        self.assertTrue({"car", "pedestrian"} <= classes, classes)
        for a in doc["annotations"]:
            mask = rle_decode(a["segmentation"])
            ys, xs = np.nonzero(mask)
            x, y, w, h = a["bbox"]
            # The mask's extent is the box, its pixels the area.
            self.assertEqual((xs.min(), ys.min(), xs.max(), ys.max()), (x, y, x + w - 1, y + h - 1), a)
            self.assertEqual(int(mask.sum()), a["area"])
            self.assertEqual(a["class"], cats[a["category_id"]])
            self.assertTrue(0.0 <= a["visible_fraction"] <= 1.0)
        for img in doc["images"]:
            im = cv2.imread(os.path.join(d, img["file_name"]))
            self.assertEqual(im.shape, (img["height"], img["width"], 3))
            depth = cv2.imread(os.path.join(d, img["depth_file"]), cv2.IMREAD_UNCHANGED)
            self.assertEqual(depth.dtype, np.uint16)
            self.assertEqual(depth.shape, (img["height"], img["width"]))
            # The road just ahead of the car is a few metres away.
            self.assertTrue(2000 < int(np.median(depth[300:330, 340:400])) < 20000)
            # Objects' pixels have their depth: the mask of a car lies at a finite depth.
            for a in doc["annotations"]:
                if a["image_id"] == img["id"] and a["class"] == "car" and a["area"] > 50:
                    m = rle_decode(a["segmentation"])
                    self.assertTrue(0 < np.median(depth[m]) < 65535)
        # The same seeds give the same annotations.
        d2 = tempfile.mkdtemp(prefix="convoy-dataset-")
        self.addCleanup(shutil.rmtree, d2, True)
        doc2 = make_dataset(d2, "--runs", "1", "--seconds", "2", "--every", "30", "--seed", "7", "--randomize")
        first = [a for a in doc["annotations"] if a["image_id"] <= 3]
        self.assertEqual(json.dumps(first, sort_keys=True), json.dumps(doc2["annotations"], sort_keys=True))

    def test_weather_kinds_in_turn_and_vehicle_models_drawn_per_run(self):
        d = tempfile.mkdtemp(prefix="convoy-dataset-")
        self.addCleanup(shutil.rmtree, d, True)
        r = subprocess.run([PY, MAKE_DATASET, CITY, "--out", d, "--build", os.path.dirname(BIN_DIR), "--runs", "2",
                            "--seconds", "1", "--every", "30", "--seed", "40", "--weather", "clear,rain",
                            "--vary-models", "bus=1"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with open(os.path.join(d, "runs.json")) as f:
            runs = json.load(f)
        self.assertEqual([run["weather_kind"] for run in runs], ["clear", "rain"])
        for run in runs:
            self.assertEqual(len(run["models"]), 20)  # city_traffic's vehicle agents
            self.assertTrue(all(m.startswith("bus") for m in run["models"].values()), run["models"])
        self.assertNotEqual(runs[0]["models"], runs[1]["models"])
        with open(os.path.join(d, "annotations.json")) as f:
            doc = json.load(f)
        rain = {img["seed"]: img["weather"]["precipitation"] for img in doc["images"]}
        self.assertEqual(rain[40], 0.0)
        self.assertGreater(rain[41], 0.0)
        cats = {c["id"]: c["name"] for c in doc["categories"]}
        self.assertIn("bus", {cats[a["category_id"]] for a in doc["annotations"]})

    def test_rle_round_trip(self):
        rng = np.random.default_rng(1)
        for shape in ((1, 1), (3, 5), (48, 64)):
            m = rng.random(shape) > 0.6
            self.assertTrue((rle_decode(rle_encode(m)) == m).all())
        m = np.zeros((4, 4), bool)
        m[0, 0] = True
        self.assertEqual(rle_encode(m)["counts"][:2], [0, 1])  # starts with a run of zeros


class DatasetBadInput(unittest.TestCase):
    def run_tool(self, config, *args):
        d = tempfile.mkdtemp(prefix="convoy-dataset-bad-")
        self.addCleanup(shutil.rmtree, d, True)
        p = subprocess.Popen([PY, MAKE_DATASET, config, "--out", d, "--build", os.path.dirname(BIN_DIR),
                              "--runs", "1", "--seconds", "1"] + list(args),
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        out, err = p.communicate(timeout=300)
        r = subprocess.CompletedProcess(p.args, p.returncode, out, err)
        r.pid = p.pid  # make_dataset names its derived configs .dataset_<pid>_<seed>.json
        return r

    def test_an_experiment_without_a_weather_engine_is_named(self):
        cfg = os.path.join(REPO, "experiments", "wheeled_robot", "simulation_config.json")
        r = self.run_tool(cfg)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("has no engine 'weather'", r.stderr)
        self.assertIn("wheeled_robot", r.stderr)

    def test_an_unknown_engine_in_set_is_named(self):
        r = self.run_tool(PARKRING, "--set", "nosuch.Key=1")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--set nosuch.Key=1: no engine 'nosuch'", r.stderr)

    def test_bad_weather_kinds_and_model_shares_are_named(self):
        r = self.run_tool(PARKRING, "--weather", "clear,mud")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--weather clear,mud: unknown kind 'mud'", r.stderr)
        r = self.run_tool(PARKRING, "--weather", "rain", "--randomize")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("either --weather or --randomize", r.stderr)
        r = self.run_tool(PARKRING, "--vary-models", "car=1,plane=2")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--vary-models car=1,plane=2: unknown class 'plane'", r.stderr)
        r = self.run_tool(PARKRING, "--vary-models", "car")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("expected CLASS=SHARE", r.stderr)

    def test_a_failing_run_names_the_run_and_leaves_no_derived_config(self):
        r = self.run_tool(PARKRING, "--set", "gazebo.GazeboWorldFile=missing_world.sdf")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("run 0 failed", r.stderr)
        self.assertIn("missing_world.sdf", r.stderr)
        # (its own: other tests running at the same time may have theirs there)
        left = [f for f in os.listdir(os.path.dirname(PARKRING)) if f.startswith(".dataset_%d_" % r.pid)]
        self.assertEqual(left, [])


class Training(unittest.TestCase):
    def test_a_few_iterations_train_and_export_a_model_opencv_loads(self):
        d = tempfile.mkdtemp(prefix="convoy-train-")
        self.addCleanup(shutil.rmtree, d, True)
        make_dataset(os.path.join(d, "data"), "--runs", "1", "--seconds", "3", "--every", "15")
        r = subprocess.run([PY, TRAIN, "--data", os.path.join(d, "data"), "--out", os.path.join(d, "model"),
                            "--iterations", "3", "--batch", "2", "--input", "128x96"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=600)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with open(os.path.join(d, "model", "model.json")) as f:
            meta = json.load(f)
        with open(os.path.join(d, "model", "classes.txt")) as f:
            classes = f.read().split()
        self.assertEqual(meta["classes"], classes)
        self.assertEqual((meta["input_width"], meta["input_height"]), (128, 96))
        net = cv2.dnn.readNetFromONNX(os.path.join(d, "model", "convoy_detector.onnx"))
        net.setInput(np.zeros((1, 3, 96, 128), np.float32))
        out = net.forward()
        cells = sum((128 // s) * (96 // s) for s in (8, 16, 32))
        self.assertEqual(out.shape, (1, 4 + len(classes), cells))


CITY = os.path.join(REPO, "experiments", "city_traffic", "simulation_config.json")
# The shipped model's mAP@0.5 on the fixed render set below, less a margin (docs/perception.md
# has the measured figure; the target, 0.8 on held-out renders, is checked by
# benchmarks/perception_bench.py).
MIN_MAP50 = 0.80  # the issue's target; measured 0.945 (car 0.84, bus 1.00, pedestrian 1.00; 31 frames; session 11's model)


class Shipped(unittest.TestCase):
    def test_the_shipped_model_loads_in_opencv_and_scores_on_fixed_renders(self):
        with open(os.path.join(MODEL_DIR, "model.json")) as f:
            meta = json.load(f)
        with open(os.path.join(MODEL_DIR, "classes.txt")) as f:
            classes = f.read().split()
        self.assertEqual(meta["classes"], classes)
        self.assertTrue({"car", "bus", "pedestrian"} <= set(classes))
        size = sum(os.path.getsize(os.path.join(MODEL_DIR, n)) for n in os.listdir(MODEL_DIR))
        self.assertLess(size, 15e6)
        net = cv2.dnn.readNetFromONNX(os.path.join(MODEL_DIR, "convoy_detector.onnx"))
        w, h = meta["input_width"], meta["input_height"]
        net.setInput(np.zeros((1, 3, h, w), np.float32))
        self.assertEqual(net.forward().shape, (1, 4 + len(classes), sum((w // k) * (h // k) for k in (8, 16, 32))))
        # A small fixed render set on the held-out camera path (the city westbound, a seed
        # training never used), scored by convoy_perception.evaluation.
        d = tempfile.mkdtemp(prefix="convoy-shipped-")
        self.addCleanup(shutil.rmtree, d, True)
        r = subprocess.run([PY, MAKE_DATASET, CITY, "--out", d, "--build", os.path.dirname(BIN_DIR),
                            "--runs", "1", "--seconds", "30", "--every", "30", "--seed", "970",
                            "--set", "gazebo.GazeboWorldFile=city_world_west.sdf",
                            "--env", "car_ctl_engine:CONVOY_EGO_ROUTE=ego_route_west.csv",
                            "--env", "car_ctl_engine:CONVOY_EGO_ROUTE_SKIP=25",
                            # the live detector and the video recorder step once (t = 0), not
                            # every 0.1 s / 0.02 s: they do not steer the ego (ground-truth input),
                            # so the images and annotations are the same bytes (compared when this
                            # was changed), for about a third less CPU
                            "--set", "yolo_detector.EngineTimestep=30",
                            "--set", "recorder.EngineTimestep=30"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=900)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        sys.path.insert(0, os.path.join(REPO, "benchmarks"))
        import perception_bench
        result, n = perception_bench.heldout_map(MODEL_DIR, d)
        self.assertEqual(n, 31)
        self.assertGreaterEqual(result["map50"], MIN_MAP50, result["classes"])


if __name__ == "__main__":
    unittest.main()
