#!/usr/bin/python3
"""Perception benchmark: prints the figures of the perception issue (median of --runs).

  /usr/bin/python3 benchmarks/perception_bench.py [--runs 3] [--seconds 60]
      [--heldout [LABEL=]DIR ...] [--model [LABEL=]DIR ...] [--stock MODEL.onnx]
      [--skip-speed] [--skip-loop]

  - Convoy's detector (models/detector) on a held-out render set (--heldout, a COCO folder
    from tools/dataset/make_dataset.py whose seeds and camera paths training never saw, or
    several folders joined by commas, scored as one set):
    mAP@0.5 and mAP@0.5:0.95 per class, by convoy_perception.evaluation (target mAP@0.5 >= 0.8
    over car, bus, pedestrian); with several --heldout sets (e.g. one per weather) and several
    --model folders (e.g. trained on clear weather only and on all weathers), a table of mAP@0.5
    by model and set
  - its milliseconds per 736x480 frame in OpenCV 4.6 DNN on this machine (letterbox, forward
    and decoding; the median of 200 frames; target <= 30 ms), as the detector engine runs it
  - the report's "both" experiment with Convoy's detector in the loop, every camera frame
    detected: camera frames/s (target >= 20); and with the detector at 10 Hz of simulated
    time (EngineTimestep 0.1, stepping concurrently under FTILoop)
  - with --stock: the stock COCO detector (shared/tools/stock_detector, never shipped) on the
    Parkring lap: recall on scored cars, buses and pedestrians (target >= 0.5), from the
    evaluator's summary (COCO names mapped: person -> pedestrian, car/truck -> car, bus)
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "python"))
sys.path.insert(0, os.path.join(REPO, "tools", "detector"))
MODEL_DIR = os.path.join(REPO, "models", "detector")

from gain import brighten, from_meta  # noqa: E402 (tools/detector, on the path above)
BOTH = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_both.json")


def load_model(model_dir):
    with open(os.path.join(model_dir, "model.json")) as f:
        meta = json.load(f)
    net = cv2.dnn.readNetFromONNX(os.path.join(model_dir, "convoy_detector.onnx"))
    return net, meta


def detect(net, meta, image_rgb, conf=0.001, nms=0.6):
    """The detector engine's steps in Python: letterbox (pad 114; the model's gain, if any, on
    the resized image), forward, per-class NMS."""
    sw, sh = meta["input_width"], meta["input_height"]
    h, w = image_rgb.shape[:2]
    s = min(sw / w, sh / h)
    nw, nh = int(round(w * s)), int(round(h * s))
    ox, oy = (sw - nw) // 2, (sh - nh) // 2
    canvas = np.full((sh, sw, 3), 114, np.uint8)
    resized = cv2.resize(image_rgb, (nw, nh), interpolation=cv2.INTER_LINEAR)
    gain = from_meta(meta)
    canvas[oy:oy + nh, ox:ox + nw] = brighten(resized, *gain) if gain else resized
    net.setInput(cv2.dnn.blobFromImage(canvas, 1 / 255.0))
    out = net.forward()[0]
    boxes, scores = out[:4].T, out[4:].T
    dets = []
    for c, name in enumerate(meta["classes"]):
        keep = np.flatnonzero(scores[:, c] >= conf)
        if keep.size == 0:
            continue
        rects = [[float(b[0] - b[2] / 2), float(b[1] - b[3] / 2), float(b[2]), float(b[3])] for b in boxes[keep]]
        for k in np.array(cv2.dnn.NMSBoxes(rects, scores[keep, c].tolist(), conf, nms)).flatten():
            x, y, bw, bh = rects[int(k)]
            dets.append({"class": name, "score": float(scores[keep[int(k)], c]),
                         "x_min": (x - ox) / s, "y_min": (y - oy) / s,
                         "x_max": (x + bw - ox) / s, "y_max": (y + bh - oy) / s})
    return dets


def heldout_map(model_dir, folder, classes=("car", "bus", "pedestrian")):
    """The model's evaluation on a COCO folder, or on several scored as one set (their paths
    joined by commas); returns (result, frames)."""
    from convoy_perception.evaluation import evaluate
    net, meta = load_model(model_dir)
    from train import read_ground_truth
    frames = []
    for one in folder.split(","):
        doc, gts = read_ground_truth(one)
        for img in doc["images"]:
            image = cv2.imread(os.path.join(one, img["file_name"]))[:, :, ::-1]
            frames.append({"gt": [g for g in gts[img["id"]] if g["class"] in classes],
                           "detections": detect(net, meta, np.ascontiguousarray(image))})
    present = [c for c in classes if any(g["class"] == c for f in frames for g in f["gt"])]
    return evaluate(frames, classes=present), len(frames)


def ms_per_frame(model_dir, frames=200):
    net, meta = load_model(model_dir)
    rng = np.random.default_rng(0)
    image = rng.integers(0, 255, (480, 736, 3), dtype=np.uint8)
    for _ in range(10):
        detect(net, meta, image, conf=0.25, nms=0.45)
    times = []
    for _ in range(frames):
        t = time.perf_counter()
        detect(net, meta, image, conf=0.25, nms=0.45)
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def run_both(build, work, label, overrides, seconds):
    run_dir = os.path.join(work, label)
    cmd = [os.path.join(build, "bin", "convoy"), "run", "-q", "-c", BOTH, "--run-dir", run_dir,
           "-o", "SimulationTimeout=%g" % seconds]
    for o in overrides:
        cmd += ["-o", o]
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("run failed: %s\n%s" % (" ".join(cmd), r.stderr[-2000:]))
    with open(os.path.join(run_dir, "summary.json")) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--heldout", action="append", default=[], metavar="[LABEL=]DIR[,DIR...]",
                    help="COCO folder of held-out renders, or several scored as one set (repeat "
                         "for a table by set)")
    ap.add_argument("--stock", help="the stock COCO detector's ONNX (shared/tools/stock_detector)")
    ap.add_argument("--stock-seconds", type=float, default=185.0)
    ap.add_argument("--model", action="append", default=[], metavar="[LABEL=]DIR",
                    help="detector folder (default models/detector; repeat for a table by model)")
    ap.add_argument("--skip-speed", action="store_true", help="only the held-out figures")
    ap.add_argument("--build", default=os.path.join(REPO, "build"))
    ap.add_argument("--skip-loop", action="store_true")
    args = ap.parse_args()
    labelled = lambda items: [(i.partition("=")[0], i.partition("=")[2]) if "=" in i else
                              (os.path.basename(os.path.normpath(i)), i) for i in items]
    models = labelled(args.model or [MODEL_DIR])
    sets = labelled(args.heldout)
    table = {}
    for mlabel, mdir in models:
        for slabel, folder in sets:
            r, n = heldout_map(mdir, folder)
            table[(mlabel, slabel)] = r["map50"]
            for c, v in r["classes"].items():
                print("%s on %s (%d frames), %-10s AP50 %s  AP50:95 %s  (scored %d)" % (
                    mlabel, slabel, n, c, "%.3f" % v["ap50"] if v["ap50"] is not None else "-",
                    "%.3f" % v["ap50_95"] if v["ap50_95"] is not None else "-", v["scored_gt"]))
            print("%s mAP@0.5 on %s: %.3f  mAP@0.5:0.95 %.3f  target mAP@0.5 >= 0.8" % (
                mlabel, slabel, r["map50"], r["map50_95"]), flush=True)
    if len(table) > 1:
        print("\nmAP@0.5 | " + " | ".join(label for label, _ in sets))
        for mlabel, _ in models:
            print("%s | %s" % (mlabel, " | ".join("%.3f" % table[(mlabel, sl)] for sl, _ in sets)))
    if args.skip_speed:
        return
    model_dir = models[0][1]
    ms = [ms_per_frame(model_dir) for _ in range(args.runs)]
    print("Convoy detector ms per 736x480 frame (2 cores, OpenCV DNN): median %.1f (runs: %s)  target <= 30" % (
        statistics.median(ms), ", ".join("%.1f" % m for m in ms)))
    work = tempfile.mkdtemp(prefix="convoy-perception-bench-")
    try:
        if not args.skip_loop:
            with open(BOTH) as f:
                names = [e["EngineName"] for e in json.load(f)["EngineConfigs"]]
            det = names.index("yolo_detector")
            for label, extra in (("every frame", []), ("10 Hz", ["EngineConfigs/%d/EngineTimestep=0.1" % det])):
                fps, inf = [], []
                for i in range(args.runs):
                    s = run_both(args.build, work, "%s-%d" % (label.replace(" ", ""), i),
                                 ["EngineConfigs/%d/Backend=convoy" % det] + extra, args.seconds)
                    fps.append(s["camera_frames_per_s"])
                    inf.append(s.get("detector_inference_ms_median") or 0)
                print("\"both\" with Convoy's detector, detection %-11s camera frames/s median %.1f (runs: %s), "
                      "inference %.1f ms%s" % (label + ":", statistics.median(fps), ", ".join("%.1f" % v for v in fps),
                                               statistics.median(inf), "  target >= 20" if not extra else ""))
        if args.stock:
            with open(BOTH) as f:
                names = [e["EngineName"] for e in json.load(f)["EngineConfigs"]]
            det = names.index("yolo_detector")
            s = run_both(args.build, work, "stock", ["EngineConfigs/%d/Backend=yolo" % det,
                                                      "EngineConfigs/%d/ModelPath=%s" % (det, args.stock),
                                                      "EngineConfigs/%d/InputSize=512" % det,
                                                      "EngineConfigs/%d/YoloVersion=v8" % det], args.stock_seconds)
            print("stock COCO detector on the Parkring lap (%g s): recall %.3f, precision %.3f, mAP@0.5 %s over %s "
                  "scored objects  target recall >= 0.5" % (
                      args.stock_seconds, s["detector_recall"] or 0, s["detector_precision"] or 0,
                      s.get("detector_map50"), s.get("detector_scored_objects")))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
