// A vehicle's step (road_users/vehicle_behaviour.h) on the city map's road 2 (along +x from
// x = 14, lane -1 at y = -1.75, lane -2 at y = -5.25): its start, IDM on a free road and
// behind a standing car, commands overriding the AI, a command that cannot be carried out, and
// that the state is a value (the same inputs give the same states; reset is a fresh start).
#include "road_users/vehicle_behaviour.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;
constexpr int64_t kStep = 50000000;  // 0.05 s

const odr::LaneGraph& city() {
  static const odr::Network net = odr::load(CONVOY_CITY_XODR);
  static const odr::LaneGraph graph{net};
  return graph;
}

VehicleDescription on_road_2(double start_s = 10.0, double speed = 10.0) {
  VehicleDescription d;
  d.name = "car";
  d.command_key = "command";
  d.graph = &city();
  d.idm.v0 = 15.0;
  d.lane_changes = false;
  d.start_s = start_s;
  d.initial_speed = speed;
  d.rear_overhang = 0.5 * (d.length - d.wheelbase);
  d.initial_route = *city().route("2", -1, "2", -1);
  const auto& last = d.initial_route.segments.back();
  d.initial_goals = {{last.lane, last.s_to}};
  return d;
}

TEST(VehicleBehaviour, StartsOnItsRoute) {
  const VehicleDescription d = on_road_2();
  const VehicleState s = start_vehicle(d);
  EXPECT_NEAR(s.y, -1.75, 1e-6);
  EXPECT_NEAR(s.yaw, 0.0, 1e-6);
  EXPECT_EQ(s.v, 10.0);
  EXPECT_EQ(s.time_ns, 0);
  EXPECT_FALSE(s.absent);
  EXPECT_NEAR(s.arc, 10.0, 1e-9);
}

TEST(VehicleBehaviour, FreeRoadIsIdmWithoutALeader) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  perceive(s, std::make_shared<const Neighbours>(), nullptr);
  ASSERT_TRUE(step_vehicle(d, s, kStep));
  const double want = d.idm.accel(10.0, INFINITY, 0, 15.0);
  EXPECT_DOUBLE_EQ(s.acc, want);
  EXPECT_DOUBLE_EQ(s.v, 10.0 + want * 0.05);
  EXPECT_EQ(s.time_ns, kStep);
  EXPECT_GT(s.x, 14.0 + 10.0);
}

TEST(VehicleBehaviour, StopsBehindAStandingCar) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  // A car standing on lane -1 with its rear at x = 80.
  const auto ahead = std::make_shared<const Neighbours>(
      Neighbours{{"parked", 80.0 + 2.25 - 1.35, -1.75, 0.0, 0.0, 4.5, 1.8, 1.35}});
  double front = 0;
  for (int i = 0; i < 400; ++i) {
    perceive(s, ahead, nullptr);
    step_vehicle(d, s, kStep);
    front = s.x + d.front_offset();
    ASSERT_LT(front, 80.0) << "at step " << i;
  }
  EXPECT_LT(s.v, 0.01);
  EXPECT_GT(front, 80.0 - d.idm.s0 - 1.0);  // it closed up to about s0
}

TEST(VehicleBehaviour, ASpeedCommandOverridesIdmForItsStep) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  VehicleCommand c;
  c.speed = VehicleCommand::Speed{3.0, -2.0};
  s.command = c;
  step_vehicle(d, s, kStep);
  EXPECT_EQ(s.v, 3.0);
  EXPECT_EQ(s.acc, -2.0);
  ASSERT_TRUE(s.commanded_acc);
  EXPECT_FALSE(s.command) << "a command holds for one step";
  step_vehicle(d, s, kStep);  // back to its AI: accelerates from 3 m/s
  EXPECT_GT(s.v, 3.0);
  EXPECT_FALSE(s.commanded_acc);
}

TEST(VehicleBehaviour, ALaneCommandMovesItOverAndNamesAMissingLane) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  for (int i = 0; i <= 40; ++i) {
    VehicleCommand c;
    c.lane = VehicleCommand::Lane{"2", -2, -1, 0.0, std::min(1.0, i / 40.0)};
    s.command = c;
    step_vehicle(d, s, kStep);
  }
  EXPECT_NEAR(s.y, -5.25, 1e-6);
  VehicleCommand bad;
  bad.lane = VehicleCommand::Lane{"2", -7, -2, 0.0, 0.5};
  s.command = bad;
  try {
    step_vehicle(d, s, kStep);
    FAIL() << "accepted a lane that does not exist";
  } catch (const CommandError& e) {
    EXPECT_EQ(e.key(), "command.lane.lane");
    EXPECT_NE(e.detail().find("no lane -7"), std::string::npos) << e.detail();
  }
}

TEST(VehicleBehaviour, TeleportedFarFromAnyLaneItStopsAndWarns) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  VehicleCommand c;
  c.teleport = CommandPose{5000.0, 5000.0, 0.0, 5.0};
  s.command = c;
  step_vehicle(d, s, kStep);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_EQ(s.warnings[0].first, "lost");
  EXPECT_TRUE(s.lost);
  for (int i = 0; i < 100; ++i) step_vehicle(d, s, kStep);
  EXPECT_EQ(s.v, 0.0);
}

TEST(VehicleBehaviour, TheStateIsAValue) {
  const VehicleDescription d = on_road_2(5.0, 12.0);
  VehicleState a = start_vehicle(d), b = start_vehicle(d);
  const auto around = std::make_shared<const Neighbours>(
      Neighbours{{"slow", 60.0, -1.75, 0.0, 4.0, 4.5, 1.8, 1.35}});
  for (int i = 0; i < 200; ++i) {
    perceive(a, around, nullptr);
    perceive(b, around, nullptr);
    step_vehicle(d, a, kStep);
    step_vehicle(d, b, kStep);
  }
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.v, b.v);
  // Reset: a fresh start, whatever happened since.
  const VehicleState fresh = start_vehicle(d);
  EXPECT_NE(a.x, fresh.x);
  a = start_vehicle(d);
  EXPECT_EQ(a.x, fresh.x);
  EXPECT_EQ(a.time_ns, 0);
  EXPECT_TRUE(a.inputs.empty());
}

TEST(VehicleBehaviour, AbsentAtItsRoutesEndAndBackAfterTheDelay) {
  VehicleDescription d = on_road_2(150.0, 15.0);
  d.respawn = true;
  d.respawn_delay_s = 1.0;
  VehicleState s = start_vehicle(d);
  int steps = 0;
  while (!s.absent && steps < 1000) {
    perceive(s, std::make_shared<const Neighbours>(), nullptr);
    step_vehicle(d, s, kStep);
    ++steps;
  }
  ASSERT_TRUE(s.absent);
  EXPECT_EQ(s.x, s.initial_path_start.x);  // it waits at its start
  perceive(s, std::make_shared<const Neighbours>(), nullptr);
  EXPECT_FALSE(step_vehicle(d, s, kStep)) << "still absent: nothing to publish";
  for (int i = 0; i < 20 && s.absent; ++i) {
    perceive(s, std::make_shared<const Neighbours>(), nullptr);
    step_vehicle(d, s, kStep);
  }
  EXPECT_FALSE(s.absent);
  EXPECT_EQ(s.v, 15.0);
}

TEST(VehicleBehaviour, TheWeatherSlowsIt) {
  const VehicleDescription d = on_road_2();
  VehicleState s = start_vehicle(d);
  drive_in(d, s, {0.2, INFINITY});
  EXPECT_LT(s.driving.idm.v0, d.idm.v0);
  VehicleDescription off = d;
  off.weather_adaptation = false;
  drive_in(off, s, {0.2, INFINITY});
  EXPECT_EQ(s.driving.idm.v0, d.idm.v0);
}

}  // namespace
}  // namespace convoy::road_users
