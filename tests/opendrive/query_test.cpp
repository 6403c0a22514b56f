// The JSON lane lookups (opendrive/query.h) that `convoy-odr query` and Python's RoadMap.query
// answer: each op on the hand-written map (data/lane_graph.xodr) and the errors.
#include "opendrive/query.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "opendrive/parser.h"

namespace convoy::opendrive {
namespace {

using ::testing::HasSubstr;
using json = nlohmann::json;

const LaneGraph& graph() {
  static const Network net = load(std::string(CONVOY_OPENDRIVE_TEST_DATA) + "/lane_graph.xodr");
  static const LaneGraph g(net);
  return g;
}

std::string error_of(const json& request) {
  try {
    query(graph(), request);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(OdrQuery, PoseInTheDrivingDirection) {
  const json r = query(graph(), {{"op", "pose"}, {"road", "a"}, {"lane", -1}, {"s", 10.0}});
  EXPECT_DOUBLE_EQ(r["x"], 10);
  EXPECT_DOUBLE_EQ(r["y"], -1.75);
  EXPECT_DOUBLE_EQ(r["z"], 0);
  EXPECT_DOUBLE_EQ(r["heading"], 0);
  // Lane 1 of a is driven against s; offset is OpenDRIVE t (left of the reference line).
  const json b =
      query(graph(), {{"op", "pose"}, {"road", "a"}, {"lane", 1}, {"s", 10}, {"offset", 0.5}});
  EXPECT_DOUBLE_EQ(b["y"], 2.25);
  EXPECT_NEAR(std::abs(b["heading"].get<double>()), std::numbers::pi, 1e-12);
}

TEST(OdrQuery, LocateFindsTheLaneOrSaysNotFound) {
  const json r = query(graph(), {{"op", "locate"}, {"x", 10}, {"y", -2}, {"yaw", 0.1}});
  EXPECT_TRUE(r["found"]);
  EXPECT_EQ(r["road"], "a");
  EXPECT_EQ(r["lane"], -1);
  EXPECT_DOUBLE_EQ(r["s"], 10);
  EXPECT_DOUBLE_EQ(r["t"], -0.25);
  EXPECT_DOUBLE_EQ(r["road_t"], -2);
  EXPECT_EQ(r["type"], "driving");
  EXPECT_EQ(r["junction"], "-1");
  EXPECT_EQ(query(graph(), {{"op", "locate"}, {"x", 1000}, {"y", 0}}), json({{"found", false}}));
  // yaw null is no yaw
  EXPECT_EQ(query(graph(), {{"op", "locate"}, {"x", 10}, {"y", -2}, {"yaw", nullptr}})["lane"], -1);
}

TEST(OdrQuery, FollowGoesOnAcrossRoads) {
  const json r =
      query(graph(),
            {{"op", "follow"}, {"road", "a"}, {"lane", -1}, {"s", 90}, {"length", 40}, {"ds", 5}});
  EXPECT_DOUBLE_EQ(r["length"], 40);
  EXPECT_EQ(r["lanes"], json::parse(R"([["a", -1], ["b", 1]])"));
  ASSERT_EQ(r["points"].size(), 9u);
  EXPECT_NEAR(r["points"].back()[0].get<double>(), 130, 1e-9);
}

TEST(OdrQuery, RouteThroughTheJunction) {
  const json r =
      query(graph(), {{"op", "route"}, {"from", {"a", -2, 5}}, {"to", {"e", -1, 40}}, {"ds", 10}});
  EXPECT_NEAR(r["length"].get<double>(), 235, 1e-9);
  EXPECT_NEAR(r["points"].back()[0].get<double>(), 240, 1e-9);
  EXPECT_THAT(error_of({{"op", "route"}, {"from", {"g", -1, 5}}, {"to", {"a", -1, 40}}}),
              HasSubstr("no route between the two lane positions"));
}

TEST(OdrQuery, InfoAndStopLines) {
  const json info = query(graph(), {{"op", "info"}});
  ASSERT_EQ(info["roads"].size(), 6u);
  EXPECT_EQ(info["roads"][2], json({{"id", "d"}, {"length", 20.0}, {"junction", "j"}}));
  EXPECT_EQ(info["signals"], json::array({"s1"}));
  const json lines = query(graph(), {{"op", "stop_lines"}})["stop_lines"];
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_EQ(lines[0]["road"], "b");
  EXPECT_DOUBLE_EQ(lines[0]["x"], 175);
  EXPECT_DOUBLE_EQ(lines[0]["t_min"], -3.5);
  EXPECT_DOUBLE_EQ(lines[0]["entry_x"], 180);
}

TEST(OdrQuery, ErrorsNameTheRoadLaneOrField) {
  EXPECT_THAT(error_of({{"op", "pose"}, {"road", "zz"}, {"lane", -1}, {"s", 0}}),
              HasSubstr("no road with id 'zz'"));
  EXPECT_THAT(error_of({{"op", "pose"}, {"road", "a"}, {"lane", -7}, {"s", 0}}),
              HasSubstr("road a has no lane -7"));
  EXPECT_THAT(error_of({{"op", "pose"}, {"road", "a"}, {"lane", -1}}), HasSubstr("'s'"));
  EXPECT_THAT(error_of({{"op", "fly"}}), HasSubstr("unknown op 'fly'"));
  EXPECT_THAT(error_of({{"op", "follow"}, {"road", "a"}, {"lane", -1}, {"s", 0}, {"length", 0}}),
              HasSubstr("length and ds must be > 0"));
}

}  // namespace
}  // namespace convoy::opendrive
