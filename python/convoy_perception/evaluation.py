"""Detection evaluation: the project's one definition of how detections are scored against the
world engine's ground truth (docs/perception.md, "Scoring detections").

Inputs are plain dicts. A run is a list of frames, each {"gt": [...], "detections": [...]}:
- ground truth: {"class", "x_min", "y_min", "x_max", "y_max"} in inclusive pixel coordinates
  (the world engine's `::boxes`: a box of one pixel has x_min == x_max), optionally
  "visible_fraction" (0..1), or "pixels" (visible pixel count) with "full_pixels" (pixels of
  the whole silhouette, as if nothing hid it);
- detections: {"class", "score", "x_min", "y_min", "x_max", "y_max"} in continuous image
  coordinates (box edges, as the detector engine's YOLO and HOG backends give them: a box
  covering pixel columns 10..19 has x_min 10, x_max 20). "confidence" (the detector engine's
  key) is read when "score" is missing. Detections given in the ground truth's inclusive pixel
  convention (the detector's ground-truth passthrough) are read as such with
  detections_inclusive=True.

Rules:
- A ground-truth object is *scored* when its box is at least MIN_HEIGHT_PX (40) pixels tall
  (y_max - y_min + 1) and at least MIN_VISIBLE_FRACTION (40 %) of it is visible; otherwise it
  is *ignored*. Visible fraction: "visible_fraction" if given, else pixels / full_pixels if
  "full_pixels" is given (0 when full_pixels <= 0), else the object counts as fully visible
  (the world engine's boxes carry only the visible pixel count, not the silhouette's).
- Matching, per frame and class, as COCO does: detections in descending score order (stable:
  equal scores keep their input order); each takes the unmatched scored object of its class
  with the highest IoU >= the threshold (TP); failing that, the unmatched ignored object with
  the highest IoU >= the threshold, and then the detection is dropped (neither TP nor FP);
  failing that it is a FP. Each object is matched at most once, so a second detection of an
  ignored object is a FP (a duplicate), as in COCO. A scored object left unmatched is a FN.
  Classes must be equal (map a COCO detector's names first: map_coco_class). IoU >= threshold
  is tested with a 1e-9 tolerance so that an IoU of exactly 0.5 matches at 0.5.
- AP: COCO's 101-point interpolated AP: detections with score >= AP_SCORE_THRESHOLD (0.001),
  sorted by score over all frames; precision made non-increasing from the right; AP = mean
  of the interpolated precision at recall 0, 0.01, ..., 1 (0 where the recall is not
  reached). Per class, at IoU 0.5 (AP50) and averaged over IoU 0.50:0.05:0.95 (AP50:95).
  Unlike pycocotools there is no cap of 100 detections per image and no area ranges.
- mAP50, mAP50:95: means over the classes that have at least one scored object.
- Precision and recall at the detector's own threshold (detections with score >= it), at IoU
  0.5, over scored objects only: TP / (TP + FP) and TP / (TP + FN), per class and summed over
  classes (None when the denominator is 0).
- Classes evaluated: those given, else every ground-truth class present. Detections of other
  classes are left out (counted as "other_class_detections").

CLI: /usr/bin/python3 -m convoy_perception.evaluation FILE.json [--coco] [--score-threshold T]
prints a table (FILE holds the list of frames, or {"frames": [...]}).
"""

import argparse
import json
import sys

import numpy as np

MIN_HEIGHT_PX = 40
MIN_VISIBLE_FRACTION = 0.4
IOU_MATCH = 0.5
IOU_THRESHOLDS = tuple(round(0.5 + 0.05 * i, 2) for i in range(10))  # 0.50, 0.55, ..., 0.95
RECALL_THRESHOLDS = np.linspace(0.0, 1.0, 101)  # as pycocotools builds them
AP_SCORE_THRESHOLD = 0.001
DEFAULT_SCORE_THRESHOLD = 0.25
IOU_TOLERANCE = 1e-9

# The stock COCO detector's classes onto the ground truth's (see map_coco_class).
COCO_TO_GT = {"person": "pedestrian", "car": "car", "bus": "bus"}


# --- boxes and objects ---------------------------------------------------------------------

def visible_fraction(gt):
    """The visible fraction of a ground-truth object: "visible_fraction", else pixels /
    full_pixels, else 1.0 (no information: counted as visible)."""
    v = gt.get("visible_fraction")
    if v is not None:
        return float(v)
    full = gt.get("full_pixels")
    if full is not None:
        if gt.get("pixels") is None:
            raise ValueError("ground truth with 'full_pixels' needs 'pixels'")
        return float(gt["pixels"]) / float(full) if full > 0 else 0.0
    return 1.0


def box_height(gt):
    """Height in pixels of a ground-truth box (inclusive coordinates)."""
    return gt["y_max"] - gt["y_min"] + 1


def is_scored(gt, min_height=MIN_HEIGHT_PX, min_visible=MIN_VISIBLE_FRACTION):
    """True when the object counts (at least min_height px tall and min_visible visible);
    False when it is ignored."""
    return box_height(gt) >= min_height and visible_fraction(gt) >= min_visible


def gt_box(gt):
    """A ground-truth box (inclusive pixels) as continuous edges (x0, y0, x1, y1)."""
    return (float(gt["x_min"]), float(gt["y_min"]), float(gt["x_max"]) + 1.0,
            float(gt["y_max"]) + 1.0)


def det_box(det, inclusive=False):
    """A detection's box as continuous edges (x0, y0, x1, y1)."""
    extra = 1.0 if inclusive else 0.0
    return (float(det["x_min"]), float(det["y_min"]), float(det["x_max"]) + extra,
            float(det["y_max"]) + extra)


def iou(a, b):
    """IoU of two boxes given as continuous edges (x0, y0, x1, y1)."""
    return float(_iou_matrix(np.array([a], float), np.array([b], float))[0, 0])


def _iou_matrix(dets, gts):
    """IoU of each detection box (rows) with each ground-truth box (columns); (n, 4) arrays of
    continuous edges."""
    if len(dets) == 0 or len(gts) == 0:
        return np.zeros((len(dets), len(gts)))
    d = dets[:, None, :]
    g = gts[None, :, :]
    iw = np.clip(np.minimum(d[..., 2], g[..., 2]) - np.maximum(d[..., 0], g[..., 0]), 0, None)
    ih = np.clip(np.minimum(d[..., 3], g[..., 3]) - np.maximum(d[..., 1], g[..., 1]), 0, None)
    inter = iw * ih
    area_d = np.clip(d[..., 2] - d[..., 0], 0, None) * np.clip(d[..., 3] - d[..., 1], 0, None)
    area_g = np.clip(g[..., 2] - g[..., 0], 0, None) * np.clip(g[..., 3] - g[..., 1], 0, None)
    union = area_d + area_g - inter
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(union > 0, inter / np.where(union > 0, union, 1), 0.0)


def detection_score(det):
    """A detection's score: "score", else "confidence" (the detector engine's key)."""
    s = det.get("score", det.get("confidence"))
    if s is None:
        raise ValueError("detection without 'score' (or 'confidence')")
    return float(s)


# --- class mapping -------------------------------------------------------------------------

def map_coco_class(name, gt_classes):
    """A stock COCO detector's class name as a ground-truth class: person -> pedestrian,
    car -> car, bus -> bus, truck -> truck when the ground truth has a `truck` class (in
    gt_classes), else truck -> car. Any other name is returned unchanged (so names that are
    already ground-truth classes pass through, and e.g. `dog` stays outside the classes
    evaluated)."""
    if name == "truck":
        return "truck" if "truck" in gt_classes else "car"
    return COCO_TO_GT.get(name, name)


def gt_classes(frames):
    """The set of ground-truth classes in the frames."""
    return {g["class"] for f in frames for g in f.get("gt", [])}


def map_coco_detections(frames, classes=None):
    """A copy of frames with each detection's class mapped by map_coco_class against
    `classes` (default: the ground-truth classes present in the frames)."""
    known = set(classes) if classes is not None else gt_classes(frames)
    out = []
    for f in frames:
        g = dict(f)
        g["detections"] = [dict(d, **{"class": map_coco_class(d["class"], known)})
                           for d in f.get("detections", [])]
        out.append(g)
    return out


# --- matching ------------------------------------------------------------------------------

TP, FP, IGNORED = 1, 0, -1


def _greedy(ious, scored, threshold):
    """COCO's greedy matching of detections (rows, already in descending score order) to
    objects (columns). Returns per detection TP, FP or IGNORED and the object index (-1)."""
    n_det, n_gt = ious.shape
    used = np.zeros(n_gt, bool)
    outcome = np.full(n_det, FP, np.int8)
    matched = np.full(n_det, -1, np.int64)
    limit = threshold - IOU_TOLERANCE
    for d in range(n_det):
        for want_scored in (True, False):
            free = ~used & (scored == want_scored)
            if not free.any():
                continue
            vals = np.where(free, ious[d], -1.0)
            j = int(np.argmax(vals))
            if vals[j] >= limit:
                used[j] = True
                matched[d] = j
                outcome[d] = TP if want_scored else IGNORED
                break
    return outcome, matched


class _Frame:
    """One frame's objects and detections of one class, detections in descending score
    order."""

    __slots__ = ("gt_boxes", "scored", "det_boxes", "scores", "det_index", "gt_index", "_ious")

    def __init__(self):
        self.gt_boxes, self.scored, self.gt_index = [], [], []
        self.det_boxes, self.scores, self.det_index = [], [], []
        self._ious = None

    def finish(self):
        self.gt_boxes = np.array(self.gt_boxes, float).reshape(-1, 4)
        self.scored = np.array(self.scored, bool)
        order = np.argsort(-np.array(self.scores, float), kind="mergesort")
        self.det_boxes = np.array(self.det_boxes, float).reshape(-1, 4)[order]
        self.scores = np.array(self.scores, float)[order]
        self.det_index = np.array(self.det_index, np.int64)[order]
        return self

    def ious(self):
        if self._ious is None:
            self._ious = _iou_matrix(self.det_boxes, self.gt_boxes)
        return self._ious

    def match(self, threshold, min_score):
        keep = self.scores >= min_score
        return _greedy(self.ious()[keep], self.scored, threshold) + (self.scores[keep],
                                                                      self.det_index[keep])


def _prepare(frames, classes, min_height, min_visible, detections_inclusive):
    """Per class, the list of _Frame (one per input frame); and the number of detections of
    classes outside `classes`."""
    if not isinstance(frames, list):
        raise ValueError("frames must be a list of {'gt': [...], 'detections': [...]}")
    if classes is None:
        try:
            classes = sorted(gt_classes(frames))
        except (KeyError, TypeError, AttributeError) as e:
            raise ValueError("frames: ground truth without a class (%s)" % e) from None
    per_class = {c: [] for c in classes}
    other = 0
    for fi, f in enumerate(frames):
        if not isinstance(f, dict):
            raise ValueError("frame %d is not an object" % fi)
        current = {c: _Frame() for c in classes}
        try:
            for gi, g in enumerate(f.get("gt", [])):
                fr = current.get(g["class"])
                if fr is not None:
                    fr.gt_boxes.append(gt_box(g))
                    fr.scored.append(is_scored(g, min_height, min_visible))
                    fr.gt_index.append(gi)
            for di, d in enumerate(f.get("detections", [])):
                fr = current.get(d["class"])
                if fr is None:
                    other += 1
                    continue
                fr.det_boxes.append(det_box(d, detections_inclusive))
                fr.scores.append(detection_score(d))
                fr.det_index.append(di)
        except (KeyError, TypeError, ValueError) as e:
            raise ValueError("frame %d: bad box (%s: %s)" % (fi, type(e).__name__, e)) from None
        for c in classes:
            per_class[c].append(current[c].finish())
    return per_class, other


def match_frame(gt, detections, iou_threshold=IOU_MATCH, min_score=0.0,
                min_height=MIN_HEIGHT_PX, min_visible=MIN_VISIBLE_FRACTION,
                detections_inclusive=False):
    """Matches one frame. Returns one entry per detection (in the input's order):
    {"outcome": "tp" | "fp" | "ignored" | "below_threshold" | "other_class", "gt": index of
    the object matched or None}; and per object {"scored": bool, "matched": bool}."""
    frame = {"gt": gt, "detections": detections}
    classes = sorted({g["class"] for g in gt})
    per_class, _ = _prepare([frame], classes, min_height, min_visible, detections_inclusive)
    names = {TP: "tp", FP: "fp", IGNORED: "ignored"}
    det_out = [{"outcome": "other_class", "gt": None} for _ in detections]
    gt_out = [{"scored": is_scored(g, min_height, min_visible), "matched": False} for g in gt]
    for c in classes:
        fr = per_class[c][0]
        for di in fr.det_index:
            det_out[di] = {"outcome": "below_threshold", "gt": None}
        outcome, matched, _, det_index = fr.match(iou_threshold, min_score)
        for o, m, di in zip(outcome, matched, det_index):
            gi = fr.gt_index[m] if m >= 0 else None
            det_out[di] = {"outcome": names[int(o)], "gt": gi}
            if gi is not None:
                gt_out[gi]["matched"] = True
    return det_out, gt_out


# --- AP ------------------------------------------------------------------------------------

def average_precision_101(scores, is_tp, n_scored):
    """COCO's 101-point interpolated AP of detections (score, TP or not; ignored detections
    already left out) against n_scored objects. None when n_scored is 0."""
    if n_scored == 0:
        return None
    scores = np.asarray(scores, float)
    is_tp = np.asarray(is_tp, bool)
    order = np.argsort(-scores, kind="mergesort")
    is_tp = is_tp[order]
    tp = np.cumsum(is_tp)
    fp = np.cumsum(~is_tp)
    if len(tp) == 0:
        return 0.0
    recall = tp / n_scored
    precision = tp / (tp + fp)
    # non-increasing from the right: precision at recall r is the best at recall >= r
    precision = np.maximum.accumulate(precision[::-1])[::-1]
    idx = np.searchsorted(recall, RECALL_THRESHOLDS, side="left")
    q = np.where(idx < len(precision), precision[np.minimum(idx, len(precision) - 1)], 0.0)
    return float(np.mean(q))


def _class_ap(frames_of_class, threshold, min_score):
    scores, tps = [], []
    n_scored = 0
    for fr in frames_of_class:
        n_scored += int(fr.scored.sum())
        outcome, _, s, _ = fr.match(threshold, min_score)
        keep = outcome != IGNORED
        scores.append(s[keep])
        tps.append(outcome[keep] == TP)
    if scores:
        return average_precision_101(np.concatenate(scores), np.concatenate(tps), n_scored)
    return average_precision_101([], [], n_scored)


def _mean(values):
    values = [v for v in values if v is not None]
    return float(np.mean(values)) if values else None


# --- precision and recall ------------------------------------------------------------------

def _ratio(a, b):
    return a / b if b else None


def _counts(frames_of_class, threshold, min_score):
    tp = fp = ign = 0
    n_scored = n_ignored = 0
    for fr in frames_of_class:
        n_scored += int(fr.scored.sum())
        n_ignored += int((~fr.scored).sum())
        outcome, _, _, _ = fr.match(threshold, min_score)
        tp += int((outcome == TP).sum())
        fp += int((outcome == FP).sum())
        ign += int((outcome == IGNORED).sum())
    return {"tp": tp, "fp": fp, "fn": n_scored - tp, "ignored_detections": ign,
            "scored_gt": n_scored, "ignored_gt": n_ignored,
            "precision": _ratio(tp, tp + fp), "recall": _ratio(tp, n_scored)}


def _sum_counts(per_class):
    total = {k: sum(c[k] for c in per_class.values())
             for k in ("tp", "fp", "fn", "ignored_detections", "scored_gt", "ignored_gt")}
    total["precision"] = _ratio(total["tp"], total["tp"] + total["fp"])
    total["recall"] = _ratio(total["tp"], total["scored_gt"])
    return total


def precision_recall(frames, score_threshold=DEFAULT_SCORE_THRESHOLD, classes=None,
                     iou_threshold=IOU_MATCH, min_height=MIN_HEIGHT_PX,
                     min_visible=MIN_VISIBLE_FRACTION, detections_inclusive=False):
    """Precision and recall of the detections with score >= score_threshold (the detector's
    own threshold), over scored objects only. Returns {"per_class": {class: {"precision",
    "recall", "tp", "fp", "fn", "ignored_detections", "scored_gt", "ignored_gt"}},
    "overall": {same keys, summed over classes}}."""
    prepared, other = _prepare(frames, classes, min_height, min_visible, detections_inclusive)
    per_class = {c: _counts(fs, iou_threshold, score_threshold) for c, fs in prepared.items()}
    overall = _sum_counts(per_class)
    overall["other_class_detections"] = other
    return {"per_class": per_class, "overall": overall}


# --- everything ----------------------------------------------------------------------------

def evaluate(frames, classes=None, score_threshold=DEFAULT_SCORE_THRESHOLD, coco=False,
             iou_threshold=IOU_MATCH, min_height=MIN_HEIGHT_PX,
             min_visible=MIN_VISIBLE_FRACTION, detections_inclusive=False):
    """Scores a run. coco=True maps the detections' COCO names first (map_coco_detections).
    Returns {"classes": {class: {"ap50", "ap50_95", "ap_per_iou": {"0.50": ..., ...},
    "precision", "recall", "tp", "fp", "fn", "ignored_detections", "scored_gt",
    "ignored_gt"}}, "map50", "map50_95", "mean_over": [classes with a scored object],
    "precision", "recall", "tp", "fp", "fn", "ignored_detections", "scored_gt", "ignored_gt",
    "other_class_detections", "frames", and the thresholds used}. AP values are None for a
    class without a scored object."""
    if coco:
        try:
            frames = map_coco_detections(frames, classes)
        except (KeyError, TypeError, AttributeError) as e:
            raise ValueError("frames: bad frame or box (%s: %s)" % (type(e).__name__, e)) from None
    prepared, other = _prepare(frames, classes, min_height, min_visible, detections_inclusive)
    out_classes = {}
    for c, fs in prepared.items():
        aps = {"%.2f" % t: _class_ap(fs, t, AP_SCORE_THRESHOLD) for t in IOU_THRESHOLDS}
        entry = {"ap50": aps["0.50"],
                 "ap50_95": None if aps["0.50"] is None else float(np.mean(list(aps.values()))),
                 "ap_per_iou": aps}
        entry.update(_counts(fs, iou_threshold, score_threshold))
        out_classes[c] = entry
    mean_over = [c for c, e in out_classes.items() if e["scored_gt"] > 0]
    result = {"classes": out_classes,
              "map50": _mean([out_classes[c]["ap50"] for c in mean_over]),
              "map50_95": _mean([out_classes[c]["ap50_95"] for c in mean_over]),
              "mean_over": mean_over}
    result.update(_sum_counts(out_classes))
    result.update({"other_class_detections": other, "frames": len(frames),
                   "score_threshold": score_threshold, "iou_threshold": iou_threshold,
                   "ap_score_threshold": AP_SCORE_THRESHOLD,
                   "iou_thresholds": list(IOU_THRESHOLDS),
                   "min_height_px": min_height, "min_visible_fraction": min_visible})
    return result


def format_table(result):
    """The result of evaluate() as a text table."""
    def f(v):
        return "-" if v is None else "%.3f" % v

    t = result["score_threshold"]
    head = "%-12s %7s %7s %6s %6s %6s %7s %7s %7s %7s" % (
        "class", "scored", "ignored", "TP", "FP", "FN", "AP50", "AP50:95", "P@%g" % t,
        "R@%g" % t)
    lines = [head, "-" * len(head)]
    for c, e in result["classes"].items():
        lines.append("%-12s %7d %7d %6d %6d %6d %7s %7s %7s %7s" % (
            c, e["scored_gt"], e["ignored_gt"], e["tp"], e["fp"], e["fn"], f(e["ap50"]),
            f(e["ap50_95"]), f(e["precision"]), f(e["recall"])))
    lines.append("-" * len(head))
    lines.append("%-12s %7d %7d %6d %6d %6d %7s %7s %7s %7s" % (
        "all", result["scored_gt"], result["ignored_gt"], result["tp"], result["fp"],
        result["fn"], f(result["map50"]), f(result["map50_95"]), f(result["precision"]),
        f(result["recall"])))
    lines.append("%d frames; mAP over %d classes with a scored object (%s); P/R at score >= %g, "
                 "IoU >= %g; AP from score >= %g; %d detections of other classes left out" % (
                     result["frames"], len(result["mean_over"]), ", ".join(result["mean_over"]),
                     t, result["iou_threshold"], result["ap_score_threshold"],
                     result["other_class_detections"]))
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(
        prog="python3 -m convoy_perception.evaluation",
        description="Scores detections against ground truth (docs/perception.md).")
    p.add_argument("file", help='JSON: a list of frames {"gt": [...], "detections": [...]}, '
                                'or {"frames": [...]}')
    p.add_argument("--score-threshold", type=float, default=DEFAULT_SCORE_THRESHOLD,
                   help="the detector's threshold, for precision and recall (default %(default)s)")
    p.add_argument("--classes", help="comma-separated classes (default: the ground truth's)")
    p.add_argument("--coco", action="store_true",
                   help="map a stock COCO detector's class names first (person -> pedestrian, ...)")
    p.add_argument("--detections-inclusive", action="store_true",
                   help="detection boxes are inclusive pixel coordinates, like the ground truth")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    args = p.parse_args(argv)
    try:
        with open(args.file) as fh:
            data = json.load(fh)
    except (OSError, ValueError) as e:
        print("error: %s: %s" % (args.file, e), file=sys.stderr)
        return 2
    frames = data.get("frames") if isinstance(data, dict) else data
    classes = [c for c in args.classes.split(",") if c] if args.classes else None
    try:
        result = evaluate(frames, classes=classes, score_threshold=args.score_threshold,
                          coco=args.coco, detections_inclusive=args.detections_inclusive)
    except ValueError as e:
        print("error: %s: %s" % (args.file, e), file=sys.stderr)
        return 2
    print(json.dumps(result, indent=1) if args.json else format_table(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
