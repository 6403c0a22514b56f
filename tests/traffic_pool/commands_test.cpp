// Scenario commands for pooled road users (Pool::set_commands) on the 3x3 SUMO grid: a speed
// command overrides IDM and the AI resumes from there; a teleport moves the car and localises
// it on the lane there; a lane command changes to the neighbour lane; bad ids and bad fields
// fail with one message naming the datapack, the road user and the key.
#include <gtest/gtest.h>

#include <cmath>

#include "grid_map.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {
namespace {

using nlohmann::json;

const PoolLane& long_lane() {
  const PoolLane* best = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && (!best || l.length > best->length)) best = &l;
  }
  return *best;
}

VehicleSpec car(const PoolLane& lane, double s, double speed) {
  VehicleSpec v = at("car", lane, s);
  v.policy = "idm";
  v.speed = speed;
  return v;
}

TEST(PoolCommands, SpeedOverridesIdmAndTheAiResumes) {
  Pool pool(map().pool, {car(long_lane(), 10, 10)});
  for (int k = 0; k < 20; ++k) {
    pool.set_commands(json{{"car", {{"speed", {{"speed", 3.0}, {"acceleration", -2.0}}}}}},
                      "commands", "pool_engine/", 0.25);
    pool.step(0.05);
    EXPECT_DOUBLE_EQ(pool.speed(0), 3.0);
    EXPECT_DOUBLE_EQ(pool.acceleration(0), -2.0);
  }
  pool.step(0.05);  // no command: IDM from 3 m/s (it speeds up, no jump)
  EXPECT_GT(pool.speed(0), 3.0);
  EXPECT_LT(pool.speed(0), 3.2);
  EXPECT_GT(pool.acceleration(0), 0);
}

TEST(PoolCommands, TeleportMovesAndRelocalises) {
  const PoolLane& lane = long_lane();
  Pool pool(map().pool, {car(lane, 10, 5)});
  const opendrive::Pose2 p = lane.at(60);  // the box centre's spot; the command gives the rear
  const double back = 0.25 * 4.5;          // axle, a quarter of its length behind it
  const json cmd{{"teleport",
                  {{"x", p.x - back * std::cos(p.heading)},
                   {"y", p.y - back * std::sin(p.heading)},
                   {"yaw", p.heading},
                   {"speed", 7.0}}}};
  pool.set_commands(json{{"pool_engine/car", cmd}}, "commands", "pool_engine/", 0.25);
  pool.step(0.05);
  EXPECT_NEAR(pool.x(0), p.x, 1e-9);
  EXPECT_NEAR(pool.y(0), p.y, 1e-9);
  EXPECT_DOUBLE_EQ(pool.speed(0), 7.0);
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &lane);
  EXPECT_NEAR(pool.s(0) - 2.25, 60, 1.01);  // its front along the lane
  pool.step(0.05);                          // on from there on its lane
  EXPECT_NEAR(pool.s(0) - 2.25, 60 + 0.35, 1.2);
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &lane);
}

TEST(PoolCommands, TeleportFarFromTheLanesStands) {
  Pool pool(map().pool, {car(long_lane(), 10, 5)});
  pool.set_commands(json{{"car", {{"teleport", {{"x", -500.0}, {"y", -500.0}, {"yaw", 0.0}}}}}},
                    "commands", "p/", 0.0);
  for (int k = 0; k < 10; ++k) pool.step(0.05);
  EXPECT_DOUBLE_EQ(pool.x(0), -500.0);
  EXPECT_DOUBLE_EQ(pool.speed(0), 0.0);
  EXPECT_TRUE(pool.standing(0));
  EXPECT_FALSE(pool.present(0));
  const opendrive::Pose2 p = long_lane().at(30);  // put back on the lanes: it drives on
  pool.set_commands(
      json{{"car", {{"teleport", {{"x", p.x}, {"y", p.y}, {"yaw", p.heading}, {"speed", 4.0}}}}}},
      "commands", "p/", 0.0);
  pool.step(0.05);
  EXPECT_FALSE(pool.standing(0));
  EXPECT_EQ(&map().pool.lane(pool.lane(0)), &long_lane());
  pool.step(0.05);
  EXPECT_GT(pool.speed(0), 3.9);
}

TEST(PoolCommands, RouteReplansThroughThePositions) {
  // A car before a junction, routed through a point of each lane out of it in turn (not turning
  // back): it drives onto that lane every time (not the seed's draw).
  const PoolLane& lane = long_lane();
  ASSERT_FALSE(lane.next.empty());
  std::vector<uint32_t> goals;
  for (uint32_t jl : lane.next) {
    if (!map().pool.lane(jl).u_turn)
      goals.insert(goals.end(), map().pool.lane(jl).next.begin(), map().pool.lane(jl).next.end());
  }
  size_t tried = 0;
  for (uint32_t goal : goals) {
    const opendrive::Pose2 p = map().pool.lane(goal).at(20);
    Pool pool(map().pool, {car(lane, 10, 8)});
    bool reached = false;
    for (int k = 0; k < 20 * 60 && !reached; ++k) {
      pool.set_commands(json{{"car", {{"route", {{"positions", {{p.x, p.y}}}}}}}}, "c", "p/", 0.25);
      pool.step(0.05);
      reached = pool.lane(0) == goal;
    }
    EXPECT_TRUE(reached) << "to lane " << goal;
    ++tried;
  }
  EXPECT_GE(tried, 2u);
}

TEST(PoolCommands, LaneChangesToTheNeighbour) {
  const PoolLane* two = nullptr;
  for (const PoolLane& l : map().pool.lanes()) {
    if (l.junction < 0 && l.length > 70 && l.left != kNone) two = &l;
  }
  ASSERT_NE(two, nullptr);
  const PoolLane& to = map().pool.lane(two->left);
  Pool pool(map().pool, {car(*two, 20, 5)});
  pool.set_commands(json{{"car", {{"lane", {{"road", to.road_id}, {"lane", to.lane_id}}}}}},
                    "commands", "p/", 0.25);
  pool.step(0.05);
  EXPECT_EQ(pool.lane(0), two->left);
  EXPECT_EQ(pool.stats().lane_changes, 1u);
}

TEST(PoolCommands, SameCommandsSameRun) {
  auto run = [] {
    std::vector<VehicleSpec> specs = spawn(map().pool, 20, 3, VehicleSpec{}, "pool/");
    Pool pool(map().pool, specs);
    std::vector<double> out;
    for (int k = 0; k < 200; ++k) {
      if (k < 100) {
        pool.set_commands(json{{"pool/3", {{"speed", {{"speed", 2.0}}}}}}, "c", "e/", 0.25);
      }
      pool.step(0.05);
    }
    for (size_t i = 0; i < pool.size(); ++i) out.push_back(pool.x(i) + pool.y(i) + pool.speed(i));
    return out;
  };
  EXPECT_EQ(run(), run());
}

TEST(PoolCommands, BadIdsAndFieldsAreNamed) {
  Pool pool(map().pool, {car(long_lane(), 10, 5)});
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"nobody", json::object()}},
                                "pool 'traffic': datapack 'commands'", "traffic/", 0.25);
            }),
            "pool 'traffic': datapack 'commands': no road user 'nobody' in the pool (ids as it "
            "publishes them, with or without 'traffic/')");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"speed", {{"speed", "fast"}}}}}}, "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.speed.speed: expected a number, got \"fast\"");
  EXPECT_EQ(error_of([&] {
              pool.set_commands(json{{"car", {{"sped", 1}}}}, "dp", "t/", 0.25);
            }),
            "dp: road user 'car': command.sped: unknown key (time_ns, speed, lane, route, "
            "trajectory, teleport)");
  const std::string poly = error_of([&] {
    pool.set_commands(json{{"car", {{"trajectory", {{"polyline", {{0, 0}, {1, 1}}}}}}}}, "dp", "t/",
                      0.25);
  });
  EXPECT_NE(poly.find("not supported by the pooled host yet"), std::string::npos) << poly;
}

}  // namespace
}  // namespace convoy::traffic_pool

namespace convoy::traffic_pool {
namespace {

TEST(PoolCommands, WalkersTakeSpeedAndTeleportNotLane) {
  Pool pool(city().pool, {});
  pool.set_walkers(spawn_walkers(city().pool, 3, 1, "walker/"));
  const PoolWalkers& w = *pool.walkers();
  for (int k = 0; k < 10; ++k) pool.step(0.05);
  for (int k = 0; k < 20; ++k) {
    pool.set_commands(json{{"walker/1", {{"speed", {{"speed", 0.5}}}}}}, "dp", "p/", 0.25);
    pool.step(0.05);
    EXPECT_LE(w.speed(1), 0.5 + 1e-9);
  }
  const double own = w.spec(1).speed;
  EXPECT_GT(own, 1.0);  // its own pace back after the command
  const double x = w.x(0) + 3, y = w.y(0) + 2;
  pool.set_commands(json{{"p/walker/0", {{"teleport", {{"x", x}, {"y", y}, {"yaw", 1.0}}}}}}, "dp",
                    "p/", 0.25);
  pool.step(0.05);
  EXPECT_NEAR(w.x(0), x, 1e-9);
  EXPECT_NEAR(w.y(0), y, 1e-9);
  EXPECT_DOUBLE_EQ(w.yaw(0), 1.0);
  for (int k = 0; k < 20; ++k) pool.step(0.05);  // and walks on from there
  EXPECT_GT(std::hypot(w.x(0) - x, w.y(0) - y), 0.1);
  const std::string e = error_of([&] {
    pool.set_commands(json{{"walker/2", {{"lane", {{"road", "1"}, {"lane", -1}}}}}}, "dp", "p/",
                      0.25);
  });
  EXPECT_EQ(e,
            "dp: road user 'walker/2': command.lane: a pedestrian has no lane to change to (a "
            "pedestrian_agent takes speed, route, trajectory and teleport)");
}

}  // namespace
}  // namespace convoy::traffic_pool
