#!/usr/bin/python3
"""Trains Convoy's detector (model.py) on COCO data written by tools/dataset/make_dataset.py,
on the CPU with Debian's python3-torch, and exports it for OpenCV 4.6 DNN.

  /usr/bin/python3 tools/detector/train.py --data DIR [--data DIR2 ...] --out models/detector
      [--epochs 12] [--batch 16] [--input 320 | WxH] [--seed 0] [--val DIR] [--iterations N]

Writes into --out: convoy_detector.onnx (YOLOv8 layout, 1 x (4 + C) x N, cx cy w h in input
pixels), classes.txt, model.json ({input_width, input_height, classes, ...}) and
training.json (the recipe: arguments, data, per-epoch loss, the validation mAP). The same
seed, data and arguments give the same weights (torch's CPU kernels, one thread order).

Recipe: letterboxed input (pad 114, as the detector engine does), random horizontal flip,
random zoom 0.75-2 with a random placement, brightness and contrast jitter; FCOS-style
assignment (a cell is positive for a box when its centre lies in the box and within 2.5
strides of the box centre, on the level whose size range holds the box's longer side: < 64,
64-128, >= 128 px, the cell under the centre always; the smallest box wins a cell);
classification BCE with the IoU of the predicted box as the positives' target, normalised by
the positives; GIoU loss on the positives (weight 5); AdamW, cosine learning rate.
"""
import argparse
import json
import math
import os
import random
import sys
import time

import cv2
import numpy as np
import torch
import torch.nn.functional as F

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(REPO, "python"))

import export as onnx_export  # noqa: E402
from gain import brighten  # noqa: E402
from model import NECKS, STRIDES, Detector  # noqa: E402

CLASSES = ["car", "truck", "bus", "pedestrian", "cyclist"]
LEVEL_RANGES = ((0, 64), (64, 128), (128, 1e9))
PAD = 114


def read_ground_truth(folder):
    """The COCO document of `folder` and, per image id, its road users as
    convoy_perception.evaluation's ground truth (inclusive pixel boxes, visible_fraction)."""
    with open(os.path.join(folder, "annotations.json")) as f:
        doc = json.load(f)
    cats = {c["id"]: c["name"] for c in doc["categories"]}
    gts = {img["id"]: [] for img in doc["images"]}
    for a in doc["annotations"]:
        name = cats[a["category_id"]]
        if name in CLASSES:
            x, y, w, h = a["bbox"]
            gts[a["image_id"]].append({"class": name, "x_min": x, "y_min": y, "x_max": x + w - 1,
                                       "y_max": y + h - 1, "visible_fraction": a.get("visible_fraction", 1.0)})
    return doc, gts


def load_coco(folders, min_height=8):
    """[(image path, boxes N x 4 (x0, y0, x1, y1 edges), classes N)] from COCO folders."""
    items = []
    for folder in folders:
        with open(os.path.join(folder, "annotations.json")) as f:
            doc = json.load(f)
        cats = {c["id"]: c["name"] for c in doc["categories"]}
        by_image = {img["id"]: [] for img in doc["images"]}
        for a in doc["annotations"]:
            name = cats[a["category_id"]]
            if name not in CLASSES:
                continue
            x, y, w, h = a["bbox"]
            if h < min_height:
                continue
            by_image[a["image_id"]].append((x, y, x + w, y + h, CLASSES.index(name)))
        for img in doc["images"]:
            b = np.array([r[:4] for r in by_image[img["id"]]], np.float32).reshape(-1, 4)
            c = np.array([r[4] for r in by_image[img["id"]]], np.int64)
            items.append((os.path.join(folder, img["file_name"]), b, c))
    return items


def brighten_meta():
    """model.json's "brighten" entry ({} when the input is not brightened)."""
    return {"brighten": {"target_mean": BRIGHTEN[0], "max_gain": BRIGHTEN[1]}} if BRIGHTEN else {}


def parse_brighten(text, ap):
    """'TARGET,MAX_GAIN' -> (target, max_gain); 'none' -> None."""
    if text == "none":
        return None
    try:
        target, gain = (float(v) for v in text.split(","))
    except ValueError:
        ap.error("--brighten: '%s': expected TARGET,MAX_GAIN or none" % text)
    if not (0 < target < 255 and gain >= 1):
        ap.error("--brighten: '%s': TARGET in (0, 255), MAX_GAIN >= 1" % text)
    return target, gain


def parse_size(text):
    """'320' (square) or '448x288' (width x height), multiples of 32."""
    w, _, h = text.partition("x")
    try:
        size = (int(w), int(h or w))
    except ValueError:
        raise argparse.ArgumentTypeError("'%s': expected SIDE or WIDTHxHEIGHT" % text)
    if min(size) <= 0 or size[0] % 32 or size[1] % 32:
        raise argparse.ArgumentTypeError("'%s': sides must be positive multiples of 32" % text)
    return size


BRIGHTEN = None  # the input's gain, (target mean, most gain) (--brighten; model.json's); none


def letterbox(image, size, scale_jitter=1.0, rng=None, gain=None):
    """Resizes into a size = (width, height) canvas (pad 114): returns the canvas, the scale
    and the offsets, with a random zoom and placement when rng is given; the resized image
    brightened by `gain` (target mean, most gain; None: as it is)."""
    h, w = image.shape[:2]
    sw, sh = size
    scale = min(sw / w, sh / h) * scale_jitter
    nw, nh = max(1, int(round(w * scale))), max(1, int(round(h * scale)))
    resized = cv2.resize(image, (nw, nh), interpolation=cv2.INTER_LINEAR)
    if gain:
        resized = brighten(resized, *gain)
    canvas = np.full((sh, sw, 3), PAD, np.uint8)
    if rng is None:
        ox, oy = (sw - nw) // 2, (sh - nh) // 2
    else:
        ox = rng.randint(min(0, sw - nw), max(0, sw - nw))
        oy = rng.randint(min(0, sh - nh), max(0, sh - nh))
    x0, y0 = max(ox, 0), max(oy, 0)
    x1, y1 = min(ox + nw, sw), min(oy + nh, sh)
    canvas[y0:y1, x0:x1] = resized[y0 - oy:y1 - oy, x0 - ox:x1 - ox]
    return canvas, scale, ox, oy


FOG_SHARE, DARK_SHARE = 0.0, 0.0  # of the training samples given synthetic fog / darkness
#                                   (--synthetic-weather; session 25 tried 0.2 and 0.15)
FOG_RGB = np.array([0.75, 0.77, 0.8], np.float32) * 255  # the world engine's fog colour by day


def depth_of(path):
    """The depth (m; inf where nothing was hit) of a dataset image, from DIR/depth/<name>.png
    (mm, uint16, 65535: beyond range), or None."""
    folder, name = os.path.split(path)
    d = cv2.imread(os.path.join(os.path.dirname(folder), "depth", os.path.splitext(name)[0] + ".png"),
                   cv2.IMREAD_UNCHANGED)
    if d is None:
        return None
    m = d.astype(np.float32) / 1000.0
    m[d == 65535] = np.inf
    return m


def weather_augment(image, path, rng):
    """More fog and night than the renders have: a share of the samples is fogged as the world
    engine fogs (Koschmieder: transmission exp(-3.912 d / V), V 60-400 m, towards the fog's
    colour, dimmed by 0-40 %) from the image's depth, another darkened (a gain of 0.15-0.5 after
    a gamma of 1-1.6, with sensor noise). The rest is left as rendered."""
    if FOG_SHARE + DARK_SHARE <= 0:
        return image  # (no draw: the shipped model's samples as they were)
    r = rng.random()
    if r >= FOG_SHARE + DARK_SHARE:
        return image
    x = image.astype(np.float32)
    noise = np.random.default_rng(rng.getrandbits(32))
    if r < FOG_SHARE:
        depth = depth_of(path)
        if depth is None:
            return image
        t = np.exp(-3.912 * depth / rng.uniform(60.0, 400.0))[:, :, None]
        x = x * t + FOG_RGB * rng.uniform(0.6, 1.0) * (1.0 - t)
    else:
        x = 255.0 * (x / 255.0) ** rng.uniform(1.0, 1.6) * rng.uniform(0.15, 0.5)
        x = x + noise.normal(0.0, rng.uniform(1.0, 5.0), x.shape).astype(np.float32)
    return np.clip(x, 0, 255).astype(np.uint8)


def sample(item, size, rng, augment):
    path, boxes, classes = item
    image = cv2.imread(path)[:, :, ::-1]  # RGB
    if augment:
        image = weather_augment(image, path, rng)
        jitter = math.exp(rng.uniform(math.log(0.75), math.log(2.0)))
        canvas, s, ox, oy = letterbox(image, size, jitter, rng, BRIGHTEN)
    else:
        canvas, s, ox, oy = letterbox(image, size, gain=BRIGHTEN)
    b = boxes * s + np.array([ox, oy, ox, oy], np.float32)
    b = np.clip(b, 0, np.array([size[0], size[1], size[0], size[1]], np.float32))
    keep = ((b[:, 2] - b[:, 0]) >= 2) & ((b[:, 3] - b[:, 1]) >= 2)
    b, c = b[keep], classes[keep]
    if augment:
        if rng.random() < 0.5:
            canvas = canvas[:, ::-1]
            b = np.stack([size[0] - b[:, 2], b[:, 1], size[0] - b[:, 0], b[:, 3]], 1)
        canvas = canvas.astype(np.float32)
        canvas = canvas * rng.uniform(0.7, 1.3) + rng.uniform(-25, 25)
        canvas = np.clip(canvas, 0, 255)
    x = torch.from_numpy(np.ascontiguousarray(canvas, dtype=np.float32).transpose(2, 0, 1) / 255.0)
    return x, torch.from_numpy(np.asarray(b, np.float32)), torch.from_numpy(np.asarray(c, np.int64))


def cell_grid(size):
    """Per cell: centre x, y, stride and level index, over the three levels in order, for an
    input of size (width, height)."""
    out = []
    for level, s in enumerate(STRIDES):
        nx, ny = size[0] // s, size[1] // s
        ys, xs = torch.meshgrid(torch.arange(ny), torch.arange(nx), indexing="ij")
        out.append(torch.stack([(xs.flatten() + 0.5) * s, (ys.flatten() + 0.5) * s,
                                torch.full((nx * ny,), float(s)), torch.full((nx * ny,), float(level))], 1))
    return torch.cat(out, 0)


def assign(boxes, grid):
    """Index of the box each cell is positive for (-1: none)."""
    n = grid.shape[0]
    target = torch.full((n,), -1, dtype=torch.long)
    if boxes.shape[0] == 0:
        return target
    cx, cy, stride, level = grid[:, 0:1], grid[:, 1:2], grid[:, 2:3], grid[:, 3:4]
    x0, y0, x1, y1 = boxes[:, 0][None], boxes[:, 1][None], boxes[:, 2][None], boxes[:, 3][None]
    side = torch.maximum(x1 - x0, y1 - y0)
    lo = torch.tensor([r[0] for r in LEVEL_RANGES])[level.long().squeeze(1)][:, None]
    hi = torch.tensor([r[1] for r in LEVEL_RANGES])[level.long().squeeze(1)][:, None]
    in_level = (side >= lo) & (side < hi)
    bcx, bcy = (x0 + x1) / 2, (y0 + y1) / 2
    inside = (cx > x0) & (cx < x1) & (cy > y0) & (cy < y1)
    near = ((cx - bcx).abs() < 2.5 * stride) & ((cy - bcy).abs() < 2.5 * stride)
    under = ((cx - bcx).abs() <= stride / 2) & ((cy - bcy).abs() <= stride / 2)
    pos = in_level & ((inside & near) | under)
    area = ((x1 - x0) * (y1 - y0)).expand(n, -1)
    area = torch.where(pos, area, torch.full_like(area, float("inf")))
    best_area, best = area.min(1)
    target[best_area < float("inf")] = best[best_area < float("inf")]
    return target


def giou(a, b):
    """GIoU of cx, cy, w, h boxes a with x0, y0, x1, y1 boxes b (rows)."""
    ax0, ay0 = a[:, 0] - a[:, 2] / 2, a[:, 1] - a[:, 3] / 2
    ax1, ay1 = a[:, 0] + a[:, 2] / 2, a[:, 1] + a[:, 3] / 2
    bx0, by0, bx1, by1 = b.unbind(1)
    iw = (torch.minimum(ax1, bx1) - torch.maximum(ax0, bx0)).clamp(min=0)
    ih = (torch.minimum(ay1, by1) - torch.maximum(ay0, by0)).clamp(min=0)
    inter = iw * ih
    union = (ax1 - ax0) * (ay1 - ay0) + (bx1 - bx0) * (by1 - by0) - inter + 1e-9
    iou = inter / union
    cw = torch.maximum(ax1, bx1) - torch.minimum(ax0, bx0)
    ch = torch.maximum(ay1, by1) - torch.minimum(ay0, by0)
    hull = cw * ch + 1e-9
    return iou - (hull - union) / hull, iou


def loss_of(model, x, targets, grid):
    raws = model.raw(x)
    flat = torch.cat([r.flatten(2) for r in raws], 2)  # B x (4 + C) x N
    decoded = model.decode(raws)
    b, nc = x.shape[0], model.num_classes
    cls_target = torch.zeros(b, nc, flat.shape[2])
    box_loss, n_pos = torch.zeros(()), 0
    for i, (boxes, classes) in enumerate(targets):
        idx = assign(boxes, grid)
        pos = idx >= 0
        if pos.any():
            pred = decoded[i, :4, pos].t()
            g, iou = giou(pred, boxes[idx[pos]])
            box_loss = box_loss + (1 - g).sum()
            cls_target[i, classes[idx[pos]], pos] = iou.detach().clamp(min=0.05)
            n_pos += int(pos.sum())
    n = max(n_pos, 1)
    cls_loss = F.binary_cross_entropy_with_logits(flat[:, 4:], cls_target, reduction="sum") / n
    return cls_loss + 5.0 * box_loss / n, float(cls_loss), float(box_loss / n)


def detect(model, x, conf=0.001, nms=0.6, max_det=300):
    """Per image: detections (x0, y0, x1, y1, score, class) in input pixels."""
    with torch.no_grad():
        out = model(x)
    results = []
    for o in out:
        boxes, scores = o[:4].t(), o[4:].t()
        dets = []
        for c in range(scores.shape[1]):
            s = scores[:, c]
            keep = s >= conf
            if not keep.any():
                continue
            bb, ss = boxes[keep], s[keep]
            rects = [[float(q[0] - q[2] / 2), float(q[1] - q[3] / 2), float(q[2]), float(q[3])] for q in bb]
            kept = cv2.dnn.NMSBoxes(rects, ss.tolist(), conf, nms)
            for k in np.array(kept).flatten():
                r = rects[int(k)]
                dets.append((r[0], r[1], r[0] + r[2], r[1] + r[3], float(ss[int(k)]), c))
        dets.sort(key=lambda d: -d[4])
        results.append(dets[:max_det])
    return results


def evaluate_folder(model, folder, size):
    """mAP on a COCO folder with the project's rules (convoy_perception.evaluation)."""
    from convoy_perception.evaluation import evaluate
    doc, gts = read_ground_truth(folder)
    model.eval()
    frames = []
    for img in doc["images"]:
        image = cv2.imread(os.path.join(folder, img["file_name"]))[:, :, ::-1]
        canvas, s, ox, oy = letterbox(image, size, gain=BRIGHTEN)
        x = torch.from_numpy(np.ascontiguousarray(canvas, dtype=np.float32).transpose(2, 0, 1)[None] / 255.0)
        dets = []
        for x0, y0, x1, y1, score, c in detect(model, x)[0]:
            dets.append({"class": CLASSES[c], "score": score, "x_min": (x0 - ox) / s, "y_min": (y0 - oy) / s,
                         "x_max": (x1 - ox) / s, "y_max": (y1 - oy) / s})
        frames.append({"gt": gts[img["id"]], "detections": dets})
    present = sorted({g["class"] for f in frames for g in f["gt"]})
    return evaluate(frames, classes=present)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", action="append", required=True)
    ap.add_argument("--val", action="append", default=[])
    ap.add_argument("--out", required=True)
    ap.add_argument("--epochs", type=int, default=12)
    ap.add_argument("--iterations", type=int, default=0, help="stop after this many (smoke tests)")
    ap.add_argument("--batch", type=int, default=16)
    ap.add_argument("--input", type=parse_size, default=(320, 320),
                    help="network input: SIDE or WIDTHxHEIGHT (multiples of 32)")
    ap.add_argument("--lr", type=float, default=2e-3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--neck", choices=sorted(NECKS), default="dense",
                    help="the fusions' and heads' convolutions (tools/detector/model.py)")
    ap.add_argument("--brighten", default="none", metavar="TARGET,MAX_GAIN|none",
                    help="the input's gain, as the detector engine applies it (model.json's "
                         "\"brighten\"): dark images scaled towards a mean of TARGET, by at most "
                         "MAX_GAIN, e.g. 90,8 (default none, as the shipped model)")
    ap.add_argument("--synthetic-weather", default="0,0", metavar="FOG,DARK",
                    help="shares of the training samples given synthetic fog and darkness "
                         "(weather_augment; default 0,0, as the shipped model)")
    args = ap.parse_args()
    globals()["BRIGHTEN"] = parse_brighten(args.brighten, ap)  # (what letterbox gets from now on)
    try:
        fog, dark = (float(v) for v in args.synthetic_weather.split(","))
    except ValueError:
        ap.error("--synthetic-weather: '%s': expected FOG,DARK" % args.synthetic_weather)
    if not (fog >= 0 and dark >= 0 and fog + dark <= 1):
        ap.error("--synthetic-weather: '%s': shares >= 0 summing to at most 1" % args.synthetic_weather)
    globals().update(FOG_SHARE=fog, DARK_SHARE=dark)
    torch.manual_seed(args.seed)
    torch.set_num_threads(args.threads)
    rng = random.Random(args.seed)
    items = load_coco(args.data)
    if not items:
        sys.exit("train: no images in %s" % args.data)
    model = Detector(len(CLASSES), input_size=args.input, neck=args.neck)
    grid = cell_grid(args.input)
    steps_per_epoch = max(1, len(items) // args.batch)
    total = steps_per_epoch * args.epochs if not args.iterations else args.iterations
    opt = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=5e-4)
    sched = torch.optim.lr_scheduler.LambdaLR(
        opt, lambda k: min(1.0, (k + 1) / 100) * 0.5 * (1 + math.cos(math.pi * min(k, total) / total)))
    os.makedirs(args.out, exist_ok=True)
    history, step, t0 = [], 0, time.time()
    print("train: %d images, %d steps of %d, input %dx%d" % ((len(items), total, args.batch) + args.input), flush=True)
    done = False
    for epoch in range(args.epochs if not args.iterations else 10 ** 6):
        model.train()
        order = list(range(len(items)))
        rng.shuffle(order)
        sums = [0.0, 0.0, 0.0]
        for k in range(steps_per_epoch):
            batch = [sample(items[i], args.input, rng, True) for i in order[k * args.batch:(k + 1) * args.batch]]
            x = torch.stack([b[0] for b in batch])
            loss, lc, lb = loss_of(model, x, [(b[1], b[2]) for b in batch], grid)
            opt.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 10.0)
            opt.step()
            sched.step()
            step += 1
            sums = [sums[0] + float(loss), sums[1] + lc, sums[2] + lb]
            if step % 20 == 0:
                print("epoch %d step %d/%d loss %.3f (cls %.3f box %.3f) %.0f s" % (
                    epoch, step, total, float(loss), lc, lb, time.time() - t0), flush=True)
            if step >= total:
                done = True
                break
        entry = {"epoch": epoch, "steps": step, "loss": sums[0] / max(1, k + 1), "cls": sums[1] / max(1, k + 1),
                 "box": sums[2] / max(1, k + 1), "wall_s": round(time.time() - t0, 1)}
        history.append(entry)
        print("epoch %d: %s" % (epoch, entry), flush=True)
        torch.save(model.state_dict(), os.path.join(args.out, "weights.pt"))
        if done:
            break
    val = {}
    for folder in args.val:
        r = evaluate_folder(model, folder, args.input)
        val[folder] = {"map50": r["map50"], "map50_95": r["map50_95"], "precision": r["precision"],
                       "recall": r["recall"], "mean_over": r["mean_over"],
                       "classes": {c: {k: v[k] for k in ("ap50", "ap50_95", "precision", "recall", "scored_gt")}
                                   for c, v in r["classes"].items()}}
        print("validation %s: mAP50 %s mAP50:95 %s %s" % (folder, r["map50"], r["map50_95"],
              {c: round(v["ap50"], 3) for c, v in r["classes"].items() if v["ap50"] is not None}), flush=True)
    ops = onnx_export.export(model, os.path.join(args.out, "convoy_detector.onnx"), args.input)
    with open(os.path.join(args.out, "classes.txt"), "w") as f:
        f.write("\n".join(CLASSES) + "\n")
    with open(os.path.join(args.out, "model.json"), "w") as f:
        json.dump({"input_width": args.input[0], "input_height": args.input[1], "classes": CLASSES,
                   "layout": "yolov8: 1 x (4 + C) x N, cx cy w h in input pixels, class scores",
                   "letterbox_pad": PAD, "onnx_opset": 12, "onnx_ops": ops,
                   **brighten_meta()},
                  f, indent=1)
    with open(os.path.join(args.out, "training.json"), "w") as f:
        json.dump({"command": " ".join(sys.argv), "args": vars(args), "images": len(items),
                   "history": history, "validation": val, "torch": torch.__version__}, f, indent=1)
    os.remove(os.path.join(args.out, "weights.pt"))
    print("train: wrote %s (%.0f s)" % (args.out, time.time() - t0), flush=True)


if __name__ == "__main__":
    main()
