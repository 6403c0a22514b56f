"""convoy-odr route over the lane graph, and the city map generator (make_city.py).

Runs the built convoy-odr on tests/opendrive/data/lane_graph.xodr and on the city map: a route
through a junction, the exit status 2 with a message naming what is missing (lane, route, a
junction's road), and that make_city.py writes the committed city.xodr byte for byte, which
SUMO's netconvert (when installed) converts keeping both junctions' traffic lights.
"""

import os
import shutil
import subprocess
import tempfile
import unittest

from e2e_util import BIN_DIR, REPO

ODR = os.path.join(BIN_DIR, "convoy-odr")
DATA = os.path.join(REPO, "tests", "opendrive", "data", "lane_graph.xodr")
CITY = os.path.join(REPO, "experiments", "city_traffic", "city.xodr")
MAKE_CITY = os.path.join(REPO, "tools", "opendrive", "make_city.py")


def run(*args):
    return subprocess.run([ODR, *args], capture_output=True, text=True, timeout=60)


class Route(unittest.TestCase):
    def test_route_through_a_junction(self):
        r = run("route", DATA, "--from", "a:-2", "--to", "e:-1")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("route a:-2 -> e:-1: 250.000 m", r.stdout)
        self.assertIn("junctions: j", r.stdout)
        self.assertIn("road d lane 1 s 20.000 -> 0.000 (junction j)", r.stdout)

    def test_waypoints_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "route.csv")
            r = run("route", CITY, "--from", "5:-1", "--to", "6:-1", "--ds", "1", "--out", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("junctions: 100, 200", r.stdout)
            with open(out) as f:
                lines = f.read().splitlines()
            self.assertEqual(lines[0], "x,y,heading")
            self.assertGreater(len(lines), 480)

    def test_missing_lane_exits_2(self):
        r = run("route", DATA, "--from", "a:-5", "--to", "e:-1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--from", r.stderr)
        self.assertIn("road a has no lane -5", r.stderr)
        r = run("route", DATA, "--from", "a:-1", "--to", "nowhere:1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--to", r.stderr)
        self.assertIn("no road with id 'nowhere'", r.stderr)

    def test_no_route_exits_2(self):
        r = run("route", DATA, "--from", "g:-1", "--to", "a:-1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("no route from road g lane -1 to road a lane -1", r.stderr)

    def test_bad_junction_exits_2(self):
        with open(DATA) as f:
            xml = f.read().replace('connectingRoad="f"', 'connectingRoad="missing"')
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "bad.xodr")
            with open(path, "w") as f:
                f.write(xml)
            r = run("route", path, "--from", "a:-1", "--to", "e:-1")
        self.assertEqual(r.returncode, 2)
        self.assertEqual(len(r.stderr.strip().splitlines()), 1, r.stderr)
        self.assertIn("junction j connection 1: connectingRoad 'missing' does not exist", r.stderr)

    def test_bad_arguments_exit_2(self):
        r = run("route", DATA, "--from", "a", "--to", "e:-1")
        self.assertEqual(r.returncode, 2)
        self.assertIn("--from must be ROAD:LANE", r.stderr)


class CityMap(unittest.TestCase):
    def test_generator_is_deterministic_and_matches_the_committed_map(self):
        with tempfile.TemporaryDirectory() as tmp:
            a, b = os.path.join(tmp, "a.xodr"), os.path.join(tmp, "b.xodr")
            for path in (a, b):
                subprocess.run(["/usr/bin/python3", MAKE_CITY, path], check=True,
                               capture_output=True, timeout=60)
            with open(a, "rb") as fa, open(b, "rb") as fb, open(CITY, "rb") as fc:
                data = fa.read()
                self.assertEqual(data, fb.read())
                self.assertEqual(data, fc.read(), "city.xodr is stale: rerun make_city.py")

    def test_routes_both_ways_through_both_junctions(self):
        for frm, to in (("1:-1", "3:-1"), ("3:1", "1:1"), ("1:-2", "3:-2")):
            r = run("route", CITY, "--from", frm, "--to", to)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertTrue("junctions: 100, 200" in r.stdout or "junctions: 200, 100" in r.stdout,
                            r.stdout)

    def test_netconvert_keeps_the_traffic_lights(self):
        netconvert = shutil.which("netconvert")
        if not netconvert:
            self.skipTest("netconvert (Debian package sumo) not installed")
        env = dict(os.environ)
        env.setdefault("SUMO_HOME", "/usr/share/sumo")
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "city.net.xml")
            r = subprocess.run([netconvert, "--opendrive-files", CITY, "-o", out],
                               capture_output=True, text=True, timeout=120, env=env)
            self.assertEqual(r.returncode, 0, r.stderr)
            with open(out) as f:
                net = f.read()
        self.assertEqual(net.count("<tlLogic "), 2)
        self.assertIn('<tlLogic id="100"', net)
        self.assertIn('<tlLogic id="200"', net)


if __name__ == "__main__":
    unittest.main()
