"""Camera objects confirmed by range and over frames before they may brake the ego (issue 27:
phantom braking on the Parkring lap came from single frames of false boxes, "bus" or
"truck" on a tree crown, ranged by the crown's LiDAR returns).

    confirmer = Confirmer()
    objs = confirmer.update(objects, t, ego, boxes)   # boxes: Surround.boxes_now(ego)

`objects` are the fused camera objects (convoy_traffic.fusion.fuse, tracked), and the LiDAR
obstacles no box explains (ranged_by "lidar_only"), in the ego's frame at `ego` (dict x, y, yaw,
the ego's pose when the camera frame was taken);
`boxes` the last LiDAR scan's clusters in that frame with their class
(convoy_sensors.clusters.segment_all: "car", "truck", "obstacle", or scenery: "static",
"overhead", "vegetation"). For each object, the clusters under its near face (at lon - length / 2,
from lat - width / 2 to lat + width / 2: a box's centre ray may place a roadside tree half a
metre off its cluster; boxes grown by `margin` m) decide:

- a road-user cluster there (for a vehicle box a car or truck cluster, for a walker, a cyclist
  or a LiDAR-only obstacle also an "obstacle" one): "lidar" support, the object passes at once;
- else a scenery cluster there: the LiDAR sees a tree, a hedge or a wall where the box is. A
  vehicle box (car, truck, bus) or a LiDAR-only obstacle is dropped ("scenery"); a walker or a
  cyclist (whose few returns merge with a trunk or a hedge they stand by) needs `frames`
  frames like an unsupported object;
- else (no cluster: beyond the LiDAR's reach, too few returns, ranged by the depth image) the
  object passes once it has been seen in `frames` consecutive camera frames (any class: the
  detector's class may flicker) within `gate` m of where it was, in the world frame.

Each object passed gets "confirmed_by": "lidar", "frames"; update() also keeps the last
frame's decisions (self.last: id -> reason, "scenery" and "unconfirmed" included) for the
run's counts.

Velocity: the tracker's (ego_planner.Tracker: a filtered difference of the box's positions)
jumps when a box takes in a neighbour or loses part of its object for a frame: a parked car
beside the road then seemed to cross at 3-5 m/s, a standing walker at 1 m/s, and the planner
braked for their predicted entry. Each object keeps its streak's last `history` world
positions; their robust rate (Theil-Sen: the median of the pairwise slopes) and the
tracker's velocity, in the ego's axes, are each kept where they agree in sign (the smaller
in magnitude), else 0. With fewer than `velocity_frames` positions the lateral velocity is 0
(a new object is taken as standing, as the tracker does)."""

import math

ROAD_USER_CLUSTERS = ("car", "truck", "obstacle")
VEHICLE_CLUSTERS = ("car", "truck")
SCENERY_CLUSTERS = ("static", "overhead", "vegetation")
VEHICLES = ("car", "truck", "bus")


def clusters_at(boxes, lon, lat0, lat1, margin):
    """The classes of the boxes overlapping the segment from (lon, lat0) to (lon, lat1), each
    box grown by margin m."""
    return [b["class"] for b in boxes
            if b["x0"] - margin <= lon <= b["x1"] + margin and b["y0"] - margin <= lat1 and lat0 <= b["y1"] + margin]


def support(obj, boxes, margin=0.3):
    """"lidar", "scenery" or None: what the LiDAR's clusters say at the object's near face.
    A vehicle box needs a vehicle-sized cluster (a post or a sign is no bus); a walker's, a
    cyclist's or a LiDAR-only obstacle's any road-user cluster."""
    near = obj["lon"] - obj.get("length", 0.0) / 2.0
    half = obj.get("width", 0.0) / 2.0
    classes = clusters_at(boxes, near, obj["lat"] - half, obj["lat"] + half, margin)
    wanted = VEHICLE_CLUSTERS if obj.get("class") in VEHICLES else ROAD_USER_CLUSTERS
    if any(c in wanted for c in classes):
        return "lidar"
    if any(c in SCENERY_CLUSTERS for c in classes) and not any(c in ROAD_USER_CLUSTERS for c in classes):
        return "scenery"
    return None


def decide(obj, why, streak, frames):
    """The object's reason: "lidar", "scenery" (dropped), "frames" or "unconfirmed" (held)."""
    if why == "lidar":
        return "lidar"
    if why == "scenery" and (obj.get("class") in VEHICLES or obj.get("ranged_by") == "lidar_only"):
        return "scenery"
    return "frames" if streak >= frames else "unconfirmed"


def theil_sen(ts, vs):
    """The median of the pairwise slopes of vs over ts (a robust rate: one jump among the
    points, a box taking in its neighbour for a frame, moves it little)."""
    slopes = sorted((vs[j] - vs[i]) / (ts[j] - ts[i]) for i in range(len(ts)) for j in range(i + 1, len(ts))
                    if ts[j] - ts[i] > 1e-6)
    if not slopes:
        return 0.0
    m = len(slopes) // 2
    return slopes[m] if len(slopes) % 2 else 0.5 * (slopes[m - 1] + slopes[m])


def agreed(a, b):
    """The smaller in magnitude of two estimates of a velocity when they agree in sign, else 0."""
    if a * b <= 0.0:
        return 0.0
    return a if abs(a) < abs(b) else b


class Confirmer:
    def __init__(self, frames=3, gate=2.5, margin=0.3, history=10, velocity_frames=4):
        self.frames, self.gate, self.margin = int(frames), float(gate), float(margin)
        self.history, self.velocity_frames = int(history), int(velocity_frames)
        self.seen = []   # [(world x, y, consecutive frames, [(t, x, y)...])] of the last frame's objects
        self.last = {}

    def _streak(self, wx, wy, previous, used):
        """The nearest unused previous position within the gate: (its streak, its history)."""
        best, best_d = None, self.gate
        for k, prev in enumerate(previous):
            d = math.hypot(wx - prev[0], wy - prev[1])
            if k not in used and d < best_d:
                best, best_d = k, d
        if best is None:
            return 0, []
        used.add(best)
        return previous[best][2], previous[best][3]

    def _velocity(self, o, hist, ego):
        """The object with the velocity its track's world positions and the tracker agree on
        (module docstring)."""
        if len(hist) < self.velocity_frames:
            return dict(o, v_lat=0.0)
        ts = [h[0] for h in hist]
        vx, vy = theil_sen(ts, [h[1] for h in hist]), theil_sen(ts, [h[2] for h in hist])
        c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        v_lon, v_lat = c * vx + s * vy, -s * vx + c * vy
        return dict(o, v_lon=agreed(o.get("v_lon", 0.0), v_lon), v_lat=agreed(o.get("v_lat", 0.0), v_lat))

    def update(self, objects, t, ego, boxes):
        """The objects that may reach the planner (module docstring), in their order."""
        c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        previous, used, seen = self.seen, set(), []
        reasons, out = [None] * len(objects), [None] * len(objects)
        order = sorted(range(len(objects)), key=lambda k: (objects[k]["lon"], objects[k]["lat"]))
        for k in order:   # the nearest first: it takes the nearest previous position
            o = objects[k]
            wx = ego["x"] + c * o["lon"] - s * o["lat"]
            wy = ego["y"] + s * o["lon"] + c * o["lat"]
            n, hist = self._streak(wx, wy, previous, used)
            hist = (hist + [(t, wx, wy)])[-self.history:]
            seen.append((wx, wy, n + 1, hist))
            reasons[k] = decide(o, support(o, boxes, self.margin), n + 1, self.frames)
            out[k] = self._velocity(dict(o, confirmed_by=reasons[k]), hist, ego)
        self.seen = seen
        self.last = {o.get("id"): r for o, r in zip(objects, reasons)}
        return [o for o, r in zip(out, reasons) if r in ("lidar", "frames")]
