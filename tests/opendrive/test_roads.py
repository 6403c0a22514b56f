"""The OpenDRIVE binding (_convoy_odr, src/opendrive/python) through
python/convoy_scenario/roads.py's RoadMap: each method on the hand-written map
(data/lane_graph.xodr: road a meets road b end to end, b's start is junction j with connecting
roads d and f), a road with an elevation profile, the errors, and odr.OdrQuery's replies
against the `convoy-odr query` tool run as a child process (they must be the same).

Run: cd tests/opendrive && CONVOY_BIN_DIR=/work/main/build/bin PYTHONPATH=../../python \
     /usr/bin/python3 -m unittest -v test_roads
"""

import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "python"))

from convoy_scenario.odr import OdrQuery, find_odr, world_pose  # noqa: E402
from convoy_scenario.roads import RoadMap, load_module  # noqa: E402
from convoy_scenario.xmltree import ScenarioError  # noqa: E402

MAP = os.path.join(HERE, "data", "lane_graph.xodr")
ESMINI = next((d for d in (os.path.join(REPO, "tests", "data", "esmini", "xodr"),
                           os.path.join(HERE, "data", "esmini")) if os.path.isdir(d)), None)

# A straight road along x rising 1 m in 10 (lanes 1 and -1, 3 m wide).
SLOPE_MAP = """<?xml version="1.0"?>
<OpenDRIVE>
  <header revMajor="1" revMinor="6"/>
  <road id="1" length="100" junction="-1">
    <planView><geometry s="0" x="0" y="0" hdg="0" length="100"><line/></geometry></planView>
    <elevationProfile><elevation s="0" a="0" b="0.1" c="0" d="0"/></elevationProfile>
    <lanes><laneSection s="0">
      <left><lane id="1" type="driving"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane></left>
      <center><lane id="0" type="none"/></center>
      <right><lane id="-1" type="driving"><width sOffset="0" a="3" b="0" c="0" d="0"/></lane></right>
    </laneSection></lanes>
  </road>
</OpenDRIVE>
"""


def child_replies(xodr, requests):
    """`convoy-odr query`'s replies (without "ok", or the error) to the requests."""
    lines = "".join(json.dumps(r) + "\n" for r in requests)
    out = subprocess.run([find_odr(), "query", xodr], input=lines, capture_output=True,
                         text=True, timeout=60, check=True).stdout
    replies = [json.loads(line) for line in out.splitlines()]
    for r in replies:
        r.pop("ok")
    return replies


class RoadMapTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.m = RoadMap(MAP)

    def test_roads(self):
        self.assertEqual(self.m.road_ids(), ["a", "b", "d", "f", "e", "g"])
        self.assertEqual(self.m.road_length("b"), 80.0)
        self.assertAlmostEqual(self.m.road_length("f"), 10 * math.pi)
        self.assertEqual(self.m.road_junction("a"), "-1")
        self.assertEqual(self.m.road_junction("d"), "j")
        self.assertEqual(self.m.warnings, [])

    def test_lane_pose(self):
        self.assertEqual(self.m.lane_pose("a", -1, 10.0), (10.0, -1.75, 0.0, 0.0, 0.0))
        x, y, z, h, p = self.m.lane_pose("a", -1, 10.0, 0.5)  # t: left of the reference line
        self.assertEqual((x, y), (10.0, -1.25))
        # lane 1 is driven against s: heading pi
        x, y, z, h, p = self.m.lane_pose("a", 1, 10.0)
        self.assertEqual((x, y), (10.0, 1.75))
        self.assertAlmostEqual(abs(h), math.pi)
        # b runs back from x 180 (heading pi); its lane 1 (right of x's direction) is driven
        # against s, towards +x
        x, y, z, h, p = self.m.lane_pose("b", 1, 10.0)
        self.assertAlmostEqual(x, 170.0)
        self.assertAlmostEqual(y, -1.75)
        self.assertAlmostEqual(h, 0.0)

    def test_pitch_follows_the_driving_direction(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "slope.xodr")
            with open(path, "w") as f:
                f.write(SLOPE_MAP)
            m = RoadMap(path)
        x, y, z, h, pitch = m.lane_pose("1", -1, 10.0)
        self.assertAlmostEqual(z, 1.0)
        self.assertAlmostEqual(pitch, -math.atan(0.1))  # uphill: nose up, negative
        x, y, z, h, pitch = m.lane_pose("1", 1, 10.0)
        self.assertAlmostEqual(pitch, math.atan(0.1))  # the same slope driven down
        self.assertAlmostEqual(m.road_pose("1", 20.0, 1.0)[2], 2.0)

    def test_road_pose(self):
        self.assertEqual(self.m.road_pose("a", 10.0, 2.0), (10.0, 2.0, 0.0, 0.0))
        x, y, z, h = self.m.road_pose("b", 10.0)
        self.assertAlmostEqual(x, 170.0)
        self.assertAlmostEqual(h, math.pi)

    def test_lane_info(self):
        self.assertEqual(self.m.lane_info("a", -1, 10.0), {
            "type": "driving", "width": 3.5, "s0": 0.0, "s1": 50.0, "forward": True,
            "junction": "-1", "left": 1, "right": -2, "change_left": False,
            "change_right": True, "centre_t": -1.75})
        # the second section: -2 has merged into -1
        i = self.m.lane_info("a", -1, 60.0)
        self.assertEqual((i["s0"], i["s1"], i["right"], i["change_right"]),
                         (50.0, 100.0, None, False))
        # against s, left and right swap
        i = self.m.lane_info("a", 1, 10.0)
        self.assertEqual((i["forward"], i["left"], i["right"], i["centre_t"]), (False, -1, 2, 1.75))
        # a solid line between -2 and its outer sidewalk -3
        i = self.m.lane_info("a", -2, 10.0)
        self.assertEqual((i["left"], i["right"], i["change_left"], i["change_right"]),
                         (-1, -3, True, False))
        self.assertEqual(self.m.lane_info("a", -3, 10.0)["type"], "sidewalk")
        self.assertEqual(self.m.lane_info("d", 1, 5.0)["junction"], "j")

    def test_lanes_at(self):
        self.assertEqual(self.m.lanes_at("a", 10.0), [2, 1, -1, -2, -3])
        self.assertEqual(self.m.lanes_at("a", 60.0), [1, -1])
        self.assertEqual(self.m.lanes_at("a", 1000.0), [1, -1])  # clamped to the road

    def test_next_lanes_through_the_junction(self):
        # a:-1 goes on into b:1 (b meets a end to end, so b's lane 1 is driven against s)
        self.assertEqual(self.m.next_lanes("a", -1, 60.0), [
            {"road": "b", "lane": 1, "s": 80.0, "forward": False, "junction": "-1",
             "type": "driving"}])
        self.assertEqual(self.m.next_lanes("a", -2, 10.0), [
            {"road": "a", "lane": -1, "s": 50.0, "forward": True, "junction": "-1",
             "type": "driving"}])
        # b:1 ends at junction j: connecting road d (entered at its end) and f (at its start)
        nxt = self.m.next_lanes("b", 1, 10.0)
        self.assertEqual([(n["road"], n["lane"], n["s"], n["forward"], n["junction"])
                          for n in nxt], [("d", 1, 20.0, False, "j"), ("f", -1, 0.0, True, "j")])
        self.assertEqual([(n["road"], n["lane"]) for n in self.m.next_lanes("f", -1, 5.0)],
                         [("g", -1)])
        self.assertEqual(self.m.next_lanes("g", -1, 5.0), [])  # a dead end

    def test_prev_lanes(self):
        self.assertEqual(self.m.prev_lanes("d", 1, 5.0), [
            {"road": "b", "lane": 1, "s": 0.0, "forward": False, "junction": "-1",
             "type": "driving"}])
        prev = self.m.prev_lanes("a", -1, 60.0)
        self.assertEqual([(p["road"], p["lane"], p["s"]) for p in prev],
                         [("a", -2, 50.0), ("a", -1, 50.0)])
        self.assertEqual(self.m.prev_lanes("a", -1, 10.0), [])

    def test_locate(self):
        self.assertEqual(self.m.locate(10.0, -2.0), {
            "road": "a", "lane": -1, "s": 10.0, "t": -0.25, "road_t": -2.0, "heading": 0.0,
            "z": 0.0, "distance": 0.0, "type": "driving", "junction": "-1"})
        self.assertIsNone(self.m.locate(1000.0, 0.0))
        self.assertIsNone(self.m.locate(10.0, 20.0, max_distance=5.0))
        self.assertEqual(self.m.locate(10.0, 20.0, max_distance=20.0)["lane"], 2)
        # only sidewalks: the one beside lane 1
        loc = self.m.locate(10.0, 2.0, lane_types={"sidewalk"})
        self.assertEqual((loc["lane"], loc["type"], loc["distance"]), (2, "sidewalk", 1.5))
        self.assertEqual(self.m.locate(10.0, 2.0, lane_types="driving")["lane"], 1)
        self.assertIsNone(self.m.locate(10.0, 2.0, lane_types=[]))
        # a round trip through lane_pose
        x, y, _, h, _ = self.m.lane_pose("f", -1, 12.0)
        loc = self.m.locate(x, y, h)
        self.assertEqual((loc["road"], loc["lane"]), ("f", -1))
        self.assertAlmostEqual(loc["s"], 12.0, places=6)
        self.assertAlmostEqual(loc["heading"], h, places=6)

    def test_route_and_follow_are_the_query_ops(self):
        r = self.m.route(("a", -2, 5.0), ("e", -1, 40.0), ds=10.0)
        self.assertAlmostEqual(r["length"], 235.0)
        self.assertEqual(r, self.m.query(op="route", ds=10.0, **{"from": ["a", -2, 5.0],
                                                                 "to": ["e", -1, 40.0]}))
        f = self.m.follow("a", -1, 90.0, 40.0, ds=5.0)
        self.assertEqual(f["lanes"], [["a", -1], ["b", 1]])
        self.assertEqual(len(f["points"]), 9)
        self.assertEqual(f, self.m.query(op="follow", road="a", lane=-1, s=90.0, length=40.0,
                                         ds=5.0))

    def test_query(self):
        self.assertEqual(self.m.query(op="info")["signals"], ["s1"])
        self.assertEqual(self.m.query(op="stop_lines")["stop_lines"][0]["road"], "b")
        self.assertEqual(self.m.query(op="locate", x=1000, y=0), {"found": False})

    def test_errors_name_the_file_road_and_lane(self):
        with self.assertRaisesRegex(ScenarioError, r"no road with id 'zz'"):
            self.m.lane_pose("zz", -1, 0.0)
        with self.assertRaisesRegex(ScenarioError, r"lane_graph.xodr: road a has no lane -7 "):
            self.m.lane_pose("a", -7, 0.0)
        with self.assertRaisesRegex(ScenarioError, r"road a has no lane -2 at s=60"):
            self.m.next_lanes("a", -2, 60.0)
        for call in (lambda: self.m.road_length("zz"), lambda: self.m.road_pose("zz", 1.0),
                     lambda: self.m.lanes_at("zz", 1.0), lambda: self.m.lane_info("zz", 1, 0.0)):
            with self.assertRaisesRegex(ScenarioError, r"lane_graph.xodr: no road with id 'zz'"):
                call()
        with self.assertRaisesRegex(ScenarioError, r"^lane_graph.xodr: fly: unknown op 'fly'"):
            self.m.query(op="fly")
        with self.assertRaisesRegex(ScenarioError, r"^lane_graph.xodr: pose: .*key 's' not found"):
            self.m.query(op="pose", road="a", lane=-1)
        with self.assertRaisesRegex(ScenarioError, r"no route between the two lane positions"):
            self.m.route(("g", -1, 5.0), ("a", -1, 40.0))
        with self.assertRaises(TypeError):  # arguments of the wrong type stay TypeErrors
            self.m.lane_pose("a", "-1", 0.0)

    def test_bad_maps(self):
        with self.assertRaisesRegex(ScenarioError, r"nothere.xodr: cannot open file"):
            RoadMap(os.path.join(HERE, "data", "nothere.xodr"))
        with self.assertRaisesRegex(ScenarioError, r"malformed.xodr:4: malformed XML"):
            RoadMap(os.path.join(HERE, "data", "malformed.xodr"))
        with self.assertRaisesRegex(ScenarioError, r"unknown_geometry.xodr:\d+: road"):
            RoadMap(os.path.join(HERE, "data", "unknown_geometry.xodr"))

    def test_module_found_from_convoy_bin_dir(self):
        """A fresh /usr/bin/python3 outside the repository finds the module in
        $CONVOY_BIN_DIR/../python."""
        bin_dir = os.path.dirname(find_odr())
        code = ("import sys; from convoy_scenario.roads import RoadMap, load_module; "
                "m = RoadMap(sys.argv[1]); print(load_module().__file__); "
                "print(m.lane_pose('a', -1, 10.0))")
        env = dict(os.environ, CONVOY_BIN_DIR=bin_dir, PYTHONPATH=os.path.join(REPO, "python"))
        out = subprocess.run(["/usr/bin/python3", "-c", code, MAP], cwd=tempfile.gettempdir(),
                             env=env, capture_output=True, text=True, timeout=60)
        self.assertEqual(out.returncode, 0, out.stderr)
        module_file, pose = out.stdout.splitlines()
        self.assertEqual(os.path.dirname(os.path.realpath(module_file)),
                         os.path.realpath(os.path.join(bin_dir, os.pardir, "python")))
        self.assertEqual(pose, "(10.0, -1.75, 0.0, 0.0, 0.0)")
        self.assertTrue(load_module().__file__)


class OdrQueryTest(unittest.TestCase):
    """OdrQuery (in-process now) against the convoy-odr query tool."""

    REQUESTS = [
        {"op": "pose", "road": "a", "lane": -1, "s": 10.0, "offset": 0.0},
        {"op": "pose", "road": "b", "lane": 1, "s": 33.3, "offset": -0.4},
        {"op": "pose", "road": "f", "lane": -1, "s": 7.5, "offset": 0.0},
        {"op": "locate", "x": 10.0, "y": -2.0, "yaw": None, "max_distance": 5.0},
        {"op": "locate", "x": 120.0, "y": 1.1, "yaw": 3.0, "max_distance": 5.0},
        {"op": "locate", "x": 1000.0, "y": 0.0, "yaw": None, "max_distance": 5.0},
        {"op": "follow", "road": "a", "lane": -1, "s": 90.0, "length": 150.0, "ds": 2.0},
        {"op": "route", "from": ["a", -2, 5.0], "to": ["e", -1, 40.0], "ds": 3.0},
        {"op": "info"},
        {"op": "stop_lines"},
    ]

    def test_replies_equal_the_tools(self):
        with OdrQuery(MAP) as odr:
            mine = [odr.ask(**r) for r in self.REQUESTS]
        self.assertEqual(mine, child_replies(MAP, self.REQUESTS))

    def test_methods_equal_the_tools_replies(self):
        want = child_replies(MAP, self.REQUESTS)
        with OdrQuery(MAP) as odr:
            for req, rep in zip(self.REQUESTS[:3], want[:3]):
                self.assertEqual(odr.pose(req["road"], req["lane"], req["s"], req["offset"]),
                                 (rep["x"], rep["y"], rep["heading"]))
            for req, rep in zip(self.REQUESTS[3:6], want[3:6]):
                got = odr.locate(req["x"], req["y"], req["yaw"], req["max_distance"])
                self.assertEqual(got, rep if rep["found"] else None)
            self.assertEqual(odr.follow("a", -1, 90, 150), want[6])
            self.assertEqual(odr.route(("a", -2, 5), ("e", -1, 40), ds=3), want[7])
            self.assertEqual(odr.info(), want[8])
            self.assertEqual(world_pose(odr, {"type": "lane", "road": "a", "lane": -1, "s": 10.0}),
                             (10.0, -1.75, 0.0))
        with self.assertRaisesRegex(ScenarioError, "closed"):
            odr.ask(op="info")

    def test_errors_as_before(self):
        bad = {"op": "pose", "road": "zz", "lane": -1, "s": 0.0, "offset": 0.0}
        with OdrQuery(MAP) as odr:
            with self.assertRaises(ScenarioError) as e:
                odr.ask(**bad)
        # the child's message, prefixed as OdrQuery always did
        self.assertEqual(str(e.exception),
                         "lane_graph.xodr: pose: " + child_replies(MAP, [bad])[0]["error"])
        with self.assertRaisesRegex(ScenarioError, "malformed.xodr:4"):
            OdrQuery(os.path.join(HERE, "data", "malformed.xodr"))

    @unittest.skipUnless(ESMINI, "esmini's maps are not there")
    def test_esmini_maps_equal_the_tools(self):
        for name in ("fabriksgatan.xodr", "multi_intersections.xodr", "curves_elevation.xodr"):
            xodr = os.path.join(ESMINI, name)
            if not os.path.exists(xodr):
                continue
            m = RoadMap(xodr)
            requests = [{"op": "info"}]
            for road in m.road_ids()[:12]:
                length = m.road_length(road)
                for lane in m.lanes_at(road, 0.5 * length):
                    requests.append({"op": "pose", "road": road, "lane": lane,
                                     "s": 0.37 * length, "offset": 0.2})
                    x, y, _, h, _ = m.lane_pose(road, lane, 0.61 * length)
                    requests.append({"op": "locate", "x": x + 0.3, "y": y - 0.2, "yaw": h})
                    if m.lane_info(road, lane, 0.5 * length)["type"] == "driving":
                        requests.append({"op": "follow", "road": road, "lane": lane,
                                         "s": 0.5 * length, "length": 120.0})
            with self.subTest(map=name), OdrQuery(xodr) as odr:
                self.assertEqual([odr.ask(**r) for r in requests], child_replies(xodr, requests))
                # next_lanes is the lane graph's successors, which follow walks
                for road in m.road_ids():
                    for lane in m.lanes_at(road, 0.0):
                        for n in m.next_lanes(road, lane, 0.0):
                            self.assertIn(n["lane"], m.lanes_at(n["road"], n["s"]))


if __name__ == "__main__":
    unittest.main()
