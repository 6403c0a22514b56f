"""The world generator end to end (docs/worlds.md): `convoy-odr world` on good and bad maps,
and scenario runs on esmini's maps (tests/data/esmini/xodr, scenarios in
benchmarks/worlds) whose worlds `convoy run --scenario` generates and caches.

Groups: Cli (the command's outputs, exit codes and warnings), Drive (the smart car on a
generated urban map with traffic lights, its first 14 of 20 simulated seconds (82 of 128 m), and
on a map that climbs a crest, 17 s (to near its top): it keeps its lane, and a second run takes
the world from the cache), Long (label long: every esmini map
generated, loaded, rendered and driven, as benchmarks/odr_world_bench.py --render does)."""

import csv
import json
import os
import subprocess
import sys
import unittest

from e2e_util import BIN_DIR, CONVOY, REPO, E2ETestCase

ODR = os.path.join(BIN_DIR, "convoy-odr")
MAPS = os.path.join(REPO, "tests", "data", "esmini", "xodr")
SCENARIOS = os.path.join(REPO, "benchmarks", "worlds")
LANE_KEEPING_M = 0.85


def odr_world(*args):
    p = subprocess.run([ODR, "world"] + list(args), capture_output=True, text=True, timeout=120)
    return p.returncode, p.stdout, p.stderr


class Cli(E2ETestCase):
    def test_a_map_becomes_a_world(self):
        out = os.path.join(self.dir, "w")
        code, stdout, err = odr_world(os.path.join(MAPS, "fabriksgatan_traffic_lights.xodr"), out,
                                      "--scenery", "urban", "--seed", "3")
        self.assertEqual(code, 0, err)
        self.assertIn("world.sdf: ", stdout)
        with open(os.path.join(out, "world.sdf")) as f:
            text = f.read()
        for cls in ("building", "traffic_light", "pole"):
            self.assertIn("<class>%s</class>" % cls, text)
        self.assertIn("model://convoy_scenery/meshes/", text)
        self.assertEqual([f for f in os.listdir(self.dir) if ".partial-" in f], [])

    def test_the_same_seed_writes_the_same_files(self):
        a, b = os.path.join(self.dir, "a"), os.path.join(self.dir, "b")
        for d in (a, b):
            self.assertEqual(odr_world(os.path.join(MAPS, "jolengatan.xodr"), d, "--scenery", "roadside")[0], 0)
        for name in sorted(os.listdir(os.path.join(a, "meshes"))) + ["../world.sdf"]:
            with open(os.path.join(a, "meshes", name), "rb") as f, open(os.path.join(b, "meshes", name), "rb") as g:
                self.assertEqual(f.read(), g.read(), name)

    def test_a_map_that_cannot_be_parsed_is_exit_2_and_writes_nothing(self):
        out = os.path.join(self.dir, "bad")
        code, _, err = odr_world(os.path.join(REPO, "tests", "opendrive", "data", "malformed.xodr"), out)
        self.assertEqual(code, 2)
        self.assertRegex(err, r"malformed\.xodr:\d+: ")
        self.assertEqual(len(err.strip().splitlines()), 1, err)
        self.assertFalse(os.path.exists(out))
        self.assertEqual(os.listdir(self.dir), [])

    def test_parts_it_cannot_build_are_warnings_naming_them(self):
        out = os.path.join(self.dir, "w")
        code, _, err = odr_world(os.path.join(REPO, "tests", "worldgen", "data", "bad_parts.xodr"), out)
        self.assertEqual(code, 0, err)
        self.assertIn("road 2", err)                                  # unknown geometry: skipped
        self.assertIn("road 1 lane section 0 lane 2 (shoulder): width 0", err)
        self.assertIn("road 1 object 7 (building) outline 0", err)
        self.assertIn("road 1 signal 9 (): unknown signal type 'zz99'", err)
        self.assertTrue(os.path.exists(os.path.join(out, "world.sdf")))

    def test_bad_options(self):
        xodr = os.path.join(MAPS, "straight_500m.xodr")
        for args, what in ((["--scenery", "forest"], "--scenery must be none, roadside or urban"),
                           (["--seed", "x"], "--seed must be a whole number"),
                           (["--catalog", "/nonexistent.json"], "/nonexistent.json")):
            code, _, err = odr_world(xodr, os.path.join(self.dir, "w"), *args)
            self.assertEqual(code, 2, args)
            self.assertIn(what, err)
            self.assertFalse(os.path.exists(os.path.join(self.dir, "w")))


class Drive(E2ETestCase):
    def drive(self, name, *args, timeout=None, tracks=None):
        env = dict(os.environ, CONVOY_CACHE_DIR=os.path.join(self.dir, "cache"))
        run = os.path.join(self.dir, "run_%s_%d" % (name, len(os.listdir(self.dir))))
        cmd = [CONVOY, "run", "-q", "--scenario", os.path.join(SCENARIOS, name + ".xosc"), "--run-dir", run]
        if timeout:
            cmd += ["-o", "SimulationTimeout=%g" % timeout]
        p = subprocess.run(cmd + list(args), capture_output=True, text=True, env=env, timeout=600)
        self.assertEqual(p.returncode, 0, p.stderr)
        if tracks is not None:
            with open(os.path.join(run, "tracks.csv")) as f:
                tracks.extend(csv.DictReader(f))
        with open(os.path.join(run, "summary.json")) as f:
            return json.load(f), p.stderr

    def test_an_urban_map_with_traffic_lights(self):
        # 14 s of the scenario's 20: past 60 m at 12 s
        s, err = self.drive("fabriksgatan_traffic_lights", timeout=14)
        self.assertIn("generated from fabriksgatan_traffic_lights.xodr", err)
        self.assertGreater(s["detector_frames"], 50)                 # the camera saw the world
        self.assertLessEqual(s["score"]["route_max_offset_m"], LANE_KEEPING_M)
        self.assertGreater(s["score"]["route_progress_m"], 60)
        self.assertEqual(s["score"]["nuplan_score"]["collisions"], [])
        again, err = self.drive("fabriksgatan_traffic_lights", timeout=1)
        self.assertIn("cached", err)

    def test_a_map_over_a_crest(self):
        # the road climbs 6 m over its crest (s 200 to 340) and comes down; one run checks the
        # drive and, below, that the car drives on the road's surface; 17 s of the scenario's 20:
        # 4 m up at 14 s, 6.4 m at 17 s (the top, 6.6 m, at 18 s)
        rows = []
        s, err = self.drive("crest-curve", timeout=17, tracks=rows)
        self.assertLessEqual(s["score"]["route_max_offset_m"], LANE_KEEPING_M)
        self.assertGreater(s["score"]["route_progress_m"], 60)
        self.assertEqual(s["score"]["nuplan_score"]["collisions"], [])
        ego = [r for r in rows if r["entity"] == "Ego"]
        self.assertGreater(len(ego), 100)
        self.assertGreater(float(ego[-1]["s"]) - float(ego[0]["s"]), 60)   # tracks.csv follows it
        self.check_on_the_surface(ego)

    def check_on_the_surface(self, ego):
        # the road model collides as a height field of the roads' surface (docs/worlds.md): the
        # car's height above the road stays the same while the road climbs 6 m
        xodr = os.path.join(MAPS, "crest-curve.xodr")
        q = subprocess.Popen([ODR, "query", xodr], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        above = []
        for r in ego[::10]:
            q.stdin.write(json.dumps({"op": "locate", "x": float(r["x"]), "y": float(r["y"])}) + "\n")
            q.stdin.flush()
            above.append(float(r["z"]) - json.loads(q.stdout.readline())["z"])
        q.stdin.close()
        q.wait()
        q.stdout.close()
        self.assertGreater(len(above), 10)
        self.assertGreater(max(float(r["z"]) for r in ego), 4.0)     # up the crest
        self.assertLess(max(above) - min(above), 0.15, above)


class Long(E2ETestCase):
    def test_every_esmini_map(self):
        p = subprocess.run([sys.executable, os.path.join(REPO, "benchmarks", "odr_world_bench.py"), "--render",
                            "--build", os.path.dirname(BIN_DIR)], capture_output=True, text=True, timeout=3000)
        print(p.stdout)
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("worlds generated: 20/20", p.stdout)
        self.assertIn("worlds that load and render: 20/20", p.stdout)
        self.assertIn("lane kept by the smart car: 20/20 maps", p.stdout)


if __name__ == "__main__":
    unittest.main()
