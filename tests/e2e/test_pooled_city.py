"""experiments/city_traffic/simulation_config_pooled.json, shortened: the ego (camera, detector,
planner) among vehicles of ONE road_user_pool engine on the city map (issue 26).

- Runs: 200 pooled vehicles for 3 simulated s. The world engine draws them: the camera's
  ground-truth boxes (smart_camera::camera::boxes, read by a TF added for the test) name
  pooled vehicles, the recorder tracked those near the ego, no two pooled vehicles touched, and
  nothing is left running.
- BadInput: a Density the map cannot hold, and Count with Density, stop the run with one
  message naming the key (and the map's capacity), exit 2, nothing left running.
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

    def run_city(self, run_dir, seconds, *overrides):
        args = [CONVOY, "run", "-c", CONFIG, "--run-dir", run_dir, "-q",
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

    def test_negative_density(self):
        err = self.bad("EngineConfigs/%d/Density=-1" % self.pool)
        self.assertIn("Density", err)


if __name__ == "__main__":
    unittest.main()
