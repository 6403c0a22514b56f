// The command contract: each part of a vehicle's command accepted into its value, and each
// kind of bad value rejected with its message (the key, then what is wrong), on the lane graph
// of tests/opendrive/data/lane_graph.xodr.
#include "road_users/command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_map.h"

namespace convoy::road_users {
namespace {

using nlohmann::json;

using testing::map;

VehicleCommand parse(const json& j) { return parse_vehicle_command(j, "command", map().graph); }

// The message a command is rejected with ("accepted" if it is not).
std::string error_of(const json& j) { return testing::rejection(parse, j); }

TEST(Command, NothingIsNoPart) {
  const VehicleCommand c = parse(json::parse(R"({"time_ns": 100})"));
  EXPECT_FALSE(c.speed || c.lane || c.route || c.timed || c.polyline || c.teleport);
  EXPECT_FALSE(parse(json::object()).speed);
}

TEST(Command, NotAnObjectOrUnknown) {
  EXPECT_EQ(error_of(json::parse("[1, 2]")),
            "command: expected a JSON object of commands, got [1,2]");
  EXPECT_EQ(error_of(json::parse(R"({"time_ns": "x"})")),
            "command.time_ns: expected a number (ns)");
  EXPECT_EQ(error_of(json::parse(R"({"brake": 1})")),
            "command.brake: unknown key (time_ns, speed, lane, route, trajectory, teleport)");
}

TEST(Command, Speed) {
  VehicleCommand c = parse(json::parse(R"({"speed": {"speed": 5}})"));
  ASSERT_TRUE(c.speed);
  EXPECT_EQ(c.speed->speed, 5);
  EXPECT_FALSE(c.speed->acceleration);
  c = parse(json::parse(R"({"speed": {"speed": 5, "target_speed": 9, "acceleration": -2.5}})"));
  EXPECT_EQ(c.speed->acceleration, -2.5);
  EXPECT_EQ(error_of(json::parse(R"({"speed": 5})")), "command.speed: expected an object, got 5");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": 5, "jerk": 1}})")),
            "command.speed.jerk: unknown key (speed, target_speed, acceleration)");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {}})")), "command.speed.speed: missing (a number)");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": "fast"}})")),
            "command.speed.speed: expected a number, got \"fast\"");
  EXPECT_EQ(error_of(json{{"speed", {{"speed", INFINITY}}}}),
            "command.speed.speed: expected a number, got null");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": -1}})")),
            "command.speed.speed: must be >= 0 m/s (reversing is not modelled)");
  EXPECT_EQ(error_of(json::parse(R"({"speed": {"speed": 1, "target_speed": null}})")),
            "command.speed.target_speed: expected a number, got null");
}

TEST(Command, Lane) {
  VehicleCommand c = parse(json::parse(R"({"lane": {"road": "a", "lane": -2}})"));
  ASSERT_TRUE(c.lane);
  EXPECT_EQ(c.lane->road, "a");
  EXPECT_EQ(c.lane->lane, -2);
  EXPECT_EQ(c.lane->from_lane, -2);
  EXPECT_EQ(c.lane->offset, 0);
  EXPECT_EQ(c.lane->progress, 1);
  c = parse(json::parse(
      R"({"lane": {"road": "a", "lane": -2, "from_lane": -1, "offset": 0.5, "progress": 0.25}})"));
  EXPECT_EQ(c.lane->from_lane, -1);
  EXPECT_EQ(c.lane->offset, 0.5);
  EXPECT_EQ(c.lane->progress, 0.25);
  const std::string& src = map().net.source;
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": 7, "lane": -1}})")),
            "command.lane.road: expected the road's id as a string");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "zz", "lane": -1}})")),
            "command.lane.road: no road zz in " + src);
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a"}})")),
            "command.lane.lane: expected a non-zero integer lane id, got nothing");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": 0}})")),
            "command.lane.lane: expected a non-zero integer lane id, got 0");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1.5}})")),
            "command.lane.lane: expected a non-zero integer lane id, got -1.5");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -7}})")),
            "command.lane.lane: road a has no lane -7");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1, "from_lane": 4}})")),
            "command.lane.from_lane: road a has no lane 4");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1, "offset": "x"}})")),
            "command.lane.offset: expected a number, got \"x\"");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1, "progress": 1.5}})")),
            "command.lane.progress: must be in [0, 1], got 1.5");
  EXPECT_EQ(error_of(json::parse(R"({"lane": {"road": "a", "lane": -1, "to": 1}})")),
            "command.lane.to: unknown key (road, lane, from_lane, offset, progress)");
}

TEST(Command, Route) {
  const VehicleCommand c =
      parse(json::parse(R"({"route": {"positions": [[50, -1.75], [240, -1.75, 0]]}})"));
  ASSERT_TRUE(c.route);
  ASSERT_EQ(c.route->size(), 2u);
  EXPECT_EQ((*c.route)[1][0], 240);
  EXPECT_EQ((*c.route)[1][1], -1.75);
  EXPECT_EQ(error_of(json::parse(R"({"route": {}})")),
            "command.route.positions: missing (a list of [x, y])");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": []}})")),
            "command.route.positions: expected a list of at least 1 points [x, y], got []");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": [[1]]}})")),
            "command.route.positions[0]: expected a point [x, y] (or [x, y, z]), got [1]");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": [[50, -1.75], [1, "y"]]}})")),
            "command.route.positions[1]: expected numbers, got [1,\"y\"]");
  EXPECT_EQ(error_of(json::parse(R"({"route": {"positions": [[50, -1.75], [50, 500]]}})")),
            "command.route.positions[1]: (50.00, 500.00) is farther than 20 m from any driving "
            "lane of " +
                map().net.source);
  EXPECT_EQ(error_of(json::parse(R"({"route": {"points": []}})")),
            "command.route.points: unknown key (positions)");
}

TEST(Command, Trajectory) {
  VehicleCommand c =
      parse(json::parse(R"({"trajectory": {"x": 1, "y": 2, "z": 0, "yaw": 0.5, "speed": 3}})"));
  ASSERT_TRUE(c.timed);
  EXPECT_EQ(c.timed->x, 1);
  EXPECT_EQ(c.timed->y, 2);
  EXPECT_EQ(c.timed->yaw, 0.5);
  EXPECT_EQ(c.timed->speed, 3);
  EXPECT_FALSE(c.polyline);
  c = parse(json::parse(R"({"trajectory": {"polyline": [[0, 0], [10, 0]], "length": 10}})"));
  ASSERT_TRUE(c.polyline);
  EXPECT_EQ(c.polyline->size(), 2u);
  EXPECT_FALSE(c.timed);
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": [1]})")),
            "command.trajectory: expected an object, got [1]");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"x": 1, "y": 2, "yaw": 0}})")),
            "command.trajectory.speed: missing (a number)");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"x": 1, "y": 2, "yaw": 0, "speed": -1}})")),
            "command.trajectory.speed: must be >= 0 m/s (reversing is not modelled)");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"x": 1, "yaw": 0, "speed": 1}})")),
            "command.trajectory.y: missing (a number)");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"x": 1, "y": 2, "yaw": 0, "t": 1}})")),
            "command.trajectory.t: unknown key (x, y, z, yaw, speed)");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"polyline": [[0, 0]], "speed": 1}})")),
            "command.trajectory.speed: unknown key (polyline, length)");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"polyline": [[0, 0]], "length": "x"}})")),
            "command.trajectory.length: expected a number, got \"x\"");
  EXPECT_EQ(error_of(json::parse(R"({"trajectory": {"polyline": 3}})")),
            "command.trajectory.polyline: expected a list of at least 1 points [x, y], got 3");
}

TEST(Command, Teleport) {
  VehicleCommand c = parse(json::parse(R"({"teleport": {"x": 1, "y": 2, "yaw": 0}})"));
  ASSERT_TRUE(c.teleport);
  EXPECT_FALSE(c.teleport->speed);
  c = parse(json::parse(R"({"teleport": {"x": 1, "y": 2, "yaw": 0, "speed": 4}})"));
  EXPECT_EQ(c.teleport->speed, 4);
  EXPECT_EQ(error_of(json::parse(R"({"teleport": {"x": 1, "y": 2, "yaw": "n"}})")),
            "command.teleport.yaw: expected a number, got \"n\"");
  EXPECT_EQ(error_of(json::parse(R"({"teleport": {"x": 1, "y": 2, "yaw": 0, "speed": -3}})")),
            "command.teleport.speed: must be >= 0 m/s (reversing is not modelled)");
  EXPECT_EQ(error_of(json::parse(R"({"teleport": "here"})")),
            "command.teleport: expected an object, got \"here\"");
}

TEST(Command, PartsThatCannotGoTogether) {
  EXPECT_EQ(
      error_of(json::parse(
          R"({"speed": {"speed": 1}, "trajectory": {"x": 1, "y": 2, "yaw": 0, "speed": 1}})")),
      "command.trajectory: a timed trajectory sets both speed and lane: give it alone");
  EXPECT_EQ(error_of(json::parse(
                R"({"lane": {"road": "a", "lane": -1}, "trajectory": {"polyline": [[0, 0]]}})")),
            "command.trajectory: both lane and trajectory steer: give one of them");
  EXPECT_EQ(
      error_of(json::parse(
          R"({"teleport": {"x": 1, "y": 2, "yaw": 0}, "trajectory": {"polyline": [[0, 0]]}})")),
      "command.teleport: give teleport or trajectory, not both");
  // Speed with a polyline or a route, speed with lane, teleport with speed: together.
  const VehicleCommand c = parse(json::parse(
      R"({"speed": {"speed": 1}, "trajectory": {"polyline": [[0, 0]]},
          "route": {"positions": [[50, -1.75]]}})"));
  EXPECT_TRUE(c.speed && c.polyline && c.route);
  EXPECT_TRUE(
      parse(json::parse(R"({"speed": {"speed": 1}, "teleport": {"x": 1, "y": 2, "yaw": 0}})"))
          .teleport);
  EXPECT_TRUE(
      parse(json::parse(R"({"speed": {"speed": 1}, "lane": {"road": "a", "lane": -1}})")).lane);
}

}  // namespace
}  // namespace convoy::road_users
