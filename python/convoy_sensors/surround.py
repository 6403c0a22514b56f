"""The roof LiDAR's objects all around the ego, for the planner with sensor perception
(python/convoy_scenario/perception_tf.py; docs/scenarios.md, "Perception: ground truth or
sensors").

    surround = Surround(rig, ego_length, ego_width, ego_offset)   # rig: convoy_traffic.fusion.Rig
    surround.scan(xyz, flags, t_scan, ego)   # at each new scan: cluster (clusters.segment), track
    objs = surround.objects(ego, camera_objects)

The camera's objects (its boxes ranged by the LiDAR, convoy_traffic.fusion) stay the objects in
its view; surround adds the tracked LiDAR clusters (convoy_sensors.cluster_tracker) that are
not wholly inside the camera's view (a box corner outside the image or behind the camera) and
that no camera object explains (its centre within `match` m of the box). A track slower than
MOVING_SPEED, or seen fewer than MOVING_HITS times, stands (velocity 0: the box of a standing
thing changes shape as the ego drives by, which reads as motion) and is left out when it is
ahead of the ego's front; a moving one is left out beyond AHEAD_M m ahead of it. Roadside trees,
hedges and walls, which a 16-beam cluster cannot tell from a truck, would otherwise become leads
on bends (phantom braking on the Parkring lap); what is ahead is the camera's. They come in the
form of the ground-truth objects (ego_planner.objects_from_road_users): ego frame at the ego's
pose now, extents along and across its axes, absolute velocity, source "sensors", ranged_by
"lidar_surround", class "car" / "truck" (vehicles) or "obstacle" (not a road user for the
planner).

refine() also gives the camera's vehicles the lateral extent of the LiDAR cluster they lie in:
a box's centre ray places a car seen at an angle (its rear and its side) or cut by the image's
edge too close to the ego's path, and as wide as its rear and side together; the cluster's
points place its sides to a few centimetres."""

import math

import numpy as np

from convoy_sensors.cluster_tracker import ClusterTracker
from convoy_sensors.clusters import STATIC_CLASSES, segment_all

SOURCE = "sensors"
RANGED_BY = "lidar_surround"
CORNER_Z = 0.8  # m: the height at which a box's corners are tested against the camera's view
VEHICLE_CLASSES = ("car", "truck", "bus")
MOVING_SPEED = 2.0  # m/s: a slower track is standing (its velocity reported as 0) ...
MOVING_HITS = 5     # ... and so is one seen fewer times (its velocity is not settled)
AHEAD_M = 5.0       # m: a moving track further ahead of the ego's front than this is left out
REFINE_LON = 1.5  # m: a camera object's near face within this of a cluster's extent along x ...
REFINE_LAT = 1.5  # m: ... and its centre within this of its extent across (the box cut by the
#                   image's edge puts it that far off): it is that cluster, the nearest across first


class Surround:
    def __init__(self, rig, ego_length=0.0, ego_width=0.0, ego_offset=0.0, match=1.0,
                 column_step=2 * math.pi / 1024, **segment_kw):
        """column_step: the LiDAR's horizontal step (rad; the smart car's: 1024 columns)."""
        self.rig, self.match, self.column_step = rig, float(match), float(column_step)
        self.segment_kw = dict(segment_kw, ego_length=ego_length, ego_width=ego_width, ego_offset=ego_offset)
        self.tracker = ClusterTracker()
        self.t = None
        self.boxes = []      # the last scan's clusters other than scenery (tracked)
        self.all_boxes = []  # all of them, scenery (clusters.STATIC_CLASSES) too
        self.scan_ego = None

    def scan(self, xyz, flags, t, ego, intensity=None):
        """A new scan (N x 3, the LiDAR's frame; its flags and intensities or None) taken at
        t s, the ego at `ego` (dict x, y, yaw)."""
        pts = self.rig.to_ego(xyz) if xyz is not None and len(xyz) else np.zeros((0, 3))
        self.all_boxes = segment_all(pts, flags, intensity, **self.segment_kw)
        self.boxes = [b for b in self.all_boxes if b["class"] not in STATIC_CLASSES]
        self.t = t
        self.scan_ego = dict(ego)
        self.tracker.update(self.boxes, t, ego)

    def boxes_now(self, ego):
        """The last scan's boxes (all of them) moved into the ego's frame at `ego` (the ego
        drives on between the scan and a camera frame): their extents kept, centres moved."""
        if self.scan_ego is None:
            return []
        s0, c0 = math.sin(self.scan_ego["yaw"]), math.cos(self.scan_ego["yaw"])
        c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        out = []
        for b in self.all_boxes:
            bx, by = (b["x0"] + b["x1"]) / 2.0, (b["y0"] + b["y1"]) / 2.0
            wx = self.scan_ego["x"] + c0 * bx - s0 * by - ego["x"]
            wy = self.scan_ego["y"] + s0 * bx + c0 * by - ego["y"]
            nx, ny = c * wx + s * wy, -s * wx + c * wy
            out.append(dict(b, x0=b["x0"] + nx - bx, x1=b["x1"] + nx - bx,
                            y0=b["y0"] + ny - by, y1=b["y1"] + ny - by))
        return out

    def refine(self, objects):
        """The camera's objects (convoy_traffic.fusion.fuse), vehicles placed across the ego's
        axis by the LiDAR cluster (of the last scan) they lie in (module docstring): lat and
        width from the cluster's points, "lat_by": "lidar_cluster"."""
        out = []
        for o in objects:
            if o.get("class") not in VEHICLE_CLASSES or o.get("ranged_by") == "rejected":
                out.append(o)
                continue
            near = o["lon"] - o["length"] / 2.0
            best = None
            for b in self.boxes:
                if not (b["x0"] - REFINE_LON <= near <= b["x1"] + REFINE_LON
                        and b["y0"] - REFINE_LAT <= o["lat"] <= b["y1"] + REFINE_LAT):
                    continue
                across = max(b["y0"] - o["lat"], o["lat"] - b["y1"], 0.0)
                key = (across, abs(b["x0"] - near), b["x0"], b["y0"])
                if best is None or key < best[0]:
                    best = (key, b)
            if best is None:
                out.append(o)
                continue
            b = best[1]
            pad = math.hypot(near, o["lat"]) * self.column_step  # half a column's step each side
            # the grown box (clusters.grow): a car seen from beside shows its side only
            out.append(dict(o, lat=(b["y0"] + b["y1"]) / 2.0, width=b["y1"] - b["y0"] + pad,
                            lat_by="lidar_cluster"))
        return out

    def in_view(self, lon0, lon1, lat0, lat1):
        """True when the box's four corners (at CORNER_Z) are all in the camera's image."""
        cam = self.rig.camera
        corners = np.array([[x, y, CORNER_Z] for x in (lon0, lon1) for y in (lat0, lat1)])
        u, _, fwd = cam.project(corners)
        return bool(np.all((fwd > self.rig.min_forward) & (u >= 0) & (u <= cam.width)))

    def objects(self, ego, camera_objects=()):
        """The surround objects (module docstring) in the ego's frame at `ego` now."""
        if self.t is None:
            return []
        c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
        front = ego.get("length_offset", 0.0) + ego.get("length", 0.0) / 2.0
        out = []
        for tr in self.tracker.confirmed(self.t):
            dx, dy = tr["x"] - ego["x"], tr["y"] - ego["y"]
            lon, lat = c * dx + s * dy, -s * dx + c * dy
            hl, hw = tr["length"] / 2.0, tr["width"] / 2.0
            vx, vy = tr["vx"], tr["vy"]
            if tr["hits"] < MOVING_HITS or math.hypot(vx, vy) < MOVING_SPEED:
                if lon - hl > front:
                    continue   # standing and ahead: the camera's (module docstring)
                vx = vy = 0.0
            elif lon - hl > front + AHEAD_M:
                continue
            if self.in_view(lon - hl, lon + hl, lat - hw, lat + hw):
                continue
            m = self.match
            if any(lon - hl - m <= o["lon"] <= lon + hl + m and lat - hw - m <= o["lat"] <= lat + hw + m
                   for o in camera_objects):
                continue
            out.append({"id": tr["id"], "class": tr["class"], "lon": lon, "lat": lat,
                        "length": tr["length"], "width": tr["width"],
                        "v_lon": c * vx + s * vy, "v_lat": -s * vx + c * vy,
                        "source": SOURCE, "ranged_by": RANGED_BY, "points": tr["points"]})
        return out
