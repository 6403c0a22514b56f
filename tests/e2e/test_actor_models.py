"""The road-user actor models (engines/gazebo_grpc/actors, written by
tools/assets/make_road_users.py): the committed files are what the generator writes; each
table entry's SDF and meshes agree with its size, class and triangle budget; the world
engine loads and renders every model; and a street of them looks as its golden image
(tests/e2e/golden/actor_models.png; CONVOY_UPDATE_GOLDEN=1 rewrites it).

Run with Debian's /usr/bin/python3 -m unittest test_actor_models."""

import filecmp
import json
import numpy as np
import os
import shutil
import subprocess
import tempfile
import textwrap
import unittest
import xml.etree.ElementTree as ET

from test_core import REPO, Experiment

ACTORS = os.path.join(REPO, "engines", "gazebo_grpc", "actors")
TABLE = os.path.join(ACTORS, "actor_models.json")
GENERATOR = os.path.join(REPO, "tools", "assets", "make_road_users.py")
BUDGET = {"car": 3000, "bus": 5000, "truck": 5000, "pedestrian": 2000, "cyclist": 2600}


def load_table():
    with open(TABLE) as f:
        return json.load(f)


def obj_stats(path):
    """(min xyz, max xyz, triangles, mtllib or None) of a Wavefront OBJ."""
    lo, hi, tris, mtl = [1e9] * 3, [-1e9] * 3, 0, None
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                v = [float(x) for x in line.split()[1:4]]
                lo = [min(a, b) for a, b in zip(lo, v)]
                hi = [max(a, b) for a, b in zip(hi, v)]
            elif line.startswith("f "):
                tris += len(line.split()) - 3
            elif line.startswith("mtllib "):
                mtl = line.split(None, 1)[1].strip()
    return lo, hi, tris, mtl


class Files(unittest.TestCase):
    def test_committed_files_are_what_the_generator_writes(self):
        out = tempfile.mkdtemp(prefix="convoy-actors-")
        self.addCleanup(shutil.rmtree, out, True)
        subprocess.run(["/usr/bin/python3", GENERATOR, "--out", out], check=True, stdout=subprocess.DEVNULL,
                       env=dict(os.environ, PYTHONDONTWRITEBYTECODE="1"))
        cmp = filecmp.dircmp(out, ACTORS)
        stack = [cmp]
        while stack:
            c = stack.pop()
            self.assertEqual(c.left_only, [], "missing from the repository (run the generator)")
            self.assertEqual(c.right_only, [], "not written by the generator")
            _, mismatch, errors = filecmp.cmpfiles(c.left, c.right, c.common_files, shallow=False)
            self.assertEqual(mismatch + errors, [], "out of date: run /usr/bin/python3 tools/assets/make_road_users.py")
            stack += c.subdirs.values()
        total = sum(os.path.getsize(os.path.join(d, f)) for d, _, fs in os.walk(ACTORS) for f in fs)
        # 1.8 MB of models, 2.5 MB of walking cycles (8 poses of 4 figures)
        self.assertLess(total, 5_000_000)

    def test_table_entries_match_their_models(self):
        table = load_table()
        models = table["models"]
        for key in ("car", "sedan", "hatchback", "suv", "van", "truck", "bus", "walker", "pedestrian", "bicycle"):
            self.assertIn(key, models)
        for cat, key in table["categories"].items():
            self.assertEqual(models[key]["class"], cat)
        for key, e in models.items():
            with self.subTest(model=key):
                L, W, H = e["size"]
                root = ET.parse(os.path.join(ACTORS, e["file"])).getroot()
                model = root.find("model")
                self.assertEqual(model.find("static").text, "true")
                cls = model.find("plugin[@filename='convoy_class']/class").text
                self.assertEqual(cls, e["class"])
                link = model.find("link")
                box = [float(v) for v in link.find("collision/geometry/box/size").text.split()]
                pose = [float(v) for v in link.find("collision/pose").text.split()]
                self.assertEqual([round(v, 3) for v in box], [L, W, H])
                self.assertAlmostEqual(pose[2], H / 2, places=3)
                lo, hi, tris = [1e9] * 3, [-1e9] * 3, 0
                for uri in link.findall("visual/geometry/mesh/uri"):
                    path = os.path.join(ACTORS, uri.text)
                    a, b, n, mtl = obj_stats(path)
                    if mtl:
                        self.assertTrue(os.path.exists(os.path.join(os.path.dirname(path), mtl)))
                    lo = [min(x, y) for x, y in zip(lo, a)]
                    hi = [max(x, y) for x, y in zip(hi, b)]
                    tris += n
                self.assertLessEqual(tris, BUDGET[e["class"]])
                # the box's base centre is the origin; a car's mirrors stand out of its width
                self.assertAlmostEqual(lo[0], -L / 2, delta=0.002)
                self.assertAlmostEqual(hi[0], L / 2, delta=0.002)
                self.assertAlmostEqual(lo[2], 0.0, delta=0.002)
                self.assertAlmostEqual(hi[2], H, delta=0.002)
                spare = 0.11 if e["class"] == "car" else 0.002
                self.assertAlmostEqual(-lo[1], hi[1], delta=0.002)
                self.assertGreaterEqual(hi[1], W / 2 - 0.002)
                self.assertLessEqual(hi[1], W / 2 + spare)


RECORD = textwrap.dedent("""\
    import json, os
    from nrp_core import *

    @EngineDataPack(keyword='boxes', id=DataPackIdentifier('top::link::cam::boxes', 'gazebo'))
    @TransceiverFunction("gazebo")
    def record(boxes):
        if not boxes.isEmpty():
            with open(os.path.join(os.path.dirname(__file__), "record.jsonl"), "a") as f:
                f.write(json.dumps(boxes.data["boxes"]) + "\\n")
        return []
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

# A camera 100 m up looking straight down (image width along -y, height along +x).
WORLD = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="top">
    <light name="sun" type="directional"><pose>0 0 10 0 0 0</pose>
      <diffuse>0.9 0.9 0.9 1</diffuse><direction>-0.3 0.2 -0.9</direction></light>
    <model name="top"><static>true</static><pose>0 0 100 0 1.5707963 0</pose>
      <link name="link"><sensor name="cam" type="camera"><camera><horizontal_fov>1.3</horizontal_fov>
        <image><width>1280</width><height>960</height></image><clip><near>1</near><far>200</far></clip>
      </camera></sensor></link></model>
    <model name="ground"><static>true</static><link name="link">
      <collision name="c"><geometry><plane><normal>0 0 1</normal><size>400 400</size></plane></geometry></collision>
      <visual name="v"><geometry><plane><normal>0 0 1</normal><size>400 400</size></plane></geometry></visual>
    </link></model>
  </world>
</sdf>
"""


def add_world_and_users(ex, users):
    """The world engine on world.sdf with the actor table, and an engine sending `users` as
    RoadUsers every step (forwarded to the world by a TF)."""
    ex.engines.append({"EngineType": "gazebo_grpc", "EngineName": "gazebo", "GazeboWorldFile": "world.sdf",
                       "EngineTimestep": 0.02, "ActorModels": TABLE})
    ex.engine("traffic", textwrap.dedent("""\
        from nrp_core.engines.python_json import EngineScript
        USERS = %r
        class Script(EngineScript):
            def initialize(self):
                self._registerDataPack("road_users")
                self._setDataPack("road_users", {"users": USERS})
            def runLoop(self, timestep_ns):
                self._setDataPack("road_users", {"users": USERS})
        """ % users), timestep=0.02)
    ex.function("forward", FORWARD)


class Rendering(unittest.TestCase):
    def test_every_model_loads_and_is_seen_with_its_class(self):
        models = load_table()["models"]
        users = []
        for k, key in enumerate(sorted(models)):
            row, col = divmod(k, 10)
            users.append({"id": "a/" + key, "model": key, "x": -45.5 + 13.0 * row, "y": 63.0 - 14.0 * col})
        self.assertLessEqual(len(users), 80)
        ex = Experiment(self)
        ex.file("world.sdf", WORLD)
        add_world_and_users(ex, users)
        ex.function("record", RECORD)
        ex.run(0.1)
        seen = {}
        for boxes in ex.records("record"):
            for b in boxes:
                seen[b["model"]] = b["class"]
        for key, e in models.items():
            self.assertEqual(seen.get("a/" + key), e["class"], key)


class Animation(unittest.TestCase):
    def test_walkers_show_the_pose_of_their_walk_phase(self):
        """Walkers seen from the side at the eight phases of the walking cycle, and one standing
        still: their boxes (the rendered silhouette's) are narrow with the feet together (phase
        0 and 0.5) and wide at heel strike (0.25, 0.75), and the one standing is narrower still."""
        ex = Experiment(self)
        ex.file("world.sdf", STREET.replace("street", "side").replace("<width>640</width>", "<width>1280</width>")
                .replace("<height>240</height>", "<height>360</height>"))
        users = [{"id": "w%d" % k, "model": "walker_woman_2", "category": "pedestrian", "x": 0.0,
                  "y": 7.0 - 1.6 * k, "yaw": 1.5708, "speed": 1.4, "walk_phase": k / 8.0} for k in range(8)]
        users.append({"id": "stand", "model": "walker_woman_2", "category": "pedestrian", "x": 0.0,
                      "y": 7.0 - 1.6 * 8, "yaw": 1.5708, "speed": 0.0, "walk_phase": 0.25})
        add_world_and_users(ex, users)
        ex.function("record", RECORD.replace("top::link::cam", "side::link::cam"))
        ex.run(0.1)
        width = {}
        for boxes in ex.records("record"):
            for b in boxes:
                width[b["model"]] = b["x_max"] - b["x_min"]
        self.assertEqual(sorted(width), sorted(u["id"] for u in users))
        together = max(width["w0"], width["w4"])
        strike = min(width["w2"], width["w6"])
        self.assertGreater(strike, 1.4 * together, width)
        self.assertLess(width["stand"], 0.8 * strike, width)
        self.assertGreaterEqual(len({round(w) for w in width.values()}), 4, width)


GOLDEN = os.path.join(os.path.dirname(os.path.abspath(__file__)), "golden", "actor_models.png")

GRAB = textwrap.dedent("""\
    import os
    import numpy as np
    from nrp_core import *

    @EngineDataPack(keyword='cam', id=DataPackIdentifier('street::link::cam', 'gazebo'))
    @TransceiverFunction("gazebo")
    def grab(cam):
        if not cam.isEmpty() and cam.data.imageWidth > 0:
            img = np.frombuffer(cam.data.imageData, np.uint8).reshape(
                cam.data.imageHeight, cam.data.imageWidth, cam.data.imageDepth)
            np.save(os.path.join(os.path.dirname(__file__), "frame.npy"), img)
        return []
    """)

# A camera 1.6 m up, 14 m from a row of road users across its view, looking at them.
STREET = """<?xml version="1.0"?>
<sdf version="1.7">
  <world name="street">
    <light name="sun" type="directional"><pose>0 0 10 0 0 0</pose>
      <diffuse>0.9 0.9 0.85 1</diffuse><direction>-0.3 0.4 -0.85</direction></light>
    <model name="street"><static>true</static><pose>-14 0 1.6 0 0.05 0</pose>
      <link name="link"><sensor name="cam" type="camera"><camera><horizontal_fov>1.6</horizontal_fov>
        <image><width>640</width><height>240</height></image><clip><near>0.5</near><far>100</far></clip>
      </camera></sensor></link></model>
    <model name="ground"><static>true</static><link name="link">
      <collision name="c"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry></collision>
      <visual name="v"><geometry><plane><normal>0 0 1</normal><size>200 200</size></plane></geometry>
        <material><ambient>0.3 0.3 0.32 1</ambient><diffuse>0.3 0.3 0.32 1</diffuse></material></visual>
    </link></model>
  </world>
</sdf>
"""

# Side by side across the view (x, y, yaw): rear, front and side views.
STREET_USERS = [("bicycle", 0.0, 12.0, 1.57), ("hatchback", 0.0, 8.5, 2.8), ("sedan_red", 0.0, 5.0, 0.3),
                ("suv", 0.0, 1.5, 2.9), ("van", 0.0, -2.0, 0.25), ("pedestrian", -2.0, -4.3, 1.2),
                ("walker", -2.0, -5.3, 2.0), ("bus", 8.0, -8.5, 0.15), ("truck", 14.0, -13.5, 3.0)]


class Golden(unittest.TestCase):
    def test_a_street_of_road_users_looks_as_its_golden_image(self):
        ex = Experiment(self)
        ex.file("world.sdf", STREET)
        users = []
        for key, x, y, yaw in STREET_USERS:
            users.append({"id": "a/" + key, "model": key, "x": x, "y": y, "yaw": yaw})
            if key == "walker":  # mid-way through its cycle: the left heel striking
                users[-1].update(speed=1.4, walk_phase=0.25)
        add_world_and_users(ex, users)
        ex.function("grab", GRAB)
        ex.run(0.1)
        frame = np.load(os.path.join(ex.dir, "frame.npy"))[:, :, :3]
        import cv2
        if os.environ.get("CONVOY_UPDATE_GOLDEN") == "1":
            os.makedirs(os.path.dirname(GOLDEN), exist_ok=True)
            cv2.imwrite(GOLDEN, frame[:, :, ::-1])
        golden = cv2.imread(GOLDEN)
        self.assertIsNotNone(golden, GOLDEN + ": missing (CONVOY_UPDATE_GOLDEN=1 writes it)")
        golden = golden[:, :, ::-1]
        self.assertEqual(frame.shape, golden.shape)
        diff = np.abs(frame.astype(np.int16) - golden.astype(np.int16)).max(axis=2)
        # Within tolerance: a few edge pixels may differ between Mesa builds.
        self.assertLess(float(np.mean(diff > 24)), 0.005, "pixels off by more than 24 levels")
        self.assertLess(float(diff.mean()), 1.5)
        # And not a blank frame: the road users cover a good part of it.
        ground_and_sky = np.mean(np.abs(frame.astype(np.int16) - frame[5, 5].astype(np.int16)).max(axis=2) < 6)
        self.assertLess(ground_and_sky, 0.9)


if __name__ == "__main__":
    unittest.main()
