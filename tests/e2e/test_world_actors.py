"""End-to-end tests of road users in the world engine (gazebo_grpc): actors posed from
RoadUser datapacks that a python_json engine publishes and a TF forwards, their ground-truth
boxes, their lifecycle, the ego's RoadUser, collision records, and bad road-user input.

Run with Debian's /usr/bin/python3 -m unittest test_world_actors."""

import json
import math
import os
import shutil
import textwrap
import unittest

from test_core import Experiment

HERE = os.path.dirname(os.path.abspath(__file__))
WORLD = os.path.join(HERE, "..", "world", "data", "actor_world.sdf")

# The rig's camera: at (-5, 0, 2) looking along +x, 320 x 240, horizontal fov 1.2.
CAM_X, CAM_Z, W, H, HFOV = -5.0, 2.0, 320, 240, 1.2
F = (W / 2) / math.tan(HFOV / 2)

# A python_json road-user engine: `users(t)` gives its road users at time t (seconds).
TRAFFIC = textwrap.dedent("""\
    from nrp_core.engines.python_json import EngineScript
    {users}
    class Script(EngineScript):
        def initialize(self):
            self._registerDataPack("road_users")
            self._setDataPack("road_users", {{"users": users(0.0)}})
        def runLoop(self, timestep_ns):
            self._setDataPack("road_users", {{"users": users(self._time_ns * 1e-9)}})
    """)

FORWARD = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_json import *

    @EngineDataPack(keyword='src', id=DataPackIdentifier('road_users', 'traffic'))
    @TransceiverFunction("gazebo")
    def forward(src):
        if src.isEmpty():
            return []
        dp = JsonDataPack("road_users", "gazebo")
        dp.data["users"] = src.data["users"]
        return [dp]
    """)

RECORD = textwrap.dedent("""\
    import json, math, os
    from nrp_core import *

    @EngineDataPack(keyword='boxes', id=DataPackIdentifier('rig::link::cam::boxes', 'gazebo'))
    @EngineDataPack(keyword='ego', id=DataPackIdentifier('robot::road_user', 'gazebo'))
    @EngineDataPack(keyword='link', id=DataPackIdentifier('robot_link_plugin::chassis', 'gazebo'))
    @EngineDataPack(keyword='collisions', id=DataPackIdentifier('collisions', 'gazebo'))
    @TransceiverFunction("gazebo")
    def record(boxes, ego, link, collisions):
        e = ego.data
        rec = {"boxes": boxes.data["boxes"] if not boxes.isEmpty() else [],
               "ego": {k: getattr(e, k) for k in ("id", "category", "x", "y", "z", "yaw",
                                                  "speed", "length", "width", "height", "time_ns")},
               "link": {"position": [float(v) for v in link.data.position], "rotation": [float(v) for v in link.data.rotation]},
               "collisions": collisions.data if not collisions.isEmpty() else []}
        with open(os.path.join(os.path.dirname(__file__), "record.jsonl"), "a") as f:
            f.write(json.dumps(rec) + "\\n")
        return []
    """)


class Actors(unittest.TestCase):
    def experiment(self, users, gazebo_extra=None, drive=None):
        ex = Experiment(self)
        shutil.copy(WORLD, os.path.join(ex.dir, "world.sdf"))
        gz = {"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
              "EngineTimestep": 0.02}
        gz.update(gazebo_extra or {})
        ex.engines.append(gz)
        ex.engine("traffic", TRAFFIC.format(users=textwrap.dedent(users)), timestep=0.02)
        ex.function("forward", FORWARD)
        ex.function("record", RECORD)
        if drive is not None:
            ex.function("drive", textwrap.dedent("""\
                from nrp_core import *
                from nrp_core.data.nrp_protobuf import GazeboJointDataPack

                @TransceiverFunction("gazebo")
                def drive():
                    out = []
                    for j in ("j_fl", "j_fr", "j_rl", "j_rr"):
                        dp = GazeboJointDataPack("robot_joint_plugin::" + j, "gazebo")
                        dp.data.velocity = %r
                        out.append(dp)
                    return out
                """ % drive))
        return ex

    def records(self, ex):
        with open(os.path.join(ex.dir, "record.jsonl")) as f:
            return [json.loads(line) for line in f]

    def test_actors_appear_in_ground_truth_where_they_are_and_come_and_go(self):
        ex = self.experiment("""\
            def users(t):
                out = []
                # a hatchback driving along the camera's axis, gone (absent) from t = 1.0
                out.append({"id": "traffic/car1", "category": "car", "model": "hatchback",
                            "x": 8.0 + 2.0 * t, "y": 0.0, "yaw": 0.0, "speed": 2.0,
                            "length": 4.5, "width": 1.9, "height": 1.5, "length_offset": 1.2,
                            "absent": t >= 1.0})
                # a pedestrian entering at t = 0.5, 2 m to the left
                if t >= 0.5:
                    out.append({"id": "traffic/ped1", "category": "pedestrian", "x": 10.0, "y": 2.0})
                # a cyclist sent only until t = 0.4: it times out (ActorTimeout 0.3 s)
                if t < 0.4:
                    out.append({"id": "traffic/bike", "category": "cyclist", "x": 12.0, "y": -3.0,
                                "yaw": 1.57})
                return out
            """, gazebo_extra={"ActorTimeout": 0.3})
        ex.run(1.6)
        recs = self.records(ex)
        self.assertGreaterEqual(len(recs), 70)

        def at(t):
            return recs[int(round(t / 0.02))]

        def box(rec, model):
            found = [b for b in rec["boxes"] if b["model"] == model]
            return found[0] if found else None

        # t ~ 0.3: the car and the cyclist, not yet the pedestrian
        r = at(0.3)
        car = box(r, "traffic/car1")
        self.assertIsNotNone(car, r["boxes"])
        self.assertEqual(car["class"], "car")
        self.assertIsNotNone(box(r, "traffic/bike"))
        self.assertEqual(box(r, "traffic/bike")["class"], "cyclist")
        self.assertIsNone(box(r, "traffic/ped1"))
        # The car's box is centred on the camera's axis; its width is 1.9 m seen from the
        # distance of its rear face (the state a step or two old: allow 0.1 m of travel).
        centre = (car["x_min"] + car["x_max"]) / 2
        self.assertLess(abs(centre - W / 2), 3, car)
        rear = 8.0 + 2.0 * 0.3 + 1.2 - 2.25 - CAM_X
        expected = F * 1.9 / rear
        self.assertLess(abs((car["x_max"] - car["x_min"]) - expected), 0.1 * expected,
                        (car, expected))
        # t ~ 0.9: the pedestrian, 2 m left at 15 m: its centre F * 2 / 15 px left of centre
        r = at(0.9)
        ped = box(r, "traffic/ped1")
        self.assertIsNotNone(ped, r["boxes"])
        self.assertEqual(ped["class"], "pedestrian")
        ped_centre = (ped["x_min"] + ped["x_max"]) / 2
        self.assertLess(abs(ped_centre - (W / 2 - F * 2.0 / 15.0)), 3, ped)
        self.assertIsNone(box(r, "traffic/bike"))  # timed out
        self.assertIsNotNone(box(r, "traffic/car1"))
        # t ~ 1.3: the car has left (absent); the pedestrian stays
        r = at(1.3)
        self.assertIsNone(box(r, "traffic/car1"))
        self.assertIsNotNone(box(r, "traffic/ped1"))
        # instances: one per actor, distinct
        ids = {b["model"]: b["instance"] for rec in recs for b in rec["boxes"]}
        self.assertEqual(len(set(ids.values())), len(ids))

        # The ego's RoadUser is its chassis link's pose.
        for rec in recs[5::20]:
            e, link = rec["ego"], rec["link"]
            self.assertEqual(e["id"], "robot")
            self.assertEqual(e["category"], "car")
            self.assertAlmostEqual(e["x"], link["position"][0], places=4)
            self.assertAlmostEqual(e["y"], link["position"][1], places=4)
            self.assertAlmostEqual(e["z"], link["position"][2], places=4)
            qx, qy, qz, qw = link["rotation"]
            yaw = math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz))
            self.assertAlmostEqual(e["yaw"], yaw, places=3)
            self.assertAlmostEqual(e["length"], 0.5, places=3)  # wheel to wheel
            self.assertAlmostEqual(e["width"], 0.44, places=3)
        # No contacts: the robot stands still, the actors apart.
        self.assertEqual(recs[-1]["collisions"], [])

    def test_ego_into_a_standing_actor_and_two_overlapping_actors(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/ped", "category": "pedestrian", "x": 1.5, "y": -10.0},
                        {"id": "traffic/a", "category": "car", "x": 20.0, "y": 30.0},
                        {"id": "traffic/b", "category": "bus", "x": 20.0 + max(0.0, 16.0 - 16.0 * t),
                         "y": 31.0, "yaw": 3.14159, "speed": 16.0 if t < 1.0 else 0.0}]
            """, drive=8.0)
        ex.run(2.5)
        recs = self.records(ex)
        # Deterministic: a second run gives the same records.
        os.remove(os.path.join(ex.dir, "record.jsonl"))
        ex.run(2.5, run_name="again")
        self.assertEqual(self.records(ex), recs)
        collisions = recs[-1]["collisions"]
        by_pair = {(c["a"], c["b"]): c for c in collisions}
        self.assertEqual(len(collisions), 2, collisions)
        hit = by_pair[("robot", "traffic/ped")]
        self.assertEqual((hit["class_a"], hit["class_b"]), ("car", "pedestrian"))
        # Wheels of radius 0.1 at 8 rad/s: up to 0.8 m/s.
        self.assertGreater(hit["relative_speed_mps"], 0.2)
        self.assertLess(hit["relative_speed_mps"], 1.0)
        # The robot's front (0.2 m ahead of its centre, with the wheels 0.25) met the
        # pedestrian's back face (1.35 m) after driving about 1.1 m.
        self.assertGreater(hit["t"], 0.5)
        over = by_pair[("traffic/a", "traffic/b")]
        self.assertEqual((over["class_a"], over["class_b"]), ("car", "bus"))
        self.assertGreater(over["relative_speed_mps"], 5)
        # The robot is held by the pedestrian: it does not drive through.
        self.assertLess(recs[-1]["ego"]["x"], 1.4)

    def test_unknown_category_names_engine_and_datapack(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/x", "category": "spaceship", "x": 5.0}]
            """)
        r = ex.run(0.2, expect=3)
        self.assertIn("engine 'gazebo'", r.stderr)
        self.assertIn("datapack 'road_users'", r.stderr)
        self.assertIn("category 'spaceship' is not one of car", r.stderr)

    def test_two_road_users_placed_on_the_same_spot(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/p", "category": "car", "x": 12.0, "y": 4.0},
                        {"id": "traffic/q", "category": "pedestrian", "x": 12.5, "y": 4.2},
                        {"id": "traffic/r", "category": "car", "x": 30.0, "y": 4.0}]
            """)
        r = ex.run(0.2, expect=3)
        self.assertIn("engine 'gazebo'", r.stderr)
        self.assertIn("road users 'traffic/p' and 'traffic/q' are placed on the same spot", r.stderr)
        self.assertIn("Route, StartS or Position", r.stderr)
        self.assertNotIn("traffic/r'", r.stderr)

    def test_unknown_model_falls_back_to_the_category_with_one_warning(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/x", "category": "car", "model": "limousine", "x": 8.0},
                        {"id": "traffic/y", "category": "car", "model": "limousine", "x": 8.0,
                         "y": 5.0}]
            """)
        ex.run(0.2)
        with open(os.path.join(ex.dir, "run", "logs", "gazebo.log")) as f:
            log = f.read()
        self.assertEqual(log.count("actor model 'limousine' is not in"), 1, log)
        recs = self.records(ex)
        self.assertEqual({b["class"] for b in recs[-1]["boxes"]}, {"car"})

    def test_an_id_reused_with_another_category_is_an_error(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/x", "category": "car" if t < 0.1 else "pedestrian",
                         "x": 5.0}]
            """)
        r = ex.run(0.4, expect=3)
        self.assertIn("engine 'gazebo'", r.stderr)
        self.assertIn("road user 'traffic/x': was 'car', now 'pedestrian'", r.stderr)

    def test_a_bad_json_road_user_key_is_named(self):
        ex = self.experiment("""\
            def users(t):
                return [{"id": "traffic/x", "category": "car", "speeed": 3.0}]
            """)
        r = ex.run(0.2, expect=3)
        self.assertIn("datapack 'road_users'", r.stderr)
        self.assertIn("unknown key 'speeed'", r.stderr)

    def test_protobuf_road_users_from_a_tf(self):
        # RoadUserDataPack and RoadUsersDataPack, built in a TF, under any names.
        ex = self.experiment("""\
            def users(t):
                return []
            """)
        ex.function("proto_users", textwrap.dedent("""\
            from nrp_core import *
            from nrp_core.data.nrp_protobuf import RoadUserDataPack, RoadUsersDataPack

            @TransceiverFunction("gazebo")
            def proto_users():
                one = RoadUserDataPack("lead_vehicle", "gazebo")
                one.data.id = "agent/lead"
                one.data.category = "truck"
                one.data.x = 10.0
                many = RoadUsersDataPack("crowd", "gazebo")
                u = many.data.users.add()
                u.id = "agent/walker"
                u.category = "pedestrian"
                u.x = 12.0
                u.y = -2.0
                return [one, many]
            """))
        ex.run(0.2)
        boxes = {b["model"]: b["class"] for b in self.records(ex)[-1]["boxes"]}
        self.assertEqual(boxes, {"agent/lead": "truck", "agent/walker": "pedestrian"})


class WorldCache(unittest.TestCase):
    def test_the_second_start_reads_the_parsed_world_from_the_cache(self):
        ex = Experiment(self)
        shutil.copy(WORLD, os.path.join(ex.dir, "world.sdf"))
        ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo",
                           "GazeboWorldFile": "world.sdf", "EngineTimestep": 0.02})
        old = os.environ.get("CONVOY_CACHE_DIR")
        os.environ["CONVOY_CACHE_DIR"] = os.path.join(ex.dir, "cache")
        try:
            logs = []
            for i in range(2):
                ex.run(0.1, run_name="run%d" % i)
                with open(os.path.join(ex.dir, "run%d" % i, "logs", "gazebo.log")) as f:
                    logs.append(f.read())
        finally:
            if old is None:
                del os.environ["CONVOY_CACHE_DIR"]
            else:
                os.environ["CONVOY_CACHE_DIR"] = old
        self.assertIn("(cache: miss", logs[0])
        self.assertIn("(cache: hit", logs[1])
        self.assertTrue(os.listdir(os.path.join(ex.dir, "cache", "world")))


if __name__ == "__main__":
    unittest.main()
