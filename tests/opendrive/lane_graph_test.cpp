// The lane graph: connectivity across lane sections, road links (both contact points) and
// junction connections, lane changes, routes, (s, t) <-> world, speed limits, crosswalks,
// sidewalks and signals; on a hand-written map (data/lane_graph.xodr), the city map and the
// Parkring.
#include "opendrive/lane_graph.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "opendrive/parser.h"

namespace convoy::opendrive {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

const std::string kData = CONVOY_OPENDRIVE_TEST_DATA;

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

const Network& test_net() {
  static const Network net = load(kData + "/lane_graph.xodr");
  return net;
}
const LaneGraph& test_graph() {
  static const LaneGraph graph(test_net());
  return graph;
}
const Network& city_net() {
  static const Network net = load(CONVOY_CITY_XODR);
  return net;
}
const LaneGraph& city_graph() {
  static const LaneGraph graph(city_net());
  return graph;
}

std::vector<LaneIndex> sorted(std::vector<LaneIndex> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// "road:lane" of each segment, with "+" for a segment entered by a lane change.
std::vector<std::string> lanes_of(const LaneRoute& r) {
  std::vector<std::string> out;
  for (const RouteSegment& g : r.segments) {
    out.push_back(std::string(g.lane_change ? "+" : "") + g.road_id + ":" +
                  std::to_string(g.lane_id));
  }
  return out;
}

TEST(LaneGraph, NodesPerLaneSectionWithDirections) {
  const LaneGraph& g = test_graph();
  // a: 5 + 2 lanes, b 2, d 1, f 1, e 3, g 2.
  EXPECT_EQ(g.lanes().size(), 16u);
  const LaneNode& a1 = g.lane(g.require("a", -1, 10));
  EXPECT_TRUE(a1.forward);
  EXPECT_EQ(a1.section, 0u);
  EXPECT_NEAR(a1.length, 50, 1e-9);
  EXPECT_FALSE(g.lane(g.require("a", 1, 10)).forward);
  EXPECT_EQ(g.lane(g.require("d", 1, 5)).junction, "j");
  EXPECT_EQ(g.find("a", -2, 60), kNoLane);  // lane -2 ends with the first section
  EXPECT_EQ(g.find("nope", -1, 0), kNoLane);
  EXPECT_THAT([&] { g.require("a", -5, 0); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  AllOf(HasSubstr("lane_graph.xodr"), HasSubstr("road a has no lane -5"))));
}

TEST(LaneGraph, SuccessorsAcrossSectionsRoadsAndJunctions) {
  const LaneGraph& g = test_graph();
  // Lane sections: -1 continues as -1 (no link), -2 merges into -1 (explicit link).
  const LaneIndex a1_end = g.require("a", -1, 60);
  EXPECT_THAT(g.successors(g.require("a", -1, 10)), ElementsAre(a1_end));
  EXPECT_THAT(g.successors(g.require("a", -2, 10)), ElementsAre(a1_end));
  // End meets end (contactPoint end, no lane link): lane -1 of a continues as lane 1 of b.
  EXPECT_THAT(g.successors(a1_end), ElementsAre(g.require("b", 1, 40)));
  // Junction: b lane 1 into d (contactPoint end, driven against s) and f (contactPoint start).
  const auto next = g.successors(g.require("b", 1, 40));
  EXPECT_EQ(sorted(next), sorted({g.require("d", 1, 5), g.require("f", -1, 5)}));
  EXPECT_THAT(g.successors(g.require("d", 1, 5)), ElementsAre(g.require("e", -1, 5)));
  EXPECT_THAT(g.successors(g.require("f", -1, 5)), ElementsAre(g.require("g", -1, 5)));
  EXPECT_THAT(g.predecessors(g.require("e", -1, 5)), ElementsAre(g.require("d", 1, 5)));
  // Lanes driven the other way do not follow on.
  EXPECT_TRUE(g.successors(g.require("e", 1, 5)).empty());
  EXPECT_TRUE(g.warnings().empty());
}

TEST(LaneGraph, RoutesThroughJunctionsWithBothContactPoints) {
  const LaneGraph& g = test_graph();
  const auto r = g.route("a", -2, "e", -1);
  ASSERT_TRUE(r);
  EXPECT_THAT(lanes_of(*r), ElementsAre("a:-2", "a:-1", "b:1", "d:1", "e:-1"));
  EXPECT_THAT(r->junctions, ElementsAre("j"));
  EXPECT_NEAR(r->length, 100 + 80 + 20 + 50, 1e-6);
  EXPECT_EQ(r->segments[3].s_from, 20);  // d against its s
  EXPECT_EQ(r->segments[3].s_to, 0);
  const auto r2 = g.route("a", -1, "g", -1);
  ASSERT_TRUE(r2);
  EXPECT_THAT(lanes_of(*r2), ElementsAre("a:-1", "a:-1", "b:1", "f:-1", "g:-1"));
  // The arc: lane -1 is 1.75 m inside a right turn of radius 20 m (quarter circle).
  EXPECT_NEAR(r2->length, 100 + 80 + 18.25 * std::numbers::pi / 2 + 50, 0.02);
  // Sampled poses run continuously from start to end.
  const std::vector<Pose2> pts = g.sample(*r2, 1.0);
  ASSERT_GT(pts.size(), 250u);
  EXPECT_NEAR(pts.front().x, 0, 1e-9);
  EXPECT_NEAR(pts.front().y, -1.75, 1e-9);
  EXPECT_NEAR(pts.back().x, 200 - 1.75, 1e-6);
  EXPECT_NEAR(pts.back().y, -70, 1e-6);
  EXPECT_NEAR(pts.back().heading, -std::numbers::pi / 2, 1e-3);
  for (size_t i = 1; i < pts.size(); ++i) {
    EXPECT_LE(std::hypot(pts[i].x - pts[i - 1].x, pts[i].y - pts[i - 1].y), 1.0 + 1e-6);
  }
}

TEST(LaneGraph, NoRoute) {
  const LaneGraph& g = test_graph();
  EXPECT_FALSE(g.route("g", -1, "a", -1));  // g is a dead end
  EXPECT_FALSE(g.route("e", 1, "g", -1));   // nothing leads from e into the junction
  EXPECT_THAT([&] { (void)g.route("zz", -1, "a", -1); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("no road with id 'zz'")));
}

TEST(LaneGraph, LaneChanges) {
  const LaneGraph& g = test_graph();
  const LaneNode& a2 = g.lane(g.require("a", -2, 10));
  EXPECT_EQ(a2.left(), g.require("a", -1, 10));   // under RHT, left = towards the centre
  EXPECT_EQ(a2.right(), g.require("a", -3, 10));  // the sidewalk: a neighbour, not for routes
  EXPECT_TRUE(a2.change_left());                  // broken line between -1 and -2
  EXPECT_FALSE(g.lane(g.require("a", -1, 10)).change_left());  // solid centre line
  // From lane -2 to the end of lane -1's first section: one change to the left.
  const LaneIndex from = g.require("a", -2, 0), to = g.require("a", -1, 10);
  const auto r = g.route(from, 0, to, 50);
  ASSERT_TRUE(r);
  EXPECT_THAT(lanes_of(*r), ElementsAre("a:-2", "+a:-1"));
  EXPECT_EQ(r->lane_changes, 1);
  EXPECT_EQ(r->segments[1].change_direction, 1);
  EXPECT_NEAR(r->segments[0].s_to, 25, 1e-9);
  RouteOptions no_changes;
  no_changes.lane_changes = false;
  EXPECT_FALSE(g.route(from, 0, to, 50, no_changes));
  // Sampling blends across: starts on -2's centre, ends on -1's.
  const auto pts = g.sample(*r, 0.5);
  EXPECT_NEAR(pts.front().y, -5.25, 1e-9);
  EXPECT_NEAR(pts.back().y, -1.75, 1e-9);
  EXPECT_NEAR(pts[pts.size() / 2].y, -3.5, 0.1);
}

TEST(LaneGraph, PedestrianRoutesOnSidewalksEitherWay) {
  const LaneGraph& g = test_graph();
  RouteOptions walk;
  walk.lane_types = {"sidewalk"};
  walk.both_directions = true;
  const LaneIndex sw = g.require("a", -3, 0);
  const auto back = g.route(sw, 40, sw, 10, walk);  // against the lane's driving direction
  ASSERT_TRUE(back);
  ASSERT_EQ(back->segments.size(), 1u);
  EXPECT_EQ(back->segments[0].s_from, 40);
  EXPECT_EQ(back->segments[0].s_to, 10);
  EXPECT_NEAR(back->length, 30, 1e-9);
  EXPECT_FALSE(g.route(sw, 40, sw, 10));  // not for a driver (and not a driving lane)
  EXPECT_FALSE(g.route(sw, 10, g.require("e", -2, 0), 5, walk));  // sidewalks not joined
}

TEST(LaneGraph, LeftHandTraffic) {
  std::string xml = read(kData + "/lane_graph.xodr");
  const std::string from = "<road id=\"a\" length=\"100\" junction=\"-1\">";
  xml.replace(xml.find(from), from.size(),
              "<road id=\"a\" length=\"100\" junction=\"-1\" rule=\"LHT\">");
  const Network net = parse(xml, "lht.xodr");
  const LaneGraph g(net);
  EXPECT_FALSE(g.lane(g.require("a", -1, 10)).forward);
  EXPECT_TRUE(g.lane(g.require("a", 1, 10)).forward);
  // Under LHT the left neighbour of lane -1 (driven against s) is lane -2.
  EXPECT_EQ(g.lane(g.require("a", -1, 10)).left(), g.require("a", -2, 10));
}

TEST(LaneGraph, WorldPoseAndLocateRoundTrip) {
  const LaneGraph& g = test_graph();
  const WorldPose p = g.world_pose("e", -1, 20, 0.3);
  EXPECT_NEAR(p.x, 220, 1e-12);
  EXPECT_NEAR(p.y, -1.75 + 0.3, 1e-12);
  struct Case {
    std::string road;
    int lane;
    double s, t;
  };
  for (const Case& c : {Case{"e", -1, 20, 0.3}, Case{"f", -1, 10, -0.5}, Case{"a", 1, 70, 1.0},
                        Case{"g", 1, 33.3, -1.2}, Case{"a", -2, 12.5, 0}}) {
    const WorldPose w = g.world_pose(c.road, c.lane, c.s, c.t);
    const auto back = g.locate(w.x, w.y, w.heading);
    ASSERT_TRUE(back) << c.road;
    EXPECT_EQ(back->road_id, c.road);
    EXPECT_EQ(back->lane_id, c.lane);
    EXPECT_NEAR(back->s, c.s, 1e-3) << c.road;
    EXPECT_NEAR(back->t, c.t, 1e-3) << c.road;
    EXPECT_NEAR(back->distance, 0, 1e-12);
  }
  EXPECT_NEAR(g.locate(220, -1.45)->road_t, -1.45, 1e-12);  // from the reference line
  EXPECT_FALSE(g.locate(100, 100));                         // far from every road
  const auto off = g.locate(25, 9);  // 1 m beyond a's left sidewalk (5.5 m wide side)
  ASSERT_TRUE(off);
  EXPECT_EQ(off->lane_id, 2);
  EXPECT_NEAR(off->distance, 3.5, 1e-9);
}

TEST(LaneGraph, LocateIfFiltersTheLanes) {
  const LaneGraph& g = test_graph();
  // A point on a's lane -1: without a filter that lane; with one accepting only lanes driven
  // within 60 degrees of heading pi (the other way), the nearest such lane, a's lane 1.
  const WorldPose w = g.world_pose("a", -1, 20, 0);
  const auto any = g.locate(w.x, w.y);
  ASSERT_TRUE(any);
  EXPECT_EQ(any->lane_id, -1);
  const double back = w.heading + 3.141592653589793;
  const auto other = g.locate_if(w.x, w.y, back, 20.0, [&](const LaneNode& n, double h) {
    return n.drivable() && std::abs(std::remainder(h - back, 2 * 3.141592653589793)) < 1.05;
  });
  ASSERT_TRUE(other);
  EXPECT_EQ(other->road_id, "a");
  EXPECT_EQ(other->lane_id, 1);
  EXPECT_GT(other->distance, 0.0);
  // Sidewalks only.
  const auto walk = g.locate_if(w.x, w.y, std::nullopt, 20.0,
                                [](const LaneNode& n, double) { return n.type == "sidewalk"; });
  ASSERT_TRUE(walk);
  EXPECT_EQ(g.lane(walk->lane).type, "sidewalk");
  // Nothing accepted: none.
  EXPECT_FALSE(
      g.locate_if(w.x, w.y, std::nullopt, 20.0, [](const LaneNode&, double) { return false; }));
}

TEST(LaneGraph, SpeedLimitsCrosswalksSidewalksSignals) {
  const LaneGraph& g = test_graph();
  EXPECT_NEAR(g.speed_limit(g.require("a", -1, 10), 10).mps, 50 / 3.6, 1e-12);
  EXPECT_NEAR(g.speed_limit(g.require("b", 1, 10), 10).mps, 20, 1e-12);
  EXPECT_FALSE(g.speed_limit(g.require("e", -1, 10), 10).known);
  ASSERT_EQ(g.crosswalks().size(), 1u);
  const Crosswalk& cw = g.crosswalks()[0];
  EXPECT_EQ(cw.road_id, "e");
  ASSERT_EQ(cw.polygon.size(), 4u);
  EXPECT_NEAR(cw.polygon[0][0], 208, 1e-12);
  EXPECT_NEAR(cw.polygon[0][1], -3.5, 1e-12);
  EXPECT_EQ(sorted(cw.lanes), sorted({g.require("e", 1, 10), g.require("e", -1, 10)}));
  EXPECT_EQ(cw.ends[0], g.require("e", -2, 10));  // the sidewalk on the right
  EXPECT_EQ(cw.ends[1], kNoLane);                 // none on the left
  EXPECT_EQ(sorted(g.sidewalks()),
            sorted({g.require("a", 2, 0), g.require("a", -3, 0), g.require("e", -2, 0)}));
  ASSERT_EQ(g.signals().size(), 1u);
  const SignalInfo& s = g.signals()[0];
  EXPECT_TRUE(s.traffic_light);
  EXPECT_EQ(s.road_id, "b");
  EXPECT_THAT(s.lanes, ElementsAre(g.require("b", 1, 5)));
  EXPECT_THAT(s.controllers, ElementsAre("c1"));
  EXPECT_EQ(s.junction, "j");
  EXPECT_NEAR(s.pose.x, 175, 1e-9);
  EXPECT_NEAR(s.pose.y, -5.5, 1e-9);
  EXPECT_NEAR(s.pose.z, 2.5, 1e-12);
  EXPECT_EQ(g.junction_signals("j").size(), 1u);
}

TEST(LaneGraph, BadJunctionNamesTheConnection) {
  std::string xml = read(kData + "/lane_graph.xodr");
  const std::string from = "connectingRoad=\"f\"";
  xml.replace(xml.find(from), from.size(), "connectingRoad=\"missing\"");
  const Network net = parse(xml, "bad.xodr");
  EXPECT_THAT([&] { LaneGraph g(net); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  AllOf(HasSubstr("bad.xodr"), HasSubstr("junction j connection 1"),
                        HasSubstr("connectingRoad 'missing' does not exist"))));
  std::string xml2 = read(kData + "/lane_graph.xodr");
  const std::string link = "<predecessor elementType=\"junction\" elementId=\"j\"/>";
  xml2.replace(xml2.find(link), link.size(),
               "<predecessor elementType=\"junction\" elementId=\"k\"/>");
  const Network net2 = parse(xml2, "bad2.xodr");
  EXPECT_THAT([&] { LaneGraph g(net2); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr("bad2.xodr: road b predecessor: junction 'k' does not exist")));
}

TEST(CityMap, RoutesThroughBothJunctionsBothWays) {
  const LaneGraph& g = city_graph();
  for (const auto& [from, to, lane] : {std::tuple{"1", "3", -1}, std::tuple{"3", "1", 1},
                                       std::tuple{"1", "3", -2}, std::tuple{"3", "1", 2}}) {
    const auto r = g.route(from, lane, to, lane);
    ASSERT_TRUE(r) << from << " -> " << to;
    EXPECT_EQ(r->junctions.size(), 2u);
    EXPECT_EQ(r->lane_changes, 0);
    EXPECT_NEAR(r->length, 700, 1e-6);
  }
  // Side road to side road: both junctions, turning, with a lane change on the main road.
  const auto r = g.route("5", -1, "6", -1);
  ASSERT_TRUE(r);
  EXPECT_THAT(r->junctions, ElementsAre("100", "200"));
  EXPECT_EQ(r->lane_changes, 1);
  const auto back = g.route("7", -1, "4", -1);  // north on 7, west, north into 4's curve
  ASSERT_TRUE(back);
  EXPECT_THAT(back->junctions, ElementsAre("200", "100"));
}

TEST(CityMap, LightsCrosswalksSidewalksAndSpeeds) {
  const LaneGraph& g = city_graph();
  for (const char* j : {"100", "200"}) {
    const auto lights = g.junction_signals(j);
    EXPECT_EQ(lights.size(), 4u) << j;
    for (const SignalInfo* s : lights) {
      EXPECT_TRUE(s->traffic_light);
      EXPECT_FALSE(s->lanes.empty());
    }
  }
  EXPECT_EQ(g.crosswalks().size(), 8u);
  for (const Crosswalk& cw : g.crosswalks()) {  // sidewalk to sidewalk across the carriageway
    ASSERT_NE(cw.ends[0], kNoLane);
    ASSERT_NE(cw.ends[1], kNoLane);
    EXPECT_EQ(g.lane(cw.ends[0]).type, "sidewalk");
    EXPECT_EQ(g.lane(cw.ends[1]).type, "sidewalk");
    EXPECT_EQ(g.lane(cw.ends[0]).lane_id, -g.lane(cw.ends[1]).lane_id);
  }
  EXPECT_EQ(g.sidewalks().size(), 22u);  // 7 roads, one each side, and 4 corners a junction
  // A pedestrian walks from the main road's south sidewalk round the corner of junction 100
  // into the south arm's west sidewalk (against that lane's s).
  RouteOptions walk;
  walk.lane_types = {"sidewalk"};
  walk.both_directions = true;
  const auto r = g.route(g.require("1", -3, 100), 100, g.require("5", 2, 50), 50, walk);
  ASSERT_TRUE(r);
  EXPECT_THAT(r->junctions, ElementsAre("100"));
  ASSERT_EQ(r->segments.size(), 3u);
  EXPECT_EQ(r->segments.back().s_to, 50);
  EXPECT_NEAR(g.speed_limit(g.require("1", -1, 5), 5).mps, 50 / 3.6, 1e-12);
  EXPECT_NEAR(g.speed_limit(g.require("4", -1, 5), 5).mps, 30 / 3.6, 1e-12);
  EXPECT_TRUE(g.warnings().empty());
  // Round trip on the curved road 4 and on a junction's paramPoly3 turn.
  for (const auto& [road, lane, s, t] :
       {std::tuple{"4", -1, 85.0, 0.4}, std::tuple{"4", 1, 100.0, -0.2},
        std::tuple{"1012", -1, 9.0, 0.1}}) {
    const WorldPose w = g.world_pose(road, lane, s, t);
    const auto back = g.locate(w.x, w.y, w.heading);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->road_id, road);
    EXPECT_EQ(back->lane_id, lane);
    EXPECT_NEAR(back->s, s, 1e-3);
    EXPECT_NEAR(back->t, t, 1e-3);
  }
}

TEST(ParkringLaneGraph, RouteAroundTheRingAndRoundTripOnSpirals) {
  const Network net = load(CONVOY_PARKRING_XODR);
  const LaneGraph g(net);
  const auto r = g.route("1", -1, "4", -1);
  ASSERT_TRUE(r);
  EXPECT_THAT(lanes_of(*r), ElementsAre("1:-1", "2:-1", "3:-1", "4:-1"));
  // The opposite lane runs the ring the other way: 1 -> 4 -> 3 -> 2.
  const auto back = g.route("1", 1, "2", 1);
  ASSERT_TRUE(back);
  EXPECT_THAT(lanes_of(*back), ElementsAre("1:1", "4:1", "3:1", "2:1"));
  for (const Road& road : net.roads) {
    for (int i = 1; i < 20; ++i) {
      const double s = road.length * i / 20;
      const WorldPose w = g.world_pose(road.id, -1, s, 0.7);
      const auto loc = g.locate(w.x, w.y, w.heading);
      ASSERT_TRUE(loc);
      EXPECT_EQ(loc->road_id, road.id);
      EXPECT_EQ(loc->lane_id, -1);
      EXPECT_NEAR(loc->s, s, 1e-3);
      EXPECT_NEAR(loc->t, 0.7, 1e-3);
    }
  }
}

}  // namespace
}  // namespace convoy::opendrive
