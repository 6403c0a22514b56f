"""Camera + LiDAR fusion for the ego planner (issue 27, part 4: "an ego that drives on its
sensors"): the detector's boxes (pixels of the camera image) ranged by the LiDAR's returns.

    rig = Rig.smart_car_lidar()                 # or Rig(camera=Camera(...), lidar_pose=...)
    objs = fuse(rig, detections, xyz, depth=None)
    objs = tracker.update(objs, t, ego_speed)   # convoy_traffic.ego_planner.Tracker

Frames: the ego's frame is the ego model's (x forward, y left, z up, origin on the ground
below base_link, as the ground-truth objects of objects_from_road_users); the camera and the
LiDAR are placed in it by their mounting poses (x, y, z, roll, pitch, yaw as SDF, the
rotation Rz(yaw) Ry(pitch) Rx(roll)). The camera is a pinhole (square pixels) looking along
its x axis, image u to the right (-y), v down (-z), focal (width / 2) / tan(hfov / 2).

For each box: the LiDAR points (ground removed: ego z below `ground_z`; weather returns, flag
1, removed) whose projection falls in the box; with at least `min_points` of them, the
object's near face is the `percentile` of their forward distances (ego x; a box also holds
background), its lateral position that of the box's centre ray at that distance, its width
the box's at that distance. With fewer points it falls back to the camera's depth image
(objects_from_detections) when one is given, else the box gives no object; a fallback closer
than `confirm_range` (m along the camera's axis; 2 by default) is dropped as a phantom (in
night rain Convoy's detector sees a bus on the lens, ranged by the depth image at 0.5 m: the
ego never started; 15 m also drops walkers the LiDAR's 16 beams catch too few points of). Objects are labelled
source "sensors"; velocities are 0 (the Tracker estimates them)."""

import math

import numpy as np

from convoy_traffic.ego_planner import COCO_TO_CLASS, objects_from_detections

SOURCE = "sensors"
SMALL_CLASSES = ("pedestrian", "cyclist")


def rotation(roll, pitch, yaw):
    """The SDF pose's rotation matrix Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def compose(*poses):
    """(R, t) of poses (x, y, z, roll, pitch, yaw) chained parent to child."""
    R, t = np.eye(3), np.zeros(3)
    for p in poses:
        Rp = rotation(*p[3:6])
        t = t + R @ np.asarray(p[:3], float)
        R = R @ Rp
    return R, t


class Camera:
    """A pinhole camera: image size, horizontal fov (rad) and its pose in the ego's frame."""

    def __init__(self, width, height, hfov, pose=(0, 0, 0, 0, 0, 0), poses=None):
        if width <= 0 or height <= 0 or not 0 < hfov < math.pi:
            raise ValueError("camera: width %r, height %r, hfov %r: need positive sizes and "
                             "0 < hfov < pi" % (width, height, hfov))
        self.width, self.height, self.hfov = int(width), int(height), float(hfov)
        self.f = (self.width / 2.0) / math.tan(self.hfov / 2.0)
        self.R, self.t = compose(*(poses or [pose]))

    def project(self, pts):
        """Ego-frame points (N x 3) -> (u, v, forward distance along the optical axis)."""
        pc = (np.asarray(pts, float) - self.t) @ self.R   # R^T (p - t), row-wise
        x = pc[:, 0]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.width / 2.0 - self.f * pc[:, 1] / x
            v = self.height / 2.0 - self.f * pc[:, 2] / x
        return u, v, x


class Rig:
    """The camera and the LiDAR's pose (x, y, z, roll, pitch, yaw, or a chain of them) in the
    ego's frame, and the fusion's parameters."""

    def __init__(self, camera, lidar_pose=(0, 0, 0, 0, 0, 0), lidar_poses=None, ground_z=0.3,
                 percentile=10.0, min_points=3, min_forward=0.5, confirm_range=2.0):
        self.camera = camera
        self.lidar_R, self.lidar_t = compose(*(lidar_poses or [lidar_pose]))
        self.ground_z, self.percentile = float(ground_z), float(percentile)
        self.min_points, self.min_forward = int(min_points), float(min_forward)
        self.confirm_range = float(confirm_range)

    @classmethod
    def smart_car_lidar(cls, **kw):
        """The smart car with a roof LiDAR (experiments/autonomous_driving/models/
        smart_car_lidar/model.sdf): camera link (0.7, 0, 1.0, pitch 0.25), its sensor (0, 0,
        0.132, pitch -0.174), 736 x 480, hfov 1.57; base_link (0, 0, 0.6), the LiDAR on it at
        (0, 0, 1.3)."""
        cam = Camera(736, 480, 1.57, poses=[(0.7, 0, 1.0, 0, 0.25, 0), (0, 0, 0.132, 0, -0.174, 0)])
        return cls(cam, lidar_poses=[(0, 0, 0.6, 0, 0, 0), (0, 0, 1.3, 0, 0, 0)], **kw)

    def to_ego(self, xyz):
        """LiDAR-frame points (N x 3) in the ego's frame."""
        return np.asarray(xyz, float) @ self.lidar_R.T + self.lidar_t

    def camera_range_points(self, xyz, flags=None):
        """The non-ground points in front of the camera: (u, v, ego x, camera forward)."""
        p = self.to_ego(xyz)
        keep = p[:, 2] > self.ground_z
        if flags is not None:
            keep &= np.asarray(flags) == 0
        p = p[keep]
        u, v, fwd = self.camera.project(p)
        ok = (fwd > self.min_forward) & np.isfinite(u) & np.isfinite(v)
        return u[ok], v[ok], p[ok, 0], fwd[ok]


def _class(d):
    c = str(d.get("class", "unknown"))
    return COCO_TO_CLASS.get(c, c)


def fuse(rig, detections, xyz, flags=None, depth=None):
    """Objects in the ego's frame (module docstring) from the detector's boxes (dicts with
    x_min, y_min, x_max, y_max in pixels and class), the LiDAR's points (N x 3, its frame;
    None: none) and optionally its flags and the camera's depth image (height x width, metres
    along the optical axis)."""
    cam = rig.camera
    if xyz is not None and len(xyz):
        u, v, ex, _ = rig.camera_range_points(xyz, flags)
    else:
        u = v = ex = np.zeros(0)
    out = []
    for i, d in enumerate(detections):
        x0, x1 = float(d["x_min"]), float(d["x_max"])
        y0, y1 = float(d["y_min"]), float(d["y_max"])
        if x1 <= x0 or y1 <= y0:
            continue
        inside = (u >= x0) & (u <= x1) & (v >= y0) & (v <= y1)
        cls = _class(d)
        length = 0.5 if cls in SMALL_CLASSES else 1.0
        if np.count_nonzero(inside) < rig.min_points:
            if depth is not None:
                for o in objects_from_detections([d], depth, cam.width, cam.height, cam.hfov,
                                                 cam_x=float(cam.t[0]), cam_y=float(cam.t[1])):
                    near = o["lon"] - o["length"] / 2.0 - float(cam.t[0])
                    ranged = "depth" if near >= rig.confirm_range else "rejected"
                    out.append(dict(o, id="%s#%d" % (cls, i), source=SOURCE, ranged_by=ranged))
            continue
        near = float(np.percentile(ex[inside], rig.percentile))
        z = max(near - float(cam.t[0]), rig.min_forward)  # along the camera's axis
        uc = (x0 + x1) / 2.0
        lat = float(cam.t[1]) - (uc - cam.width / 2.0) / cam.f * z
        w = (x1 - x0) / cam.f * z
        out.append({"id": "%s#%d" % (cls, i), "class": cls, "lon": near + length / 2.0,
                    "lat": lat, "length": length, "width": w, "v_lon": 0.0, "v_lat": 0.0,
                    "source": SOURCE, "ranged_by": "lidar", "points": int(np.count_nonzero(inside))})
    return out


def lidar_obstacles(rig, xyz, flags=None, objects=(), corridor=2.0, max_range=25.0, cell=0.5,
                    min_points=5, top_z=2.5):
    """What the LiDAR sees in the ego's way that no box explains: its non-ground points (ego z
    in (ground_z, top_z); weather returns removed) ahead of the ego within `max_range` m and
    `corridor` m of its axis, clustered on a `cell` m grid (cells touching, diagonals too);
    a cluster of at least `min_points` points that is not within 2 m of one of `objects` is an
    object at its nearest point, classed by its size (narrower than 1.2 m: pedestrian, else
    car: the planner reacts to road users only), source "sensors", ranged_by "lidar_only".
    The ground is taken as flat (ego z = 0)."""
    if xyz is None or not len(xyz):
        return []
    p = rig.to_ego(xyz)
    keep = (p[:, 2] > rig.ground_z) & (p[:, 2] < top_z) & (p[:, 0] > 1.0) & (p[:, 0] < max_range) \
        & (np.abs(p[:, 1]) < corridor)
    if flags is not None:
        keep &= np.asarray(flags) == 0
    p = p[keep]
    if len(p) < min_points:
        return []
    cells = {}
    for k, key in enumerate(map(tuple, np.floor(p[:, :2] / cell).astype(int))):
        cells.setdefault(key, []).append(k)
    seen, out = set(), []
    for start in cells:
        if start in seen:
            continue
        seen.add(start)
        todo, members = [start], []
        while todo:
            c = todo.pop()
            members += cells[c]
            for dx in (-1, 0, 1):
                for dy in (-1, 0, 1):
                    n = (c[0] + dx, c[1] + dy)
                    if n in cells and n not in seen:
                        seen.add(n)
                        todo.append(n)
        if len(members) < min_points:
            continue
        q = p[members]
        near = float(q[:, 0].min())
        lat = float((q[:, 1].min() + q[:, 1].max()) / 2.0)
        width = float(q[:, 1].max() - q[:, 1].min()) + 0.1
        if any(abs(o["lon"] - o["length"] / 2.0 - near) < 2.0 and abs(o["lat"] - lat) < 2.0
               for o in objects):
            continue
        cls = "pedestrian" if width < 1.2 else "car"
        length = 0.5 if cls == "pedestrian" else 1.0
        out.append({"id": "lidar#%d" % len(out), "class": cls, "lon": near + length / 2.0, "lat": lat,
                    "length": length, "width": width, "v_lon": 0.0, "v_lat": 0.0, "source": SOURCE,
                    "ranged_by": "lidar_only", "points": len(members)})
    return out


def accepted(objects):
    """The objects fuse() kept (not those the LiDAR rejected)."""
    return [o for o in objects if o.get("ranged_by") != "rejected"]
