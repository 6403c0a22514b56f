"""Unit tests of convoy_perception.evaluation (docs/perception.md): the scoring rules and AP
against hand-computed values.

Run: PYTHONPATH=python /usr/bin/python3 -m unittest -v tests/unit/test_evaluation.py
(ctest: py_evaluation)."""

import json
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "python")
if PYTHON_DIR not in sys.path:
    sys.path.insert(0, PYTHON_DIR)

from convoy_perception import evaluation as ev  # noqa: E402


def gt(cls, x0, y0, x1, y1, **extra):
    """Ground truth, inclusive pixel coordinates."""
    return dict({"class": cls, "x_min": x0, "y_min": y0, "x_max": x1, "y_max": y1}, **extra)


def det(cls, score, x0, y0, x1, y1):
    """A detection, continuous edges."""
    return {"class": cls, "score": score, "x_min": x0, "y_min": y0, "x_max": x1, "y_max": y1}


def square(cls, k=0, size=100, **extra):
    """A size x size object at x = 200 k (pixels x .. x + size - 1)."""
    return gt(cls, 200 * k, 0, 200 * k + size - 1, size - 1, **extra)


def hit(cls, score, k=0, size=100):
    """A detection exactly on square(cls, k, size)."""
    return det(cls, score, 200 * k, 0, 200 * k + size, size)


def frame(gts, dets):
    return {"gt": gts, "detections": dets}


class AveragePrecision(unittest.TestCase):
    def test_perfect_detector(self):
        frames = [frame([square("car", 0), square("car", 1)],
                        [hit("car", 0.9, 0), hit("car", 0.8, 1)]) for _ in range(3)]
        r = ev.evaluate(frames)
        c = r["classes"]["car"]
        self.assertEqual(c["ap50"], 1.0)
        self.assertEqual(c["ap50_95"], 1.0)
        self.assertEqual((c["precision"], c["recall"]), (1.0, 1.0))
        self.assertEqual((c["tp"], c["fp"], c["fn"], c["scored_gt"]), (6, 0, 0, 6))
        self.assertEqual((r["map50"], r["map50_95"]), (1.0, 1.0))

    def test_one_fp_ranked_above_the_tp(self):
        # the FP (0.9) comes first: precision 1/2 at recall 1, made 1/2 everywhere
        r = ev.evaluate([frame([square("car", 0)], [det("car", 0.9, 500, 0, 600, 100),
                                                    hit("car", 0.8, 0)])])
        c = r["classes"]["car"]
        self.assertAlmostEqual(c["ap50"], 0.5)
        self.assertEqual((c["tp"], c["fp"], c["fn"]), (1, 1, 0))
        self.assertEqual((c["precision"], c["recall"]), (0.5, 1.0))

    def test_fp_below_the_tp_costs_nothing(self):
        r = ev.evaluate([frame([square("car", 0)], [det("car", 0.3, 500, 0, 600, 100),
                                                    hit("car", 0.8, 0)])])
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)

    def test_ranking_is_over_all_frames(self):
        # the FP of frame 0 (0.9) outranks the TP of frame 1 (0.8)
        r = ev.evaluate([frame([], [det("car", 0.9, 0, 0, 100, 100)]),
                         frame([square("car")], [hit("car", 0.8)])])
        self.assertAlmostEqual(r["classes"]["car"]["ap50"], 0.5)

    def test_missed_object(self):
        # recall reaches 1/2 at precision 1: recall thresholds 0, 0.01, ..., 0.50 (51 of 101)
        r = ev.evaluate([frame([square("car", 0), square("car", 1)], [hit("car", 0.9, 0)])])
        c = r["classes"]["car"]
        self.assertAlmostEqual(c["ap50"], 51 / 101)
        self.assertEqual((c["fn"], c["recall"]), (1, 0.5))

    def test_101_points_differ_from_11_points_and_the_raw_area(self):
        # 3 objects; TP 0.9, FP 0.8, TP 0.7, FP 0.6; one object never found.
        # recall 1/3 1/3 2/3 2/3, precision 1 1/2 2/3 1/2 -> interpolated 1 2/3 2/3 1/2.
        # 101 points: r = 0..0.33 (34) at 1, r = 0.34..0.66 (33) at 2/3 -> 56/101 = 0.5545
        # 11 points: 0..0.3 (4) at 1, 0.4..0.6 (3) at 2/3 -> 6/11 = 0.5455
        # area under the interpolated curve: 1/3 + 2/9 = 5/9 = 0.5556
        gts = [square("car", k) for k in range(3)]
        dets = [hit("car", 0.9, 0), det("car", 0.8, 900, 0, 1000, 100), hit("car", 0.7, 1),
                det("car", 0.6, 1100, 0, 1200, 100)]
        ap = ev.evaluate([frame(gts, dets)])["classes"]["car"]["ap50"]
        self.assertAlmostEqual(ap, 56 / 101, places=12)
        self.assertGreater(abs(ap - 6 / 11), 1e-3)
        self.assertGreater(abs(ap - 5 / 9), 1e-4)

    def test_average_precision_101_directly(self):
        self.assertAlmostEqual(ev.average_precision_101([0.9, 0.8, 0.7, 0.6],
                                                        [True, False, True, False], 3), 56 / 101)
        self.assertEqual(ev.average_precision_101([], [], 2), 0.0)
        self.assertIsNone(ev.average_precision_101([0.5], [False], 0))
        # input order does not matter, the scores do
        self.assertAlmostEqual(ev.average_precision_101([0.6, 0.7, 0.8, 0.9],
                                                        [False, True, False, True], 3), 56 / 101)

    def test_no_detections(self):
        r = ev.evaluate([frame([square("car")], [])])
        c = r["classes"]["car"]
        self.assertEqual((c["ap50"], c["ap50_95"], c["recall"]), (0.0, 0.0, 0.0))
        self.assertIsNone(c["precision"])

    def test_ap_keeps_detections_from_0_001(self):
        r = ev.evaluate([frame([square("car")], [hit("car", 0.0009)])])
        self.assertEqual(r["classes"]["car"]["ap50"], 0.0)
        r = ev.evaluate([frame([square("car")], [hit("car", 0.001)])])
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)
        # but precision and recall are at the detector's threshold
        self.assertEqual(r["classes"]["car"]["recall"], 0.0)
        self.assertIsNone(r["classes"]["car"]["precision"])


class Ignored(unittest.TestCase):
    def test_too_small_object_is_ignored(self):
        small = gt("car", 300, 0, 339, 38)  # 39 px tall
        self.assertFalse(ev.is_scored(small))
        self.assertTrue(ev.is_scored(gt("car", 300, 0, 339, 39)))  # 40 px
        # found: not a TP; missed: not a FN
        for dets in ([hit("car", 0.9)], [hit("car", 0.9), det("car", 0.95, 300, 0, 340, 39)]):
            r = ev.evaluate([frame([square("car"), small], dets)])
            c = r["classes"]["car"]
            self.assertEqual((c["tp"], c["fp"], c["fn"]), (1, 0, 0), dets)
            self.assertEqual((c["scored_gt"], c["ignored_gt"]), (1, 1))
            self.assertEqual((c["precision"], c["recall"], c["ap50"]), (1.0, 1.0, 1.0))
        self.assertEqual(c["ignored_detections"], 1)

    def test_occluded_object_is_ignored(self):
        cases = [({"visible_fraction": 0.39}, False), ({"visible_fraction": 0.4}, True),
                 ({"pixels": 390, "full_pixels": 1000}, False),
                 ({"pixels": 400, "full_pixels": 1000}, True),
                 ({"pixels": 5, "full_pixels": 0}, False),
                 ({"pixels": 10}, True),  # no silhouette: counted as visible
                 ({}, True)]
        for extra, scored in cases:
            g = square("pedestrian", 1, **extra)
            self.assertEqual(ev.is_scored(g), scored, extra)
            r = ev.evaluate([frame([square("pedestrian", 0), g],
                                   [hit("pedestrian", 0.9, 0), hit("pedestrian", 0.8, 1)])])
            c = r["classes"]["pedestrian"]
            self.assertEqual((c["tp"], c["fp"], c["fn"]), (2 if scored else 1, 0, 0), extra)
            self.assertEqual(c["ignored_gt"], 0 if scored else 1)
            # missed: a FN only when scored
            r = ev.evaluate([frame([square("pedestrian", 0), g], [hit("pedestrian", 0.9, 0)])])
            self.assertEqual(r["classes"]["pedestrian"]["fn"], 1 if scored else 0, extra)

    def test_detection_of_an_ignored_object_does_not_lower_ap(self):
        hidden = square("car", 1, visible_fraction=0.1)
        r = ev.evaluate([frame([square("car", 0), hidden],
                               [hit("car", 0.95, 1), hit("car", 0.5, 0)])])
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)
        self.assertEqual(r["classes"]["car"]["ap50_95"], 1.0)

    def test_scored_object_is_preferred_to_an_ignored_one(self):
        # the detection overlaps an ignored object exactly and a scored one at IoU 0.6: it is
        # the scored one's TP, as in COCO
        hidden = gt("car", 0, 0, 99, 99, visible_fraction=0.2)
        scored = gt("car", 0, 0, 99, 59, visible_fraction=1.0)  # 60 px tall
        r = ev.evaluate([frame([hidden, scored], [det("car", 0.9, 0, 0, 100, 100)])])
        c = r["classes"]["car"]
        self.assertEqual((c["tp"], c["fp"], c["fn"]), (1, 0, 0))

    def test_duplicate_on_an_ignored_object_is_a_fp(self):
        # each object is matched once, ignored ones too (COCO)
        hidden = square("car", visible_fraction=0.2)
        r = ev.evaluate([frame([hidden], [hit("car", 0.9), hit("car", 0.8)])])
        c = r["classes"]["car"]
        self.assertEqual((c["tp"], c["fp"], c["ignored_detections"]), (0, 1, 1))
        self.assertIsNone(c["ap50"])  # no scored object

    def test_class_with_only_ignored_objects_is_out_of_the_mean(self):
        r = ev.evaluate([frame([square("car", 0), square("bus", 1, visible_fraction=0.0)],
                               [hit("car", 0.9, 0)])])
        self.assertIsNone(r["classes"]["bus"]["ap50"])
        self.assertEqual(r["mean_over"], ["car"])
        self.assertEqual(r["map50"], 1.0)


class Matching(unittest.TestCase):
    def test_class_mismatch_is_no_match(self):
        frames = [frame([square("pedestrian")], [hit("car", 0.9)])]
        r = ev.evaluate(frames, classes=["car", "pedestrian"])
        self.assertEqual(r["classes"]["pedestrian"]["ap50"], 0.0)
        self.assertEqual(r["classes"]["pedestrian"]["fn"], 1)
        self.assertEqual(r["classes"]["car"]["fp"], 1)
        self.assertIsNone(r["classes"]["car"]["ap50"])
        self.assertEqual((r["tp"], r["fp"], r["fn"]), (0, 1, 1))
        self.assertEqual(r["map50"], 0.0)
        # classes default to the ground truth's: the car detection is left out
        r = ev.evaluate(frames)
        self.assertEqual(list(r["classes"]), ["pedestrian"])
        self.assertEqual((r["fp"], r["other_class_detections"]), (0, 1))

    def test_iou_exactly_0_5_matches_0_49_does_not(self):
        g = square("car")  # [0, 100) x [0, 100)
        half = det("car", 0.9, 0, 0, 50, 100)
        self.assertEqual(ev.iou(ev.gt_box(g), ev.det_box(half)), 0.5)
        r = ev.evaluate([frame([g], [half])])
        self.assertEqual(r["tp"], 1)
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)
        less = det("car", 0.9, 0, 0, 49, 100)
        self.assertAlmostEqual(ev.iou(ev.gt_box(g), ev.det_box(less)), 0.49)
        r = ev.evaluate([frame([g], [less])])
        self.assertEqual((r["tp"], r["fp"], r["fn"]), (0, 1, 1))
        self.assertEqual(r["classes"]["car"]["ap50"], 0.0)
        # a threshold of one's own
        r = ev.evaluate([frame([g], [less])], iou_threshold=0.45)
        self.assertEqual(r["tp"], 1)

    def test_each_object_matched_once(self):
        r = ev.evaluate([frame([square("car")], [hit("car", 0.9), hit("car", 0.8)])])
        self.assertEqual((r["tp"], r["fp"]), (1, 1))
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)  # the FP ranks below

    def test_greedy_by_score(self):
        # the higher-scored, worse-placed detection takes the object
        g = square("car")
        good, poor = det("car", 0.5, 0, 0, 100, 100), det("car", 0.9, 0, 0, 60, 100)
        out, gts = ev.match_frame([g], [good, poor])
        self.assertEqual([o["outcome"] for o in out], ["fp", "tp"])
        self.assertEqual(out[1]["gt"], 0)
        self.assertEqual(gts, [{"scored": True, "matched": True}])

    def test_match_frame_outcomes(self):
        gts = [square("car", 0), square("car", 1, visible_fraction=0.1)]
        dets = [hit("car", 0.9, 0), hit("car", 0.8, 1), det("car", 0.7, 900, 0, 950, 50),
                hit("car", 0.1, 0), det("dog", 0.9, 0, 0, 10, 10)]
        out, _ = ev.match_frame(gts, dets, min_score=0.25)
        self.assertEqual([o["outcome"] for o in out],
                         ["tp", "ignored", "fp", "below_threshold", "other_class"])

    def test_box_conventions(self):
        g = gt("car", 10, 20, 19, 39)  # 10 x 20 pixels
        self.assertEqual(ev.gt_box(g), (10.0, 20.0, 20.0, 40.0))
        # the same numbers as a detection: continuous edges, 9 x 19
        d = dict(g, score=1.0)
        self.assertAlmostEqual(ev.iou(ev.gt_box(g), ev.det_box(d)), 9 * 19 / 200)
        self.assertEqual(ev.iou(ev.gt_box(g), ev.det_box(d, inclusive=True)), 1.0)
        # ground truth passed through as detections (detections_inclusive) scores 1 at 0.95
        # (read as continuous edges, a 10 x 40 object's IoU is 9 * 39 / 400 = 0.88)
        narrow = gt("pedestrian", 0, 0, 9, 39)
        frames = [frame([narrow], [dict(narrow, confidence=1.0)])]
        self.assertEqual(ev.evaluate(frames, detections_inclusive=True)["map50_95"], 1.0)
        self.assertAlmostEqual(ev.evaluate(frames)["map50_95"], 0.8)
        self.assertEqual(ev.iou((0, 0, 10, 10), (20, 20, 30, 30)), 0.0)

    def test_confidence_is_read_as_the_score(self):
        d = hit("car", 0.0)
        del d["score"]
        d["confidence"] = 0.7
        self.assertEqual(ev.detection_score(d), 0.7)
        del d["confidence"]
        with self.assertRaises(ValueError):
            ev.evaluate([frame([square("car")], [d])])

    def test_bad_input(self):
        for frames in ({"gt": []}, [1], [{"gt": [{"class": "car", "x_min": 0}]}],
                       [{"gt": [{"x_min": 0}]}]):
            with self.assertRaises(ValueError, msg=repr(frames)):
                ev.evaluate(frames)


class IouRange(unittest.TestCase):
    def test_offset_box(self):
        # shifted by 10 px: IoU 90/110 = 0.818, a match at 0.50 ... 0.80 (7 of 10 thresholds)
        g = square("car")
        d = det("car", 0.9, 10, 0, 110, 100)
        self.assertAlmostEqual(ev.iou(ev.gt_box(g), ev.det_box(d)), 90 / 110)
        c = ev.evaluate([frame([g], [d])])["classes"]["car"]
        self.assertAlmostEqual(c["ap50_95"], 0.7)
        self.assertEqual(c["ap50"], 1.0)
        self.assertEqual([c["ap_per_iou"]["%.2f" % t] for t in ev.IOU_THRESHOLDS],
                         [1.0] * 7 + [0.0] * 3)

    def test_iou_on_a_threshold(self):
        # IoU exactly 0.75: matches at 0.50 ... 0.75 (6 of 10)
        r = ev.evaluate([frame([square("car")], [det("car", 0.9, 0, 0, 75, 100)])])
        self.assertAlmostEqual(r["map50_95"], 0.6)

    def test_means_over_classes(self):
        frames = [frame([square("car", 0), square("pedestrian", 1), square("pedestrian", 2)],
                        [hit("car", 0.9, 0), det("car", 0.9, 10, 0, 110, 100),
                         hit("pedestrian", 0.9, 1)])]
        r = ev.evaluate(frames)
        # car: TP then FP (duplicate) -> 1; pedestrian: 1 of 2 found -> 51/101
        self.assertEqual(r["classes"]["car"]["ap50"], 1.0)
        self.assertAlmostEqual(r["classes"]["pedestrian"]["ap50"], 51 / 101)
        self.assertAlmostEqual(r["map50"], (1 + 51 / 101) / 2)
        self.assertAlmostEqual(r["map50_95"], (1 + 51 / 101) / 2)
        self.assertEqual(r["mean_over"], ["car", "pedestrian"])


class CocoNames(unittest.TestCase):
    def test_map_coco_class(self):
        road = {"car", "bus", "pedestrian"}
        self.assertEqual(ev.map_coco_class("person", road), "pedestrian")
        self.assertEqual(ev.map_coco_class("car", road), "car")
        self.assertEqual(ev.map_coco_class("bus", road), "bus")
        self.assertEqual(ev.map_coco_class("truck", road), "car")
        self.assertEqual(ev.map_coco_class("truck", road | {"truck"}), "truck")
        self.assertEqual(ev.map_coco_class("dog", road), "dog")
        self.assertEqual(ev.map_coco_class("pedestrian", road), "pedestrian")

    def test_evaluate_with_coco_names(self):
        frames = [frame([square("pedestrian", 0), square("car", 1)],
                        [hit("person", 0.9, 0), hit("truck", 0.8, 1)])]
        self.assertEqual(ev.evaluate(frames)["tp"], 0)
        r = ev.evaluate(frames, coco=True)
        self.assertEqual((r["tp"], r["fp"], r["map50"]), (2, 0, 1.0))
        # with a truck class the truck is a truck, not a car
        r = ev.evaluate(frames, classes=["car", "pedestrian", "truck"], coco=True)
        self.assertEqual((r["tp"], r["fp"], r["fn"]), (1, 1, 1))
        self.assertEqual(r["classes"]["truck"]["fp"], 1)
        mapped = ev.map_coco_detections(frames)
        self.assertEqual([d["class"] for d in mapped[0]["detections"]], ["pedestrian", "car"])
        self.assertEqual(frames[0]["detections"][0]["class"], "person")  # input unchanged


class PrecisionRecall(unittest.TestCase):
    def test_at_the_detectors_threshold(self):
        frames = [frame([square("car", 0), square("car", 1), square("car", 2, size=30),
                         square("bus", 3)],
                        [hit("car", 0.9, 0), hit("car", 0.3, 1), det("car", 0.8, 900, 0, 999, 99),
                         hit("car", 0.7, 2, size=30), hit("bus", 0.6, 3)])]
        r = ev.precision_recall(frames, score_threshold=0.5)
        car = r["per_class"]["car"]
        # 0.9 TP, 0.8 FP, 0.7 on the 30 px object ignored, 0.3 below the threshold
        self.assertEqual((car["tp"], car["fp"], car["fn"], car["ignored_detections"]),
                         (1, 1, 1, 1))
        self.assertEqual((car["precision"], car["recall"]), (0.5, 0.5))
        self.assertEqual((car["scored_gt"], car["ignored_gt"]), (2, 1))
        self.assertEqual((r["per_class"]["bus"]["precision"], r["per_class"]["bus"]["recall"]),
                         (1.0, 1.0))
        o = r["overall"]
        self.assertEqual((o["tp"], o["fp"], o["fn"]), (2, 1, 1))
        self.assertAlmostEqual(o["precision"], 2 / 3)
        self.assertAlmostEqual(o["recall"], 2 / 3)
        r = ev.precision_recall(frames, score_threshold=0.25)
        self.assertEqual(r["per_class"]["car"]["recall"], 1.0)
        # evaluate() reports the same
        e = ev.evaluate(frames, score_threshold=0.5)
        self.assertEqual((e["precision"], e["recall"]), (o["precision"], o["recall"]))


class Cli(unittest.TestCase):
    def run_cli(self, data, *args):
        with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
            json.dump(data, f)
        self.addCleanup(os.unlink, f.name)
        env = dict(os.environ, PYTHONPATH=PYTHON_DIR)
        return subprocess.run([sys.executable, "-m", "convoy_perception.evaluation", f.name]
                              + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, env=env, timeout=60)

    def test_table(self):
        frames = [frame([square("pedestrian", 0), square("car", 1)],
                        [hit("person", 0.9, 0), hit("car", 0.8, 1)])]
        r = self.run_cli(frames, "--coco")
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = r.stdout.splitlines()
        self.assertTrue(lines[0].startswith("class"))
        row = next(l for l in lines if l.startswith("pedestrian")).split()
        self.assertEqual(row[1:], ["1", "0", "1", "0", "0", "1.000", "1.000", "1.000", "1.000"])
        self.assertTrue(any(l.startswith("all") for l in lines))
        r = self.run_cli({"frames": frames}, "--json")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertEqual(json.loads(r.stdout)["classes"]["pedestrian"]["ap50"], 0.0)

    def test_bad_file(self):
        r = self.run_cli({"nothing": 1})
        self.assertEqual(r.returncode, 2)
        self.assertIn("error", r.stderr)


if __name__ == "__main__":
    unittest.main()
