// The pedestrian's command contract: each part accepted into its value, and each kind of bad
// value rejected with its message (the key, then what is wrong), on the lane graph of
// tests/opendrive/data/lane_graph.xodr.
#include "road_users/pedestrian_command.h"

#include <gtest/gtest.h>

#include <string>

#include "test_map.h"

namespace convoy::road_users {
namespace {

using nlohmann::json;

using testing::map;

PedestrianCommand parse(const json& j) {
  return parse_pedestrian_command(j, "command", map().graph);
}

// The message a command is rejected with ("accepted" if it is not).
std::string error_of(const json& j) { return testing::rejection(parse, j); }

TEST(PedestrianCommand, NothingIsNoPart) {
  const PedestrianCommand c = parse(json::parse(R"({"time_ns": 100})"));
  EXPECT_FALSE(c.speed || c.route || c.timed || c.polyline || c.teleport);
  EXPECT_EQ(error_of(json::parse("3")), "command: expected a JSON object of commands, got 3");
  EXPECT_EQ(error_of(json::parse(R"({"time_ns": "x"})")),
            "command.time_ns: expected a number (ns)");
  EXPECT_EQ(error_of(json::parse(R"({"brake": 1})")),
            "command.brake: unknown key (time_ns, speed, route, trajectory, teleport)");
}

TEST(PedestrianCommand, Speed) {
  const PedestrianCommand c =
      parse(json::parse(R"({"speed": {"speed": 1.5, "target_speed": 2, "acceleration": 1}})"));
  ASSERT_TRUE(c.speed);
  EXPECT_EQ(*c.speed, 1.5);
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": -1}})")),
            "command.speed.speed: must be >= 0 m/s");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {}})")), "command.speed.speed: missing (a number)");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": 1, "acceleration": "x"}})")),
            "command.speed.acceleration: expected a number, got \"x\"");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": 1, "jerk": 0}})")),
            "command.speed.jerk: unknown key (speed, target_speed, acceleration)");
}

TEST(PedestrianCommand, LaneIsAnError) {
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1}})")),
            "command.lane: a pedestrian has no lane to change to (a pedestrian_agent takes speed, "
            "route, trajectory and teleport)");
}

TEST(PedestrianCommand, Route) {
  // One position is a route; [x, y, z] drops z.
  const auto route = parse(json::parse(R"({"route": {"positions": [[240, -1.75, 0]]}})")).route;
  EXPECT_EQ(route, (Points{{240, -1.75}}));
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": []}})")),
            "command.route.positions: expected a list of points [x, y], got []");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": [[1, 2, 3, 4]]}})")),
            "command.route.positions[0]: expected a point [x, y] (or [x, y, z]), got [1,2,3,4]");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": [[50, -1.75], [50, 500]]}})")),
            "command.route.positions[1]: (50.00, 500.00) is farther than 20 m from any lane of " +
                map().net.source);
}

TEST(PedestrianCommand, Trajectory) {
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"x": 1, "y": 2, "yaw": 0.5}})")),
            "command.trajectory.speed: missing (a number)");
  PedestrianCommand c =
      parse(json::parse(R"({"trajectory": {"x": 1, "y": 2, "z": 0, "yaw": 0.5, "speed": 1}})"));
  ASSERT_TRUE(c.timed);
  EXPECT_EQ(c.timed->x, 1);
  EXPECT_EQ(c.timed->yaw, 0.5);
  EXPECT_EQ(*c.timed->speed, 1);
  c = parse(json::parse(R"({"trajectory": {"polyline": [[0, 0], [3, 4]], "length": 5}})"));
  ASSERT_TRUE(c.polyline);
  EXPECT_EQ(c.polyline->size(), 2u);
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"polyline": "x"}})")),
            "command.trajectory.polyline: expected a list of points [x, y], got \"x\"");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": 1})")),
            "command.trajectory: expected an object, got 1");
}

TEST(PedestrianCommand, Teleport) {
  const PedestrianCommand c = parse(json::parse(R"({"teleport": {"x": 3, "y": 4, "yaw": 1}})"));
  ASSERT_TRUE(c.teleport);
  EXPECT_FALSE(c.teleport->speed);
  EXPECT_EQ(error_of(json::parse(R"({"teleport": {"x": 3, "y": 4, "yaw": 1, "speed": -2}})")),
            "command.teleport.speed: must be >= 0 m/s");
}

TEST(PedestrianCommand, PartsThatCannotGoTogether) {
  EXPECT_EQ(
      error_of(json::parse(
          R"({"speed": {"speed": 1}, "trajectory": {"x": 1, "y": 2, "yaw": 0, "speed": 1}})")),
      "command.trajectory: a timed trajectory sets the speed too: give it alone");
  EXPECT_EQ(
      error_of(json::parse(
          R"({"teleport": {"x": 1, "y": 2, "yaw": 0}, "trajectory": {"polyline": [[0, 0]]}})")),
      "command.teleport: give teleport or trajectory, not both");
  // A polyline with a speed is fine (the speed it walks it at).
  EXPECT_EQ(error_of(json::parse(
                R"({"speed": {"speed": 1}, "trajectory": {"polyline": [[0, 0], [1, 0]]}})")),
            "accepted");
}

}  // namespace
}  // namespace convoy::road_users
