#!/usr/bin/python3
"""A bird's-eye PNG of a scenario run's tracks over esmini's reference tracks (docs/scenarios.md,
"Agreement with esmini"): each entity's reference as a wide pale line, Convoy's as a thin line of
the same colour on it, a dot every 2 s, the map's lane borders in grey.

  /usr/bin/python3 tools/esmini/plot_tracks.py RUN_DIR/tracks.csv tests/data/esmini/reference/NAME.csv.gz OUT.png
      [--map MAP.xodr] [--size 900]
"""

import argparse
import os
import sys

import cv2
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_scenario import compare  # noqa: E402

COLOURS = [(40, 90, 220), (40, 170, 60), (210, 120, 30), (160, 60, 180), (30, 170, 200)]  # BGR
MARGIN = 40


def lane_lines(xodr, box):
    """Lane centre polylines of the map near the box (x0, y0, x1, y1), from the OpenDRIVE module."""
    from convoy_scenario.roads import RoadMap
    m = RoadMap.open(xodr)
    out = []
    for road in m.road_ids():
        length = m.road_length(road)
        for lane in m.lanes_at(road, 0.0) + m.lanes_at(road, length):
            pts = []
            s = 0.0
            while s <= length:
                try:
                    x, y = m.lane_pose(road, lane, s)[:2]
                    pts.append((x, y))
                except Exception:  # noqa: BLE001 - the lane does not reach here
                    pass
                s += 2.0
            if any(box[0] <= x <= box[2] and box[1] <= y <= box[3] for x, y in pts):
                out.append(pts)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tracks")
    ap.add_argument("reference")
    ap.add_argument("out")
    ap.add_argument("--map")
    ap.add_argument("--size", type=int, default=900)
    a = ap.parse_args()
    ours, ref = compare.read_tracks(a.tracks), compare.read_tracks(a.reference)
    xs = [x for tr in list(ref.values()) + list(ours.values()) for x in tr.x]
    ys = [y for tr in list(ref.values()) + list(ours.values()) for y in tr.y]
    x0, x1, y0, y1 = min(xs) - 5, max(xs) + 5, min(ys) - 5, max(ys) + 5
    scale = (a.size - 2 * MARGIN) / max(x1 - x0, y1 - y0)
    w, h = max(520, int((x1 - x0) * scale) + 2 * MARGIN), int((y1 - y0) * scale) + 2 * MARGIN
    img = np.full((h, w, 3), 250, np.uint8)
    px = lambda x, y: (int(MARGIN + (x - x0) * scale), int(h - MARGIN - (y - y0) * scale))  # noqa: E731
    if a.map:
        for line in lane_lines(a.map, (x0, y0, x1, y1)):
            cv2.polylines(img, [np.array([px(x, y) for x, y in line], np.int32)], False, (205, 205, 205), 1)
    for i, name in enumerate(sorted(ref)):
        c = COLOURS[i % len(COLOURS)]
        pale = tuple(int(v + (255 - v) * 0.65) for v in c)
        r = ref[name]
        cv2.polylines(img, [np.array([px(x, y) for x, y in zip(r.x, r.y)], np.int32)], False, pale, 9)
        if name in ours:
            o = ours[name]
            cv2.polylines(img, [np.array([px(x, y) for x, y in zip(o.x, o.y)], np.int32)], False, c, 2)
            for t, x, y in zip(o.t, o.x, o.y):
                if abs(t / 2.0 - round(t / 2.0)) < 1e-6:
                    cv2.circle(img, px(x, y), 4, c, -1)
        cv2.putText(img, name, (MARGIN, 25 + 22 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.6, c, 2)
    cv2.putText(img, "pale: esmini   line and dots (every 2 s): Convoy", (MARGIN, h - 12),
                cv2.FONT_HERSHEY_SIMPLEX, 0.5, (80, 80, 80), 1)
    cv2.imwrite(a.out, img)
    print(a.out)


if __name__ == "__main__":
    main()
