"""Objects from a LiDAR scan all around the ego (issue 27, item 4: the planner's lane changes
need what is behind and beside the ego, which the camera does not see).

    pts = rig.to_ego(xyz)                          # the scan in the ego's frame (convoy_traffic.fusion)
    boxes = segment(pts, flags, ego_length=2.7, ego_width=1.6, ego_offset=0.0)
    for b in boxes: b["class"]                     # "car", "truck", "obstacle" (classify)

Frames as convoy_traffic.fusion: the ego's (x forward, y left, z up from the ground below it).
Only what the sensor measures is used: geometry and the returns' intensity (never the points'
ground-truth instance or label).

- points: weather returns (flag 1) dropped; ground removed as in fusion (ego z <= `ground_z`,
  the ground taken as flat), and what is above `top_z`, beyond `max_range` m (horizontally) or
  inside the ego's own footprint (its box plus `self_margin` m; the roof LiDAR's own mounts);
- clusters: the points' cells on a `cell` m grid in x, y, cells touching (diagonals too) are one
  cluster; clusters with fewer than `min_points` points are dropped;
- a box per cluster: its extent in the ego's axes (x0, x1, y0, y1), its top z, its point count;
  the clusters are made of the returns below `top_z`, but returns above STATIC_HEIGHT (up to
  TALL_Z) in one of a cluster's grid cells mark it "tall" (a house's façade, a big tree:
  points above top_z were cut, so they looked like a truck);
- class (classify) from size and shape: longer than STATIC_LENGTH m (a wall, a hedge, a row of
  parked cars merged), or at least VEHICLE_EXTENT m long and taller than STATIC_HEIGHT (or "tall"),
  or narrower than that and taller than POST_HEIGHT (a post, a sign, a trunk): "static" (a
  walker under a crown stays an obstacle); every return higher than OVERHEAD_Z m, nearer
  than OVERHEAD_RANGE m: "overhead" (a crown or a sign over the road: the ego passes under
  it); a tree's trunk under its crown, or returns as dim as leaves and no glass
  (convoy_sensors.shape): "vegetation"; a footprint of at least VEHICLE_EXTENT m one way and at least VEHICLE_HEIGHT m high: a vehicle, "truck" when longer
  than TRUCK_LENGTH m or taller than TRUCK_HEIGHT m, else "car"; anything smaller: "obstacle"
  (posts, walkers, bins: the planner's road-user classes leave it out; the camera classes
  walkers in front);
- vehicle boxes are grown to a vehicle's least size (VEHICLE_MIN_LENGTH x VEHICLE_MIN_WIDTH) on
  the side away from the sensor: a car behind shows its front only, its length is behind that.
"""

import numpy as np

from convoy_sensors import shape

STATIC_CLASSES = ("static", "overhead", "vegetation")   # scenery: not tracked

STATIC_LENGTH = 15.0        # m
STATIC_HEIGHT = 4.5         # m
OVERHEAD_Z = 2.2            # m: the smart car is 1.6 m high
OVERHEAD_RANGE = 20.0       # m: beyond, the beams are over 0.7 m apart (2 degrees): a truck's bed
#                             at 42 m showed only its top, between the beams under and over it
TALL_Z = 15.0               # m: returns up to this high count for a cluster's height
POST_HEIGHT = 2.5           # m: narrower than a vehicle and taller than this: a post, no walker
VEHICLE_EXTENT = 1.0        # m: a footprint this long one way may be a vehicle ...
VEHICLE_HEIGHT = 0.8        # m: ... when it reaches this high
TRUCK_LENGTH = 7.0          # m
TRUCK_HEIGHT = 2.6          # m
VEHICLE_MIN_LENGTH = 4.5    # m
VEHICLE_MIN_WIDTH = 1.7     # m


def keep_points(pts, flags=None, **kw):
    """The rows of `pts` (N x 3, ego frame) that may belong to objects (module docstring)."""
    pts = np.asarray(pts, float).reshape(-1, 3)
    return pts[keep_mask(pts, flags, **kw)]


def keep_mask(pts, flags=None, ground_z=0.3, top_z=4.0, max_range=50.0, ego_length=0.0,
              ego_width=0.0, ego_offset=0.0, self_margin=0.3):
    """keep_points' choice as a boolean mask of the rows of `pts`."""
    pts = np.asarray(pts, float).reshape(-1, 3)
    keep = (pts[:, 2] > ground_z) & (pts[:, 2] < top_z) & (np.hypot(pts[:, 0], pts[:, 1]) < max_range)
    if flags is not None:
        keep &= np.asarray(flags) == 0
    if ego_length > 0.0:
        inside = (np.abs(pts[:, 0] - ego_offset) < ego_length / 2.0 + self_margin) & \
                 (np.abs(pts[:, 1]) < max(ego_width, 0.0) / 2.0 + self_margin)
        keep &= ~inside
    return keep


def cluster_labels(xy, cell=0.5):
    """A cluster index per point (0..K-1, numbered in the order of the clusters' lowest grid
    cell, so the same points give the same labels) of 8-connected `cell` m grid cells."""
    xy = np.asarray(xy, float).reshape(-1, 2)
    if not len(xy):
        return np.zeros(0, int)
    keys = np.floor(xy / cell).astype(np.int64)
    cells, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = np.asarray(inverse).reshape(-1)
    index = {tuple(c): i for i, c in enumerate(cells.tolist())}
    comp = [-1] * len(cells)
    k = 0
    for i, c in enumerate(cells.tolist()):   # sorted: deterministic numbering
        if comp[i] >= 0:
            continue
        comp[i] = k
        todo = [tuple(c)]
        while todo:
            cx, cy = todo.pop()
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    j = index.get((cx + dx, cy + dy))
                    if j is not None and comp[j] < 0:
                        comp[j] = k
                        todo.append((cx + dx, cy + dy))
        k += 1
    return np.asarray(comp, int)[inverse]


def near_range(box):
    """The box's nearest horizontal distance from the sensor (ego origin), m."""
    dx = max(box["x0"], -box["x1"], 0.0)
    dy = max(box["y0"], -box["y1"], 0.0)
    return float(np.hypot(dx, dy))


def classify(box, feats=None):
    """"static", "overhead", "vegetation", "truck", "car" or "obstacle" from a box's size and,
    when given, its features (convoy_sensors.shape.features; module docstring)."""
    dx, dy = box["x1"] - box["x0"], box["y1"] - box["y0"]
    long, top = max(dx, dy), box["z1"]
    if long > STATIC_LENGTH:
        return "static"
    if box.get("z0", 0.0) > OVERHEAD_Z and near_range(box) < OVERHEAD_RANGE:
        return "overhead"
    if long >= VEHICLE_EXTENT and (top > STATIC_HEIGHT or box.get("tall")):
        return "static"
    if long < VEHICLE_EXTENT and top > POST_HEIGHT:
        return "static"   # a post, a sign, a trunk: taller than a walker, narrower than a vehicle
    if feats is not None and long >= VEHICLE_EXTENT and shape.vegetation(feats):
        return "vegetation"   # (a walker-sized cluster stays an obstacle, whatever it reflects)
    if long >= VEHICLE_EXTENT and top >= VEHICLE_HEIGHT:
        return "truck" if long > TRUCK_LENGTH or top > TRUCK_HEIGHT else "car"
    return "obstacle"


def grow(box, min_length=VEHICLE_MIN_LENGTH, min_width=VEHICLE_MIN_WIDTH):
    """The box grown to min_length x min_width on the side away from the sensor (ego origin)."""
    b = dict(box)
    if b["x1"] - b["x0"] < min_length:
        if (b["x0"] + b["x1"]) / 2.0 < 0.0:
            b["x0"] = b["x1"] - min_length
        else:
            b["x1"] = b["x0"] + min_length
    if b["y1"] - b["y0"] < min_width:
        if (b["y0"] + b["y1"]) / 2.0 < 0.0:
            b["y0"] = b["y1"] - min_width
        else:
            b["y1"] = b["y0"] + min_width
    return b


def tall_cells(pts, flags=None, cell=0.5, top_z=4.0, max_range=50.0, **_):
    """The `cell` m grid cells (set of (i, j)) holding returns higher than STATIC_HEIGHT (and
    below TALL_Z): a house's wall, a tree's crown, no road vehicle (module docstring)."""
    high = (pts[:, 2] > STATIC_HEIGHT) & (pts[:, 2] < TALL_Z) & (np.hypot(pts[:, 0], pts[:, 1]) < max_range)
    if flags is not None:
        high &= np.asarray(flags) == 0
    return set(map(tuple, np.floor(pts[high, :2] / cell).astype(np.int64).tolist()))


def segment(pts, flags=None, intensity=None, cell=0.5, min_points=4, **keep_kw):
    """Boxes (dicts x0, x1, y0, y1, z0, z1, points, class, why) of the scan's clusters, the
    scenery's (STATIC_CLASSES) left out, vehicles grown (module docstring); in the order of
    cluster_labels. `intensity`: the returns' intensities (N), for the vegetation test."""
    return [b for b in segment_all(pts, flags, intensity, cell, min_points, **keep_kw)
            if b["class"] not in STATIC_CLASSES]


def segment_all(pts, flags=None, intensity=None, cell=0.5, min_points=4, **keep_kw):
    """segment()'s boxes, the scenery's too (its class one of STATIC_CLASSES)."""
    pts = np.asarray(pts, float).reshape(-1, 3)
    keep = keep_mask(pts, flags, **keep_kw)
    p = pts[keep]
    inten = None if intensity is None else np.asarray(intensity, float).reshape(-1)[keep]
    labels = cluster_labels(p[:, :2], cell)
    tall = tall_cells(pts, flags, cell, **keep_kw)
    out = []
    for k in range(int(labels.max()) + 1 if len(labels) else 0):
        sel = labels == k
        q = p[sel]
        if len(q) < min_points:
            continue
        box = {"x0": float(q[:, 0].min()), "x1": float(q[:, 0].max()),
               "y0": float(q[:, 1].min()), "y1": float(q[:, 1].max()),
               "z0": float(q[:, 2].min()), "z1": float(q[:, 2].max()), "points": int(len(q))}
        box["tall"] = bool(tall) and any(tuple(c) in tall for c in np.floor(q[:, :2] / cell).astype(np.int64).tolist())
        feats = shape.features(q, None if inten is None else inten[sel])
        box["class"] = classify(box, feats)
        box["why"] = shape.vegetation(feats) if box["class"] == "vegetation" else None
        if box["class"] in ("car", "truck"):
            box = grow(box)
        out.append(box)
    return out
