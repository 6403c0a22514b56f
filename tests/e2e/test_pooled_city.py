"""experiments/city_traffic/simulation_config_pooled.json, shortened: the ego (camera, detector,
planner) among vehicles of ONE road_user_pool engine on the city map (issue 26).

- Runs: 200 pooled vehicles for 3 simulated s. The world engine draws them: the camera's
  ground-truth boxes (smart_camera::camera::boxes, read by a TF added for the test) name
  pooled vehicles, the recorder tracked those near the ego, no two pooled vehicles touched, and
  nothing is left running.
- EgoSeen: at density 80 (~300 pooled vehicles) the pool sees the ego (pool_tf.py's
  external_users): 30 simulated s with no collision involving the ego (the world engine's
  records in summary.json; before the pool saw the ego, two pooled cars ran into it by 23 s).
- LargeCity: simulation_config_pooled_large.json, 1,000 pooled vehicles on the 4x4 grid city
  for 4 simulated s: the world draws them, the ego drives, no collision.
- BadInput: a Density the map cannot hold, and Count with Density, stop the run with one
  message naming the key (and the map's capacity), exit 2, nothing left running; so does a
  malformed external_users datapack, naming the road user and the field.
"""

import json
import os
import shutil
import subprocess
import tempfile
import textwrap
import unittest

from e2e_util import CONVOY, REPO

EXAMPLE = os.path.join(REPO, "experiments", "city_traffic")
CONFIG = "simulation_config_pooled.json"
POOL_ENGINE = os.path.join(os.path.dirname(CONVOY), "convoy-engine-road_user_pool")

BOXES_TF = textwrap.dedent("""\
    import json
    from nrp_core import *

    _seen = {"frames": 0, "models": []}


    @EngineDataPack(keyword="boxes", id=DataPackIdentifier("smart_camera::camera::boxes", "gazebo"))
    @TransceiverFunction("pool")
    def seen_boxes(boxes):
        if boxes.isEmpty():
            return []
        _seen["frames"] += 1
        models = sorted(set(_seen["models"]) | {b["model"] for b in boxes.data["boxes"]})
        _seen["models"] = models
        with open(OUT, "w") as f:
            json.dump(_seen, f)
        return []
    """)


BAD_EXTERNAL_TF = textwrap.dedent("""\
    from nrp_core import *
    from nrp_core.data.nrp_protobuf import RoadUsersDataPack


    @TransceiverFunction("pool")
    def bad_external():
        dp = RoadUsersDataPack("external_users", "pool")
        u = dp.data.users.add()
        u.id, u.x, u.y, u.length, u.width = "truck_9", 10.0, -1.75, -4.0, 2.0
        return [dp]
    """)


def engine_index(name):
    with open(os.path.join(EXAMPLE, CONFIG)) as f:
        return [e["EngineName"] for e in json.load(f)["EngineConfigs"]].index(name)


def functions():
    with open(os.path.join(EXAMPLE, CONFIG)) as f:
        return json.load(f)["DataPackProcessingFunctions"]


def processes_of(run_dir):
    """Live processes started for the run in run_dir (their environment names it)."""
    found = []
    key = ("CONVOY_RUN_DIR=" + run_dir).encode()
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/environ" % entry, "rb") as f:
                if key in f.read().split(b"\0"):
                    found.append(int(entry))
        except OSError:
            continue
    return found


class PooledCity(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.access(POOL_ENGINE, os.X_OK):
            raise unittest.SkipTest("convoy-engine-road_user_pool is not built")

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convoy-pooled-city-")
        self.addCleanup(shutil.rmtree, self.tmp, True)
        self.pool = engine_index("pool")

    def run_city(self, run_dir, seconds, *overrides, config=CONFIG):
        args = [CONVOY, "run", "-c", config, "--run-dir", run_dir, "-q",
                "-o", "SimulationTimeout=%g" % seconds]
        for o in overrides:
            args += ["-o", o]
        return subprocess.run(args, cwd=EXAMPLE, capture_output=True, text=True, timeout=300)


class Runs(PooledCity):
    def test_world_draws_the_pool(self):
        out = os.path.join(self.tmp, "boxes.json")
        tf = os.path.join(self.tmp, "boxes_tf.py")
        with open(tf, "w") as f:
            f.write(BOXES_TF.replace("OUT", repr(out)))
        tfs = functions() + [{"Name": "seen_boxes", "FileName": tf}]
        run_dir = os.path.join(self.tmp, "run")
        r = self.run_city(run_dir, 3.0, "EngineConfigs/%d/Density=0" % self.pool,
                          "EngineConfigs/%d/Count=200" % self.pool,
                          "DataPackProcessingFunctions=" + json.dumps(tfs))
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        with open(out) as f:
            seen = json.load(f)
        self.assertGreater(seen["frames"], 20)
        pooled = [m for m in seen["models"] if m.startswith("pool/pool/")]
        self.assertGreaterEqual(len(pooled), 3, seen["models"])
        with open(os.path.join(run_dir, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(s["participants"]["road_user_pool"], 1)
        self.assertGreater(s["camera_frames"], 60)
        self.assertEqual([c for c in s["collisions"] if "smart_car" not in (c["a"], c["b"])], [])
        with open(os.path.join(run_dir, "tracks.jsonl")) as f:
            rows = [json.loads(line) for line in f]
        near = {u[0] for r in rows for u in r["users"] if u[0].startswith("pool/pool/")}
        self.assertGreaterEqual(len(near), 1)  # pooled vehicles within 60 m of the ego
        self.assertEqual(processes_of(run_dir), [])


class EgoSeen(PooledCity):
    def test_no_pooled_car_runs_into_the_ego(self):
        run_dir = os.path.join(self.tmp, "run")
        r = self.run_city(run_dir, 30.0, "EngineConfigs/%d/Density=80" % self.pool)
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        with open(os.path.join(run_dir, "summary.json")) as f:
            s = json.load(f)
        self.assertGreaterEqual(s["simulated_s"], 29.0)
        ego = [c for c in s["collisions"] if "smart_car" in (c["a"], c["b"])]
        self.assertEqual(ego, [])
        self.assertEqual(s["collisions"], [])
        with open(os.path.join(run_dir, "tracks.jsonl")) as f:
            rows = [json.loads(line) for line in f]
        ego_x = [u[2] for r in rows for u in r["users"] if u[0] == "smart_car"]
        self.assertGreater(max(ego_x) - min(ego_x), 60.0)  # the ego drove among them
        self.assertGreaterEqual(s["pooled_vehicles"], 250)
        self.assertEqual(processes_of(run_dir), [])


class LargeCity(PooledCity):
    def test_a_thousand_pooled_road_users(self):
        run_dir = os.path.join(self.tmp, "run")
        r = self.run_city(run_dir, 4.0, config="simulation_config_pooled_large.json")
        self.assertEqual(r.returncode, 0, r.stderr[-3000:])
        with open(os.path.join(run_dir, "summary.json")) as f:
            s = json.load(f)
        self.assertEqual(s["participants"]["road_user_pool"], 1)
        self.assertEqual(s["collisions"], [])
        self.assertGreater(s["camera_frames"], 60)
        self.assertEqual(s["pooled_vehicles"], 800)  # and 200 walkers: 1,000 road users
        self.assertEqual(s["pooled_pedestrians"], 200)
        with open(os.path.join(run_dir, "tracks.jsonl")) as f:
            rows = [json.loads(line) for line in f]
        ego_x = [u[2] for r in rows for u in r["users"] if u[0] == "smart_car"]
        self.assertGreater(max(ego_x) - min(ego_x), 5.0)
        self.assertEqual(processes_of(run_dir), [])


class BadInput(PooledCity):
    def bad(self, *overrides):
        run_dir = os.path.join(self.tmp, "run")
        r = self.run_city(run_dir, 1.0, *overrides)
        self.assertEqual(r.returncode, 2, r.stderr[-2000:])
        self.assertEqual(processes_of(run_dir), [])
        return r.stderr

    def test_density_that_cannot_fit(self):
        err = self.bad("EngineConfigs/%d/Density=500" % self.pool)
        self.assertIn("road_user_pool engine 'pool': Density 500 vehicles/km cannot fit the map", err)
        self.assertIn("city.xodr", err)
        self.assertRegex(err, r"which hold at most \d+ \(\d+\.\d vehicles/km")

    def test_count_and_density(self):
        err = self.bad("EngineConfigs/%d/Count=10" % self.pool)
        self.assertIn("give Count or Density, not both", err)

    def test_malformed_external_datapack(self):
        tf = os.path.join(self.tmp, "bad_tf.py")
        with open(tf, "w") as f:
            f.write(BAD_EXTERNAL_TF)
        tfs = [t for t in functions() if t["Name"] != "pool_tf"] + \
            [{"Name": "bad_external", "FileName": tf}]
        err = self.bad("DataPackProcessingFunctions=" + json.dumps(tfs))
        self.assertIn("road_user_pool engine 'pool': datapack 'external_users': users[0] "
                      "('truck_9'): length must be > 0 m", err)

    def test_negative_density(self):
        err = self.bad("EngineConfigs/%d/Density=-1" % self.pool)
        self.assertIn("Density", err)


if __name__ == "__main__":
    unittest.main()
