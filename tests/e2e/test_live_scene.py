"""The scene channels (docs/architecture.md "Live server"; src/scene): a short city_traffic run
(the ego among vehicle and pedestrian agents, SUMO's traffic, the traffic lights; 2 simulated
seconds) served live and recorded. Live: /convoy/map (kept for a client that subscribes late),
/convoy/scene (road users that move, the ego marked), /convoy/transforms, /convoy/frames. In
the MCAP: the same channels but /convoy/frames. And the same run gives the same scene bytes
(the pedestrians experiment twice), which a replay reads. The smart car of the "both"
experiment, whose road user no function reads, is in the live scene, and watching changes
nothing the run computes."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

from e2e_util import CONVOY, REPO, free_port
from live_ws import LiveClient

sys.path.insert(0, os.path.join(REPO, "python"))
from convoy_mcap import Recording  # noqa: E402

CITY = os.path.join(REPO, "experiments", "city_traffic", "simulation_config.json")
PEDESTRIANS = os.path.join(REPO, "experiments", "pedestrians", "simulation_config.json")
BOTH = os.path.join(REPO, "experiments", "autonomous_driving", "simulation_config_both.json")
CAMERA_IMAGE = "gazebo/smart_camera::camera/image"
EGO = "smart_car"


def meta(entity):
    return {kv["key"]: kv["value"] for kv in entity["metadata"]}


def positions(updates, entity_id):
    """(x, y) of an entity's cube in each update that has it."""
    out = []
    for u in updates:
        for e in u["entities"]:
            if e["id"] == entity_id and e["cubes"]:
                p = e["cubes"][0]["pose"]["position"]
                out.append((p["x"], p["y"]))
    return out


def recorded(path, topic):
    return [m for m in Recording(path).messages([topic])]


class Scene(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="convoy_scene_")
        port = free_port()
        run = subprocess.Popen([CONVOY, "run", "-c", CITY, "-o", "SimulationTimeout=2", "--run-dir",
                                os.path.join(cls.tmp, "city"), "--live", str(port), "--record"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            cls.client = LiveClient(port)
            for topic in ("/convoy/scene", "/convoy/transforms", "/convoy/map", "/convoy/frames",
                          CAMERA_IMAGE, "/convoy/metrics"):
                cls.client.subscribe(topic)
            # A second viewer that comes once the run has started still gets the map.
            cls.client.wait_for(lambda: len(cls.client.data.get(1, [])) >= 3, timeout=60)
            cls.late = LiveClient(port)
            cls.late.subscribe("/convoy/map")
            cls.late.wait_for(lambda: cls.late.data.get(1), timeout=10)
            _, cls.stderr = run.communicate(timeout=120)
        finally:
            if run.poll() is None:
                run.kill()
                run.wait()
        cls.returncode = run.returncode
        cls.client.wait_for(lambda: cls.client.closed, timeout=5)
        cls.mcap = os.path.join(cls.tmp, "city", "recording.mcap")

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.late.close()
        if os.environ.get("CONVOY_E2E_KEEP") != "1":
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def check_map(self, update):
        ids = [e["id"] for e in update["entities"]]
        self.assertEqual(ids[:2], ["lanes", "centres"])
        lanes = update["entities"][0]
        self.assertGreater(len(lanes["lines"]), 30)
        self.assertGreater(sum(len(line["points"]) for line in lanes["lines"]), 1000)
        self.assertEqual(lanes["frame_id"], "map")
        self.assertEqual(meta(lanes)["kind"], "lanes")
        signals = [e for e in update["entities"] if e["id"].startswith("signal/")]
        self.assertEqual(len(signals), 8)  # the city's two junctions, four lights each
        self.assertEqual(meta(signals[0])["kind"], "signal")

    def check_scene(self, updates):
        self.assertGreaterEqual(len(updates), 15)  # 10 per simulated second
        last = updates[-1]
        ids = {e["id"] for e in last["entities"]}
        self.assertIn(EGO, ids)
        self.assertIn("car_0", ids)
        self.assertIn("ped_0", ids)
        self.assertTrue(any(i.startswith("sumo/") for i in ids), sorted(ids))
        egos = [e["id"] for e in last["entities"] if meta(e).get("ego") == "true"]
        self.assertEqual(egos, [EGO])
        ped = next(e for e in last["entities"] if e["id"] == "ped_0")
        self.assertEqual(meta(ped)["category"], "pedestrian")
        # Road users move: car_0 starts at 6 m/s.
        car = positions(updates, "car_0")
        self.assertGreater(abs(car[-1][0] - car[0][0]) + abs(car[-1][1] - car[0][1]), 5.0)
        signals = next(e for e in last["entities"] if e["id"] == "signals")
        states = {kv["value"] for kv in signals["metadata"]}
        self.assertTrue(states <= {"red", "yellow", "green", "red_yellow", "off"}, states)
        self.assertEqual(len(signals["spheres"]), 8)

    def test_the_run_completes(self):
        self.assertEqual(self.returncode, 0, self.stderr[-3000:])
        self.assertIn("scene: map", self.stderr)

    def test_live_map_also_for_a_late_viewer(self):
        maps = self.client.messages("/convoy/map")
        self.assertEqual(len(maps), 1)
        self.check_map(maps[0])
        late = self.late.messages("/convoy/map")
        self.assertEqual(len(late), 1)
        self.assertEqual(late[0], maps[0])

    def test_live_scene_and_transforms(self):
        scenes = self.client.messages("/convoy/scene")
        self.check_scene(scenes)
        stamps = [u["entities"][0]["timestamp"] for u in scenes]
        ns = [s["sec"] * 10**9 + s["nsec"] for s in stamps]
        self.assertEqual(ns, sorted(ns))
        self.assertEqual(ns[1] - ns[0], 100000000)
        tfs = self.client.messages("/convoy/transforms")
        self.assertGreaterEqual(len(tfs), 15)
        tf = tfs[-1]["transforms"][0]
        self.assertEqual((tf["parent_frame_id"], tf["child_frame_id"]), ("map", EGO))

    def test_live_frame_notes(self):
        frames = self.client.messages("/convoy/frames")
        images = self.client.messages(CAMERA_IMAGE)
        self.assertGreater(len(frames), 5)
        self.assertLessEqual(len(frames), len(images))
        self.assertEqual({f["topic"] for f in frames}, {CAMERA_IMAGE})
        now_ms = time.time() * 1000
        for f in frames:
            self.assertLess(abs(now_ms - f["wall_ms"]), 300000)
        t = [f["time_ns"] for f in frames]
        self.assertEqual(t, sorted(t))

    def test_recorded_scene(self):
        maps = recorded(self.mcap, "/convoy/map")
        self.assertEqual(len(maps), 1)
        self.assertEqual(maps[0].schema_name, "foxglove.SceneUpdate")
        self.check_map(maps[0].value)
        scenes = recorded(self.mcap, "/convoy/scene")
        self.assertEqual(scenes[0].schema_name, "foxglove.SceneUpdate")
        self.check_scene([m.value for m in scenes])
        tfs = recorded(self.mcap, "/convoy/transforms")
        self.assertEqual(tfs[0].schema_name, "foxglove.FrameTransforms")
        self.assertEqual(len(tfs), len(scenes))
        self.assertEqual(recorded(self.mcap, "/convoy/frames"), [])  # live only
        # The live server's scene and the recording's are the same messages.
        live = {json.dumps(u, sort_keys=True) for u in self.client.messages("/convoy/scene")}
        rec = [json.dumps(m.value, sort_keys=True) for m in scenes]
        self.assertGreaterEqual(sum(r in live for r in rec), len(rec) - 2)


    def test_recorded_metrics_as_served(self):
        # score_tf.py's score, live on /convoy/metrics and in the recording (for a replay).
        rec = recorded(self.mcap, "/convoy/metrics")
        self.assertGreaterEqual(len(rec), 1)
        self.assertEqual(rec[0].channel.metadata.get("viewer"), "metrics")
        last = rec[-1].value
        self.assertIn("driving_score", last)
        self.assertGreater(last["route_completion"], 0)
        self.assertEqual(last["time_ns"], rec[-1].log_time)
        live = self.client.messages("/convoy/metrics")
        self.assertEqual(live[-1], last)


class SceneDeterminism(unittest.TestCase):
    def test_the_same_run_gives_the_same_scene_bytes(self):
        tmp = tempfile.mkdtemp(prefix="convoy_scene_det_")
        try:
            data = []
            for name in ("a", "b"):
                r = subprocess.run([CONVOY, "run", "-c", PEDESTRIANS, "-o", "SimulationTimeout=3",
                                    "--run-dir", os.path.join(tmp, name), "--record", "-q"],
                                   capture_output=True, text=True, timeout=120)
                self.assertEqual(r.returncode, 0, r.stderr)
                path = os.path.join(tmp, name, "recording.mcap")
                data.append([(m.topic, m.log_time, m.data) for m in
                             Recording(path).messages(["/convoy/map", "/convoy/scene",
                                                       "/convoy/transforms"])])
            self.assertGreater(len(data[0]), 50)
            self.assertEqual(data[0], data[1])
            scenes = [json.loads(d) for t, _, d in data[0] if t == "/convoy/scene"]
            ped = positions(scenes, "ped_0")
            self.assertGreater(abs(ped[-1][0] - ped[0][0]) + abs(ped[-1][1] - ped[0][1]), 1.0)
            # A replay leaves the viewers' channels out.
            r = subprocess.run([CONVOY, "replay", os.path.join(tmp, "a")], capture_output=True,
                               text=True, timeout=120)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn(" 0 mismatches", r.stderr)
        finally:
            shutil.rmtree(tmp, ignore_errors=True)


# summary.json fields that depend on the wall clock or on what was watched, not on the run.
WALL_FIELDS = {"wall_s", "loop_wall_s", "real_time_factor", "physics_real_time_factor",
               "camera_frames_per_s", "detector_inference_ms_median", "startup_s", "startup",
               "live"}


def computed(summary_path):
    with open(summary_path) as f:
        summary = json.load(f)
    return {k: v for k, v in summary.items() if k not in WALL_FIELDS}


class SceneEgo(unittest.TestCase):
    """The README's example: the smart car on the Parkring ("both" experiment), whose functions
    read only the car's links. The scene shows it anyway (the loop also asks the world engine
    for smart_car::road_user), and the run computes the same as without a viewer."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="convoy_scene_ego_")
        port = free_port()
        run = subprocess.Popen([CONVOY, "run", "-c", BOTH, "-o", "SimulationTimeout=3",
                                "--run-dir", os.path.join(cls.tmp, "live"), "--live", str(port)],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            cls.client = LiveClient(port)
            cls.client.subscribe("/convoy/scene")
            _, cls.stderr = run.communicate(timeout=180)
        finally:
            if run.poll() is None:
                run.kill()
                run.wait()
        cls.returncode = run.returncode
        cls.client.wait_for(lambda: cls.client.closed, timeout=5)
        cls.plain = subprocess.run([CONVOY, "run", "-c", BOTH, "-o", "SimulationTimeout=3",
                                    "--run-dir", os.path.join(cls.tmp, "plain")],
                                   capture_output=True, text=True, timeout=180)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        if os.environ.get("CONVOY_E2E_KEEP") != "1":
            shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_the_ego_is_in_the_scene_and_moves(self):
        self.assertEqual(self.returncode, 0, self.stderr[-3000:])
        self.assertIn("scene: also taking gazebo/smart_car::road_user", self.stderr)
        scenes = self.client.messages("/convoy/scene")
        self.assertGreaterEqual(len(scenes), 20)  # 10 per simulated second
        car = [e for e in scenes[-1]["entities"] if e["id"] == EGO]
        self.assertEqual(len(car), 1, [e["id"] for e in scenes[-1]["entities"]])
        self.assertEqual(meta(car[0])["ego"], "true")
        self.assertEqual(meta(car[0])["category"], "car")
        self.assertEqual(meta(car[0])["source"], "gazebo/smart_car::road_user")
        path = positions(scenes, EGO)
        self.assertGreaterEqual(len(path), 20)
        self.assertGreater(abs(path[-1][0] - path[0][0]) + abs(path[-1][1] - path[0][1]), 3.0)

    def test_the_run_computes_the_same_as_without_a_viewer(self):
        self.assertEqual(self.plain.returncode, 0, self.plain.stderr[-3000:])
        self.assertNotIn("scene: also taking", self.plain.stderr)
        live, plain = (os.path.join(self.tmp, d) for d in ("live", "plain"))
        self.assertEqual(computed(os.path.join(live, "summary.json")),
                         computed(os.path.join(plain, "summary.json")))
        for name in ("trajectory.csv", "control_summary.json"):
            with open(os.path.join(live, name)) as a, open(os.path.join(plain, name)) as b:
                self.assertEqual(a.read(), b.read(), name)


if __name__ == "__main__":
    unittest.main()
