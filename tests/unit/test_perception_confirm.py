"""Unit tests of what a LiDAR cluster is (python/convoy_sensors/shape.py, clusters.classify) and
of the camera objects' confirmation by range and over frames (convoy_sensors/confirm.py; issue
27: no phantom braking for roadside trees and false boxes). Pure Python, synthetic clusters."""
import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "python"))

from convoy_sensors import clusters, shape  # noqa: E402
from convoy_sensors.cluster_tracker import ClusterTracker  # noqa: E402
from convoy_sensors.confirm import Confirmer, agreed, support, theil_sen  # noqa: E402

RNG = np.random.default_rng(7)


def tree(x=12.0, y=8.0, trunk_top=1.8, crown_r=1.3, crown_z=3.0, n=300):
    """Returns of a tree seen from the ego: a 0.3 m trunk up to trunk_top, a round crown above.
    Intensities: bark 0.10, leaves 0.45 x cos(incidence)."""
    zs = np.arange(0.35, trunk_top, 0.15)
    trunk = np.array([(x - 0.1, y + dy, z) for z in zs for dy in (-0.15, 0.0, 0.15)])
    a = RNG.uniform(-math.pi / 2, math.pi / 2, n)           # the half facing the ego
    h = RNG.uniform(-1.0, 1.0, n)
    r = crown_r * np.sqrt(1 - h ** 2)
    crown = np.stack([x - r * np.cos(a), y + r * np.sin(a), crown_z + crown_r * h], axis=1)
    cos_inc = np.clip(np.sqrt(1 - h ** 2) * np.cos(a), 0.05, 1.0)
    pts = np.vstack([trunk, crown])
    inten = np.concatenate([np.full(len(trunk), 0.10), 0.45 * cos_inc])
    keep = pts[:, 2] < 4.0
    return pts[keep], inten[keep]


def car_side(x=8.0, y=3.5, length=4.2, height=1.45, paint=0.55):
    """Returns of a car's side seen from the ego: wheels and sill dark, the body painted, the
    windows glass, the roof painted."""
    pts, inten = [], []
    for z in np.arange(0.35, height, 0.12):
        for u in np.arange(0.0, length, 0.1):
            pts.append((x - length / 2 + u, y - 0.9, z))
            if z < 0.55 and (u < 1.1 and u > 0.5 or u > 3.1 and u < 3.7):
                inten.append(0.03)                    # tyres
            elif z > 0.95 and z < 1.3 and 0.8 < u < 3.4:
                inten.append(0.05)                    # glass
            else:
                inten.append(paint * RNG.uniform(0.8, 1.0))
    return np.array(pts), np.array(inten)


def shrub(x=10.0, y=-4.0, r=0.75, n=200):
    """A round shrub standing on the ground, seen from the ego (-x): leaves only, sampled
    evenly over its outline as a scanner's rays fall."""
    u, v = RNG.uniform(-1.0, 1.0, (2, 4 * n))
    inside = u * u + v * v < 1.0
    u, v = u[inside][:n], v[inside][:n]
    cos_inc = np.sqrt(1.0 - u * u - v * v)
    pts = np.stack([x - r * cos_inc, y + r * u, 0.7 + r * v], axis=1)
    inten = 0.45 * cos_inc
    keep = pts[:, 2] > 0.31
    return pts[keep], inten[keep]


def box_of(q):
    return {"x0": q[:, 0].min(), "x1": q[:, 0].max(), "y0": q[:, 1].min(), "y1": q[:, 1].max(),
            "z0": q[:, 2].min(), "z1": q[:, 2].max()}


class Shape(unittest.TestCase):
    def test_a_tree_is_vegetation_by_its_trunk_under_a_crown(self):
        q, i = tree()
        f = shape.features(q)   # no intensities: the shape alone
        self.assertTrue(f["trunk_canopy"], f["profile"])
        self.assertEqual(clusters.classify(box_of(q), f), "vegetation")
        self.assertEqual(clusters.classify(box_of(q)), "truck")   # by size alone, as before

    def test_a_car_is_not_a_tree_its_body_is_wide_low_down(self):
        q, i = car_side()
        f = shape.features(q, i)
        self.assertFalse(f["trunk_canopy"], f["profile"])
        self.assertIsNone(shape.vegetation(f))
        self.assertEqual(clusters.classify(box_of(q), f), "car")

    def test_a_car_on_a_narrow_pillar_profile_is_not_a_trunk(self):
        # a car's cabin narrower than its body over a wide base: the base is not a trunk
        prof = [(0.3, 1.8, 40), (0.7, 1.8, 40), (1.1, 1.2, 20)]
        self.assertFalse(shape.trunk_canopy(prof))
        self.assertTrue(shape.trunk_canopy([(0.3, 0.3, 6), (0.7, 0.3, 6), (1.5, 2.4, 60)]))

    def test_a_shrub_is_foliage_by_its_intensities_a_dark_car_is_not(self):
        q, i = shrub()
        f = shape.features(q, i)
        self.assertEqual(shape.vegetation(f), "foliage", (f["bright"], f["dark"]))
        self.assertEqual(clusters.classify(box_of(q), f), "vegetation")
        self.assertEqual(clusters.classify(box_of(q)), "car")   # the shape alone: car-sized
        # a black car (paint reflectivity 0.46: never brighter than leaves) keeps its glass
        q, i = car_side(paint=0.46)
        f = shape.features(q, i)
        self.assertLessEqual(f["bright"], shape.FOLIAGE_BRIGHT)
        self.assertIsNone(shape.vegetation(f))
        # the same shrub dimmed by fog stays no car: fog only darkens (more dark returns)
        q, i = shrub()
        self.assertEqual(shape.vegetation(shape.features(q, i * 0.9)), "foliage")

    def test_few_returns_say_nothing_by_intensity(self):
        q, i = shrub(n=20)
        f = shape.features(q, i)
        self.assertLess(f["points"], shape.FOLIAGE_MIN_POINTS)
        self.assertIsNone(shape.vegetation(f))

    def test_a_crown_over_the_road_is_overhead_a_far_trucks_top_is_not(self):
        q, _ = tree()
        crown = q[q[:, 2] > 2.3]
        self.assertEqual(clusters.classify(box_of(crown)), "overhead")
        # a truck 42 m ahead: the beams under its bed pass beneath it, the next one hits its top
        top = {"x0": 41.4, "x1": 41.6, "y0": -1.2, "y1": 1.2, "z0": 2.6, "z1": 2.7}
        self.assertEqual(clusters.classify(top), "truck")   # taller than TRUCK_HEIGHT

    def test_a_facade_is_taller_than_any_vehicle_a_truck_is_not(self):
        def wall(x, y0, length, height):
            return np.array([(x, y0 + u, z) for u in np.arange(0.0, length, 0.2)
                             for z in np.arange(0.4, height, 0.3)])
        facade = wall(20.0, 5.0, 6.0, 9.0)        # 6 m of a house: short of STATIC_LENGTH
        truck = wall(20.0, -3.0, 2.5, 3.8)         # a truck's rear, 3.8 m high
        boxes = clusters.segment_all(np.vstack([facade, truck]))
        got = sorted((round((b["y0"] + b["y1"]) / 2), b["class"]) for b in boxes)
        self.assertEqual([c for _, c in got], ["truck", "static"], got)
        # the façade cut at top_z alone (no returns above it) was a truck
        self.assertEqual(clusters.segment_all(facade[facade[:, 2] < 4.0])[0]["class"], "truck")

    def test_a_post_is_no_walker(self):
        post = np.array([(12.0, 3.0 + dy, z) for z in np.arange(0.4, 3.9, 0.2) for dy in (-0.1, 0.0, 0.1)])
        walker = np.array([(12.0, -3.0 + dy, z) for z in np.arange(0.4, 1.8, 0.2) for dy in (-0.2, 0.0, 0.2)])
        got = sorted(((b["y0"] + b["y1"]) / 2 > 0, b["class"]) for b in clusters.segment_all(np.vstack([post, walker])))
        self.assertEqual(got, [(False, "obstacle"), (True, "static")])
        # a walker under a tree's crown (returns above STATIC_HEIGHT over it) stays an obstacle
        crown = np.array([(12.0 + dx, -3.0 + dy, 5.0) for dx in (-1, 0, 1) for dy in (-1, 0, 1)])
        boxes = clusters.segment_all(np.vstack([walker, crown]))
        self.assertEqual([b["class"] for b in boxes], ["obstacle"])

    def test_segment_keeps_the_car_and_drops_the_tree_and_shrub(self):
        parts = [tree(), car_side(), shrub()]
        pts = np.vstack([p for p, _ in parts])
        inten = np.concatenate([i for _, i in parts])
        everything = clusters.segment_all(pts, intensity=inten)
        self.assertEqual(sorted(b["class"] for b in everything), ["car", "vegetation", "vegetation"])
        self.assertEqual(sorted(b["why"] or "" for b in everything), ["", "foliage", "trunk_canopy"])
        self.assertEqual([b["class"] for b in clusters.segment(pts, intensity=inten)], ["car"])
        # without intensities the shrub is car-sized: two "cars"
        self.assertEqual(sorted(b["class"] for b in clusters.segment(pts)), ["car", "car"])


def obj(cls, lon, lat, ranged_by="lidar", oid=None):
    return {"id": oid or "%s@%g" % (cls, lon), "class": cls, "lon": lon, "lat": lat,
            "length": 0.5 if cls == "pedestrian" else 1.0, "width": 1.8, "ranged_by": ranged_by}


def cluster(cls, x0, x1, y0, y1):
    return {"class": cls, "x0": x0, "x1": x1, "y0": y0, "y1": y1}


EGO = {"x": 0.0, "y": 0.0, "yaw": 0.0}


class Confirm(unittest.TestCase):
    def test_support_by_the_cluster_under_the_near_face(self):
        boxes = [cluster("car", 14.8, 19.3, -0.9, 0.9), cluster("vegetation", 15.0, 17.0, 3.0, 5.0),
                 cluster("obstacle", 9.8, 10.2, -0.2, 0.2)]
        self.assertEqual(support(obj("car", 15.3, 0.0), boxes), "lidar")
        self.assertEqual(support(obj("bus", 15.5, 4.0), boxes), "scenery")
        self.assertIsNone(support(obj("car", 30.0, 0.0), boxes))
        self.assertIsNone(support(obj("bus", 10.5, 0.0), boxes))       # a post is no bus
        self.assertEqual(support(obj("pedestrian", 10.25, 0.0), boxes), "lidar")

    def test_a_box_placed_beside_its_tree_by_the_centre_ray_is_still_the_tree(self):
        # the box's centre ray put it 0.55 m off the tree's cluster; its width reaches it
        boxes = [cluster("vegetation", 14.5, 16.1, -6.7, -5.05)]
        o = dict(obj("car", 16.2, -4.5), width=2.2)
        self.assertEqual(support(o, boxes), "scenery")
        self.assertIsNone(support(dict(o, width=0.2), boxes))   # a narrow box there: nothing under it

    def test_a_vehicle_box_on_a_tree_never_passes(self):
        c = Confirmer(frames=3)
        boxes = [cluster("vegetation", 15.0, 17.0, -1.0, 1.0)]
        for k in range(6):
            self.assertEqual(c.update([obj("bus", 15.5, 0.0)], 0.1 * k, EGO, boxes), [])
        self.assertEqual(list(c.last.values()), ["scenery"])

    def test_an_unsupported_box_passes_after_three_frames_whatever_its_class(self):
        c = Confirmer(frames=3)
        got = [c.update([obj(cls, 30.0 - k * 0.5, 0.0)], 0.1 * k, EGO, [])
               for k, cls in enumerate(("car", "truck", "car", "car"))]
        self.assertEqual([len(g) for g in got], [0, 0, 1, 1])
        self.assertEqual(got[2][0]["confirmed_by"], "frames")

    def test_a_single_frame_flicker_never_passes(self):
        c = Confirmer(frames=3)
        for k in range(8):
            objs = [obj("car", 14.0, 0.0)] if k % 2 == 0 else []
            self.assertEqual(c.update(objs, 0.1 * k, EGO, []), [])

    def test_a_lidar_supported_object_passes_at_once(self):
        c = Confirmer(frames=3)
        out = c.update([obj("car", 20.3, 0.0)], 0.0, EGO, [cluster("car", 20.0, 24.5, -0.9, 0.9)])
        self.assertEqual([o["confirmed_by"] for o in out], ["lidar"])

    def test_a_walker_by_a_tree_is_held_not_dropped(self):
        c = Confirmer(frames=3)
        boxes = [cluster("vegetation", 11.5, 13.0, 1.0, 2.5)]
        got = [c.update([obj("pedestrian", 12.0, 1.5)], 0.1 * k, EGO, boxes) for k in range(3)]
        self.assertEqual([len(g) for g in got], [0, 0, 1])
        # a LiDAR-only obstacle on the tree is the tree
        c = Confirmer(frames=3)
        for k in range(4):
            self.assertEqual(c.update([obj("car", 12.0, 1.5, ranged_by="lidar_only")], 0.1 * k, EGO, boxes), [])

    def test_streaks_follow_the_world_not_the_ego_frame(self):
        # the ego drives at 15 m/s towards a standing object: its ego-frame lon shrinks 1.5 m a frame
        c = Confirmer(frames=3, gate=1.0)
        out = []
        for k in range(3):
            ego = {"x": 1.5 * k, "y": 0.0, "yaw": 0.0}
            out = c.update([obj("car", 30.0 - 1.5 * k, 0.0)], 0.1 * k, ego, [])
        self.assertEqual(len(out), 1)


class Velocity(unittest.TestCase):
    def test_theil_sen_ignores_one_jump_and_agreed_takes_the_smaller(self):
        ts = [0.1 * k for k in range(8)]
        self.assertAlmostEqual(theil_sen(ts, [1.5 * t for t in ts]), 1.5)
        self.assertAlmostEqual(theil_sen(ts, [0.0] * 7 + [1.4]), 0.0)
        self.assertEqual(theil_sen([0.0], [3.0]), 0.0)
        self.assertEqual(agreed(4.1, 0.2), 0.2)
        self.assertEqual(agreed(-1.2, -1.4), -1.2)
        self.assertEqual(agreed(4.1, -0.1), 0.0)

    def test_a_parked_car_whose_box_jumps_for_a_frame_does_not_cross(self):
        # the box takes in the next car for a frame: the tracker's lateral speed jumps to 4 m/s
        c = Confirmer()
        boxes = [cluster("car", 19.0, 24.0, -11.4, -9.6)]
        for k in range(8):
            lat, v_lat = (-9.1, 4.1) if k == 7 else (-10.5, 0.0)
            o = dict(obj("car", 20.0, lat), v_lon=0.0, v_lat=v_lat)
            ego = {"x": 0.0, "y": 0.0, "yaw": 0.0}
            out = c.update([o], 0.1 * k, ego, boxes)
        self.assertEqual(len(out), 1)
        self.assertLess(abs(out[0]["v_lat"]), 0.5)

    def test_a_crossing_walker_keeps_its_speed(self):
        c = Confirmer()
        for k in range(8):
            o = dict(obj("pedestrian", 15.0, -4.0 + 0.14 * k), v_lon=0.0, v_lat=1.2)
            out = c.update([o], 0.1 * k, EGO, [cluster("obstacle", 14.7, 15.1, -4.3 + 0.14 * k, -3.7 + 0.14 * k)])
        self.assertAlmostEqual(out[0]["v_lat"], 1.2)
        # a new object is standing until it has a few positions
        c = Confirmer()
        out = c.update([dict(obj("pedestrian", 15.0, -4.0), v_lat=1.2)], 0.0, EGO, [cluster("obstacle", 14.7, 15.1, -4.3, -3.7)])
        self.assertEqual(out[0]["v_lat"], 0.0)

    def test_a_standing_cluster_that_grows_and_shrinks_does_not_move(self):
        tr = ClusterTracker()
        for k in range(12):
            x1 = 17.0 if k % 4 == 3 else 14.0   # a hedge's end seen now and then (last scan too)
            out = tr.update([{"x0": 10.0, "x1": x1, "y0": 4.0, "y1": 5.0, "z1": 1.2, "points": 30,
                              "class": "car"}], 0.1 * k, EGO)
        self.assertEqual(len(out), 1)
        self.assertGreater(math.hypot(tr.tracks[0]["vx"], tr.tracks[0]["vy"]), 2.0)   # filtered: "moving"
        self.assertLess(math.hypot(out[0]["vx"], out[0]["vy"]), 0.5)


if __name__ == "__main__":
    unittest.main()
