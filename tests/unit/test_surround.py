"""Unit tests of the roof LiDAR's objects all around the ego (python/convoy_sensors/clusters.py,
cluster_tracker.py, surround.py; issue 27 item 4: the planner changes lanes on its sensors).
Pure Python: synthetic scans of boxes, and a kinematic ego on a straight two-lane road."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from convoy_sensors import clusters  # noqa: E402
from convoy_sensors.cluster_tracker import ClusterTracker  # noqa: E402
from convoy_sensors.surround import Surround  # noqa: E402
from convoy_traffic import ego_planner as ep  # noqa: E402
from convoy_traffic import lane_change as lc  # noqa: E402
from convoy_traffic.fusion import Rig  # noqa: E402
from convoy_traffic.lanes import RouteLanes  # noqa: E402
from convoy_traffic.route_path import RoutePath  # noqa: E402

EGO = {"x": 0.0, "y": 0.0, "yaw": 0.0}


def box_points(x, y, length=4.5, width=1.8, height=1.4, eye=(0.0, 0.0), step=0.2):
    """Points on the faces of an axis-aligned box (world x, y its centre) that face `eye`."""
    x0, x1, y0, y1 = x - length / 2, x + length / 2, y - width / 2, y + width / 2
    pts = []
    zs = np.arange(0.4, height + 1e-9, 0.3)
    faces = []
    if eye[0] < x0:
        faces.append(((x0, y0), (x0, y1)))
    if eye[0] > x1:
        faces.append(((x1, y0), (x1, y1)))
    if eye[1] < y0:
        faces.append(((x0, y0), (x1, y0)))
    if eye[1] > y1:
        faces.append(((x0, y1), (x1, y1)))
    for (ax, ay), (bx, by) in faces:
        n = max(int(math.hypot(bx - ax, by - ay) / step), 1)
        for k in range(n + 1):
            u = k / n
            for z in zs:
                pts.append((ax + u * (bx - ax), ay + u * (by - ay), z))
    return pts


def scan_of(ego, users, rig, ground=True):
    """A synthetic scan (the LiDAR's frame) of world boxes `users` seen from the ego, with
    ground returns around it."""
    pts = []
    for u in users:
        pts += box_points(u["x"], u["y"], u.get("length", 4.5), u.get("width", 1.8),
                          u.get("height", 1.4), eye=(ego["x"], ego["y"]))
    c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
    w = np.asarray(pts, float).reshape(-1, 3)
    dx, dy = w[:, 0] - ego["x"], w[:, 1] - ego["y"]
    e = np.stack([c * dx + s * dy, -s * dx + c * dy, w[:, 2]], axis=1)
    if ground:
        g = np.array([(r * math.cos(a), r * math.sin(a), 0.05) for r in (8.0, 12.0, 20.0)
                      for a in np.linspace(-math.pi, math.pi, 90)])
        e = np.vstack([e, g])
    return (e - rig.lidar_t) @ rig.lidar_R   # ego frame -> the LiDAR's


class Segment(unittest.TestCase):
    def test_ground_weather_far_and_own_points_are_removed(self):
        pts = np.array([[10.0, 0.0, 0.1],    # ground
                        [10.0, 0.0, 1.0],    # kept
                        [10.0, 0.0, 5.0],    # above top_z
                        [80.0, 0.0, 1.0],    # beyond max_range
                        [0.5, 0.2, 1.5],     # on the ego itself
                        [10.0, 0.5, 1.0]])   # a weather return
        flags = np.array([0, 0, 0, 0, 0, 1])
        kept = clusters.keep_points(pts, flags, ego_length=2.7, ego_width=1.6)
        self.assertEqual(kept.tolist(), [[10.0, 0.0, 1.0]])

    def test_clusters_touching_cells_join_and_numbering_is_stable(self):
        xy = np.array([[0.1, 0.1], [0.6, 0.6], [1.1, 1.1],   # diagonal neighbours: one
                       [5.0, 5.0], [5.2, 5.1]])              # another
        a = clusters.cluster_labels(xy)
        self.assertEqual(a.tolist(), [0, 0, 0, 1, 1])
        b = clusters.cluster_labels(xy[::-1])
        self.assertEqual(b.tolist(), [1, 1, 0, 0, 0])

    def test_classes_by_size(self):
        def box(dx, dy, top):
            return {"x0": 0.0, "x1": dx, "y0": 0.0, "y1": dy, "z1": top}
        self.assertEqual(clusters.classify(box(4.4, 1.8, 1.5)), "car")
        self.assertEqual(clusters.classify(box(0.2, 1.8, 1.2)), "car")     # a car's rear
        self.assertEqual(clusters.classify(box(11.0, 2.5, 3.1)), "truck")
        self.assertEqual(clusters.classify(box(0.5, 0.5, 1.8)), "obstacle")  # a walker, a post
        self.assertEqual(clusters.classify(box(2.0, 1.5, 0.5)), "obstacle")  # low: a kerb stone
        self.assertEqual(clusters.classify(box(30.0, 0.5, 2.0)), "static")   # a wall

    def test_a_car_behind_grows_backwards_ahead_forwards(self):
        behind = clusters.grow({"x0": -10.2, "x1": -10.0, "y0": -0.9, "y1": 0.9})
        self.assertAlmostEqual(behind["x1"], -10.0)
        self.assertAlmostEqual(behind["x0"], -10.0 - clusters.VEHICLE_MIN_LENGTH)
        ahead = clusters.grow({"x0": 10.0, "x1": 10.1, "y0": 2.6, "y1": 3.5})
        self.assertAlmostEqual(ahead["x0"], 10.0)
        self.assertAlmostEqual(ahead["x1"], 10.0 + clusters.VEHICLE_MIN_LENGTH)
        self.assertAlmostEqual(ahead["y0"], 2.6)   # away from the ego: to the left
        self.assertAlmostEqual(ahead["y1"], 2.6 + clusters.VEHICLE_MIN_WIDTH)

    def test_segment_finds_cars_around_the_ego(self):
        rig = Rig.smart_car_lidar()
        users = [{"x": -15.0, "y": -3.5}, {"x": 0.5, "y": 3.5}, {"x": 20.0, "y": 0.0}]
        boxes = clusters.segment(rig.to_ego(scan_of(EGO, users, rig)), ego_length=2.7, ego_width=1.6)
        self.assertEqual(len(boxes), 3, boxes)
        self.assertEqual([b["class"] for b in boxes], ["car"] * 3)
        got = sorted(((b["x0"] + b["x1"]) / 2, (b["y0"] + b["y1"]) / 2) for b in boxes)
        for (gx, gy), u in zip(got, sorted(users, key=lambda u: u["x"])):
            self.assertLess(abs(gx - u["x"]), 0.3, got)
            self.assertLess(abs(gy - u["y"]), 0.3, got)


class Tracking(unittest.TestCase):
    def boxes_at(self, cx, cy, length=4.5):
        return [{"x0": cx - length / 2, "x1": cx + length / 2, "y0": cy - 0.9, "y1": cy + 0.9,
                 "z1": 1.4, "points": 50, "class": "car"}]

    def test_velocity_of_a_passing_car_with_the_ego_moving(self):
        tr = ClusterTracker()
        for k in range(20):
            t = 0.1 * k
            ego = {"x": 5.0 * t, "y": 0.0, "yaw": 0.0}
            car_x = -20.0 + 12.0 * t   # world
            out = tr.update(self.boxes_at(car_x - ego["x"], -3.5), t, ego)
        self.assertEqual(len(out), 1)
        self.assertEqual(out[0]["id"], "lidar0")
        self.assertAlmostEqual(out[0]["vx"], 12.0, places=2)
        self.assertAlmostEqual(out[0]["vy"], 0.0, places=3)

    def test_confirmed_after_two_hits_coasts_then_dropped(self):
        tr = ClusterTracker(coast=2)
        self.assertEqual(tr.update(self.boxes_at(10.0, 0.0), 0.0, EGO), [])
        self.assertEqual(len(tr.update(self.boxes_at(10.0, 0.0), 0.1, EGO)), 1)
        self.assertEqual(len(tr.update([], 0.2, EGO)), 1)
        self.assertEqual(len(tr.update([], 0.3, EGO)), 1)
        self.assertEqual(tr.update([], 0.4, EGO), [])

    def test_two_cars_keep_their_ids(self):
        tr = ClusterTracker()
        for k in range(10):
            t = 0.1 * k
            boxes = self.boxes_at(-10.0 + 10.0 * t, -3.5) + self.boxes_at(15.0, 0.0)
            out = tr.update(boxes, t, EGO)
        by_id = {o["id"]: o for o in out}
        self.assertLess(abs(by_id["lidar0"]["vx"] - 10.0), 0.2)
        self.assertAlmostEqual(by_id["lidar1"]["vx"], 0.0, places=3)

    def test_a_vehicle_stays_a_vehicle(self):
        tr = ClusterTracker()
        tr.update(self.boxes_at(10.0, 0.0), 0.0, EGO)
        tr.update(self.boxes_at(10.0, 0.0), 0.1, EGO)
        small = [dict(self.boxes_at(10.0, 0.0)[0], **{"class": "obstacle"})]
        out = tr.update(small, 0.2, EGO)
        self.assertEqual(out[0]["class"], "car")


class SurroundObjects(unittest.TestCase):
    def run_scans(self, users, seconds=1.0, camera=()):
        rig = Rig.smart_car_lidar()
        sur = Surround(rig, 2.7, 1.6, 0.0)
        t = 0.0
        while t < seconds:
            sur.scan(scan_of(EGO, users, rig), None, t, EGO)
            for u in users:
                u["x"] += u.get("vx", 0.0) * 0.1
            t += 0.1
        return sur, sur.objects(EGO, list(camera))

    def test_a_car_behind_in_the_next_lane_with_its_speed(self):
        _, objs = self.run_scans([{"x": -25.0, "y": -3.5, "vx": 8.0}])
        self.assertEqual(len(objs), 1, objs)
        o = objs[0]
        self.assertEqual((o["class"], o["source"], o["ranged_by"]), ("car", "sensors", "lidar_surround"))
        self.assertLess(abs(o["lat"] + 3.5), 0.3)
        self.assertLess(abs(o["v_lon"] - 8.0), 0.5)
        self.assertLess(abs(o["v_lat"]), 0.3)
        self.assertGreaterEqual(o["length"], clusters.VEHICLE_MIN_LENGTH - 1e-9)
        for k in ("id", "lon", "width"):
            self.assertIn(k, o)

    def test_a_car_wholly_in_the_camera_view_is_left_to_the_camera(self):
        _, objs = self.run_scans([{"x": 25.0, "y": 0.0}])
        self.assertEqual(objs, [])

    def test_a_camera_object_explains_a_cluster_at_the_edge(self):
        cam = [{"id": "track0", "class": "car", "lon": 1.5, "lat": -3.3, "length": 1.0, "width": 2.0}]
        _, objs = self.run_scans([{"x": 1.0, "y": -3.5}], camera=cam)
        self.assertEqual(objs, [])
        _, objs = self.run_scans([{"x": 1.0, "y": -3.5}])
        self.assertEqual(len(objs), 1)

    def test_standing_ahead_is_left_out_beside_kept_still(self):
        # out of the camera's view: far to the side ahead, and beside the ego
        _, objs = self.run_scans([{"x": 6.0, "y": -9.0}, {"x": -0.5, "y": 3.5}])
        self.assertEqual(len(objs), 1, objs)
        self.assertLess(abs(objs[0]["lat"] - 3.5), 0.3)
        self.assertEqual((objs[0]["v_lon"], objs[0]["v_lat"]), (0.0, 0.0))
        # moving, ahead out of view (within AHEAD_M of the front): kept
        _, objs = self.run_scans([{"x": 0.0, "y": -9.0, "vx": 5.0}])
        self.assertEqual(len(objs), 1, objs)
        self.assertGreater(objs[0]["v_lon"], 4.0)

    def test_refine_places_a_camera_car_by_its_cluster(self):
        sur, _ = self.run_scans([{"x": 12.0, "y": -3.5}], seconds=0.1)
        # the box's centre ray put it too near the path and too wide (its rear and side)
        cam = [{"id": "car#0", "class": "car", "lon": 10.3, "lat": -2.4, "length": 1.0, "width": 2.9,
                "ranged_by": "lidar"},
               {"id": "person#1", "class": "pedestrian", "lon": 10.3, "lat": -2.4, "length": 0.5,
                "width": 0.6, "ranged_by": "lidar"}]
        car, walker = sur.refine(cam)
        self.assertLess(abs(car["lat"] + 3.5), 0.1)
        self.assertLess(abs(car["width"] - 1.8), 0.25)
        self.assertEqual(car["lat_by"], "lidar_cluster")
        self.assertEqual(walker, cam[1])

    def test_same_scans_same_objects(self):
        users = [{"x": -25.0, "y": -3.5, "vx": 8.0}, {"x": 2.0, "y": 3.5}]
        a = self.run_scans([dict(u) for u in users])[1]
        b = self.run_scans([dict(u) for u in users])[1]
        self.assertEqual(a, b)


DT = 0.05
WHEELBASE = 2.5


def in_camera(rig, ego, u):
    """The ground truth of user u when the camera sees all of it (a stand-in for the camera's
    fused objects), else None."""
    c, s = math.cos(ego["yaw"]), math.sin(ego["yaw"])
    dx, dy = u["x"] - ego["x"], u["y"] - ego["y"]
    lon, lat = c * dx + s * dy, -s * dx + c * dy
    corners = np.array([[lon + a * 2.25, lat + b * 0.9, 0.8] for a in (-1, 1) for b in (-1, 1)])
    uu, _, fwd = rig.camera.project(corners)
    if not np.all((fwd > 0.5) & (uu >= 0) & (uu <= rig.camera.width)):
        return None
    return {"id": "cam_" + u["id"], "class": "car", "lon": lon - 2.25 + 0.5, "lat": lat, "length": 1.0,
            "width": 1.8, "v_lon": c * u["vx"], "v_lat": -s * u["vx"], "source": "sensors"}


def drive_on_sensors(surround=True, seconds=35.0):
    """The planner (sensor input) on a straight road with a stopped car at x 80 in its lane and
    a car coming from behind in the right lane at 9 m/s; its objects are the camera's (ground
    truth of what the camera wholly sees, in_camera) and, with `surround`, the LiDAR's clusters
    around it (Surround on synthetic scans). Returns (planner, ego x per step, closest distance
    per user, passer x per step)."""
    route = RoutePath([(float(x), 0.0) for x in range(0, 401, 2)])
    rl = RouteLanes(route, [{"left": None, "right": -3.5} for _ in route.points])
    planner = ep.Planner(ep.parse_config({"CruiseSpeed": 8.333, "Input": "sensors"}), route, rl)
    rig = Rig.smart_car_lidar()
    sur = Surround(rig, 3.5, 1.6, 0.0)
    ego = {"id": "ego", "x": 10.0, "y": 0.0, "yaw": 0.0, "speed": 8.0, "yaw_rate": 0.0,
           "length": 3.5, "width": 1.6, "length_offset": 0.0}
    users = [{"id": "stopped", "x": 80.0, "y": 0.0, "vx": 0.0},
             {"id": "passer", "x": -20.0, "y": -3.5, "vx": 9.0}]
    closest, xs, passer, t, k = {}, [], [], 0.0, 0
    while t < seconds:
        if surround and k % 2 == 0:   # the LiDAR at 10 Hz
            sur.scan(scan_of(ego, users, rig), None, t, ego)
        cam = [o for o in (in_camera(rig, ego, u) for u in users) if o is not None]
        objs = cam + (sur.objects(ego, cam) if surround else [])
        out = planner.step(t, ego, objs)
        steer = out["steer"]
        if steer is None:
            s_ego, _ = route.locate(ego["x"], ego["y"])
            steer = lc.steer_to(route, ego, s_ego, lambda s: 0.0, 7.0)
        v = ego["speed"] + max(-6.0, min(2.0, (out["speed"] - ego["speed"]) / 0.5)) * DT
        ego["speed"] = max(v, 0.0)
        ego["yaw_rate"] = ego["speed"] * math.tan(steer) / WHEELBASE
        ego["yaw"] += ego["yaw_rate"] * DT
        ego["x"] += ego["speed"] * math.cos(ego["yaw"]) * DT
        ego["y"] += ego["speed"] * math.sin(ego["yaw"]) * DT
        for u in users:
            u["x"] += u["vx"] * DT
            closest[u["id"]] = min(closest.get(u["id"], 1e9),
                                   math.hypot(u["x"] - ego["x"], u["y"] - ego["y"]))
        t += DT
        k += 1
        xs.append(ego["x"])
        passer.append(users[1]["x"])
    return planner, xs, closest, passer


class PassesOnSensors(unittest.TestCase):
    """The planner with sensor input passes a stopped car once the car coming from behind in
    the next lane has gone by; that car it sees only by the LiDAR's clusters."""

    def test_waits_for_the_passer_then_passes(self):
        planner, xs, closest, passer = drive_on_sensors()
        self.assertEqual(planner.lane_change, "on")
        out_events = [e for e in planner.lc.events if e["kind"] == "out"]
        self.assertEqual(len(out_events), 1, planner.lc.events)
        k = int(round(out_events[0]["t"] / DT))
        self.assertGreater(passer[k] - 2.25, xs[k] + 1.75, "it pulled out once the passer was ahead")
        self.assertGreater(xs[-1], 120.0, "it passed the stopped car")
        self.assertIn("back", [e["kind"] for e in planner.lc.events])
        self.assertGreater(closest["stopped"], 3.0)
        self.assertGreater(closest["passer"], 3.0)

    def test_without_the_lidar_around_it_would_pull_out_beside_the_passer(self):
        planner, xs, _, passer = drive_on_sensors(surround=False, seconds=15.0)
        out_events = [e for e in planner.lc.events if e["kind"] == "out"]
        self.assertTrue(out_events, planner.lc.events)
        k = int(round(out_events[0]["t"] / DT))
        self.assertLess(passer[k] - 2.25, xs[k] + 1.75, "blind: it pulled out with the passer not ahead")


class OccludedSpeed(unittest.TestCase):
    """Sensor input: slower past a standing vehicle beside the path (lane_change.occluded_speed)."""

    def changer(self, inp):
        route = RoutePath([(float(x), 0.0) for x in range(0, 401, 2)])
        rl = RouteLanes(route, [{"left": None, "right": -3.5} for _ in route.points])
        return lc.LaneChanger(ep.parse_config({"Input": inp}), route, rl)

    EGO_STATE = {"length": 3.5, "width": 1.6, "length_offset": 0.0}

    def car(self, s, d, v=0.0):
        return {"id": "c", "class": "car", "s": s, "d": d, "v": v, "length": 4.5, "width": 1.8}

    def test_caps_beside_not_in_path_not_moving_not_ground_truth(self):
        ch = self.changer("sensors")
        at = ch.occluded_speed(self.EGO_STATE, 100.0, [self.car(104.0, -3.5)], 8.3)
        self.assertAlmostEqual(at, 5.0)    # beside, ahead: OccludedSpeed
        near = ch.occluded_speed(self.EGO_STATE, 90.0, [self.car(104.0, -3.5)], 8.3)
        self.assertAlmostEqual(near, 5.0)  # within OccludedRange of its rear
        far = ch.occluded_speed(self.EGO_STATE, 50.0, [self.car(104.0, -3.5)], 30.0)
        self.assertAlmostEqual(far, math.sqrt(25.0 + 2 * 2.0 * (104.0 - 2.25 - 51.75 - 15.0)))
        self.assertEqual(ch.occluded_speed(self.EGO_STATE, 100.0, [self.car(104.0, 0.0)], 8.3), 8.3)
        self.assertEqual(ch.occluded_speed(self.EGO_STATE, 100.0, [self.car(104.0, -3.5, 8.0)], 8.3), 8.3)
        self.assertEqual(ch.occluded_speed(self.EGO_STATE, 100.0, [self.car(104.0, -7.0)], 8.3), 8.3)
        self.assertEqual(ch.occluded_speed(self.EGO_STATE, 110.0, [self.car(104.0, -3.5)], 8.3), 8.3)
        gt = self.changer("ground_truth")
        self.assertEqual(gt.occluded_speed(self.EGO_STATE, 100.0, [self.car(104.0, -3.5)], 8.3), 8.3)


if __name__ == "__main__":
    unittest.main()
