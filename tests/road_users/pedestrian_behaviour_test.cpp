// A walker's planner and step (road_users/pedestrian_walks.h, pedestrian_behaviour.h) on the
// city map's road 2 (along +x from x = 14; sidewalks -3 at y = -8.25 and 3 at y = 8.25;
// crosswalk 2 at x = 16.75, next to vehicle light 2): the plan over the crosswalk and its
// on-road part, waiting at the curb for a car and for the lights, the rain, keeping behind a
// slower walker, and its end.
#include "road_users/pedestrian_behaviour.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "road_users/pedestrian_walks.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;
constexpr int64_t kStep = 50000000;  // 0.05 s

const odr::LaneGraph& city() {
  static const odr::Network net = odr::load(CONVOY_CITY_XODR);
  static const odr::LaneGraph graph{net};
  return graph;
}

// Across crosswalk 2: from sidewalk -3 at s = 10 to sidewalk 3 at s = 10.
WalkPlan across() {
  const odr::Crosswalk* cw = nullptr;
  for (const auto& c : city().crosswalks()) {
    if (c.id == "2") cw = &c;
  }
  EXPECT_NE(cw, nullptr);
  const Spot from{city().find("2", -3, 10.0), 10.0}, to{city().find("2", 3, 10.0), 10.0};
  return plan_walk(city(), from, to, cw);
}

PedestrianDescription walker() {
  PedestrianDescription d;
  d.name = "ped";
  d.lights_key = "traffic_lights";
  d.graph = &city();
  d.initial_path = make_walk_path(city(), across());
  return d;
}

// Steps until it is on the road (true) or `steps` have passed.
bool steps_onto_road(const PedestrianDescription& d, PedestrianState& s, int steps,
                     const std::shared_ptr<const WalkerNeighbours>& around) {
  const WalkCrossing& c = s.path.road_crossings.at(0);
  for (int i = 0; i < steps; ++i) {
    s.neighbours = around;
    step_pedestrian(d, s, kStep);
    if (s.arc > c.enter) return true;
  }
  return false;
}

TEST(PedestrianWalks, AcrossTheCrosswalk) {
  const WalkPlan p = across();
  ASSERT_TRUE(p.before && p.after && p.cross);
  EXPECT_EQ(p.cross->crosswalk, "2");
  const WalkPath path = make_walk_path(city(), p);
  ASSERT_EQ(path.road_crossings.size(), 1u);
  const WalkCrossing& c = path.road_crossings[0];
  // On the road between the sidewalks' inner edges (14 m of carriageway).
  EXPECT_GT(c.enter, c.start);
  EXPECT_LT(c.exit, c.end);
  EXPECT_NEAR(c.exit - c.enter, 14.0, 0.6);
  EXPECT_FALSE(c.veh_signals.empty());
  const odr::Pose2 mid = path.at(0.5 * (c.enter + c.exit));
  EXPECT_NEAR(mid.x, 16.75, 0.5);
  EXPECT_NEAR(mid.y, 0.0, 0.5);
}

TEST(PedestrianWalks, MidBlockIsFurtherAlongTheRoad) {
  const WalkPlan p = across();
  const auto m = mid_block(city(), *p.cross, 20.0);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->crosswalk.empty());
  EXPECT_NEAR(m->from.s, p.cross->from.s + 20.0, 1e-9);
}

TEST(PedestrianBehaviour, WaitsForACarWithinItsGapThenCrosses) {
  PedestrianDescription d = walker();
  d.obey_lights = false;
  PedestrianState s = start_pedestrian(d);
  // A car on lane 1 (y = 1.75) standing 30 m away would never arrive: it crosses.
  auto standing = std::make_shared<WalkerNeighbours>();
  standing->vehicles.push_back({"car", 50.0, 1.75, M_PI, 0.0, 4.5, 1.8, 1.35});
  EXPECT_TRUE(steps_onto_road(d, s, 400, standing));
  // The same car coming at 10 m/s, 2 s away: it waits at the curb.
  s = start_pedestrian(d);
  auto coming = std::make_shared<WalkerNeighbours>();
  coming->vehicles.push_back({"car", 16.75 + 3.6 + 20.0, 1.75, M_PI, 10.0, 4.5, 1.8, 1.35});
  EXPECT_FALSE(steps_onto_road(d, s, 400, coming));
  EXPECT_EQ(s.v, 0.0);
  EXPECT_NEAR(s.arc, s.path.road_crossings[0].enter - 0.3, 1e-6);
}

TEST(PedestrianBehaviour, CrossesOnlyWhileTheCrossedRoadHasRed) {
  const PedestrianDescription d = walker();
  PedestrianState s = start_pedestrian(d);
  const auto none = std::make_shared<const WalkerNeighbours>();
  s.lights = std::make_shared<const SignalStates>(SignalStates{{"2", "green"}});
  EXPECT_FALSE(steps_onto_road(d, s, 400, none));
  s.lights = std::make_shared<const SignalStates>(SignalStates{{"2", "red"}});
  EXPECT_TRUE(steps_onto_road(d, s, 400, none));
  // No lights datapack yet: unsignalised, with a warning.
  s = start_pedestrian(d);
  EXPECT_TRUE(steps_onto_road(d, s, 400, none));
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_EQ(s.warnings[0].first, "no-lights");
}

TEST(PedestrianBehaviour, FasterInRainAndBehindASlowerWalker) {
  EXPECT_EQ(rain_factor(0.5, true), 1.1);
  EXPECT_EQ(rain_factor(2.0, true), 1.2);
  EXPECT_EQ(rain_factor(0.5, false), 1.0);
  const PedestrianDescription d = walker();
  PedestrianState s = start_pedestrian(d);
  s.rain_factor = 1.1;
  step_pedestrian(d, s, kStep);
  EXPECT_DOUBLE_EQ(s.v, d.speed * 1.1);
  // A walker standing 0.8 m ahead in its way: it does not walk into it.
  s = start_pedestrian(d);
  auto ahead = std::make_shared<WalkerNeighbours>();
  ahead->walkers.push_back(
      {"w", s.x + 0.8 * std::cos(s.yaw), s.y + 0.8 * std::sin(s.yaw), s.yaw, 0.0, 0.3, 0.45, 0.0});
  s.neighbours = ahead;
  step_pedestrian(d, s, kStep);
  EXPECT_EQ(s.v, 0.0);
}

TEST(PedestrianBehaviour, AbsentAtItsEndThenBackAtItsStart) {
  PedestrianDescription d = walker();
  d.obey_lights = false;
  d.respawn = true;
  d.respawn_delay_s = 0.5;
  PedestrianState s = start_pedestrian(d);
  const PedestrianState fresh = s;
  const auto none = std::make_shared<const WalkerNeighbours>();
  for (int i = 0; i < 2000 && !s.absent; ++i) {
    s.neighbours = none;
    step_pedestrian(d, s, kStep);
  }
  ASSERT_TRUE(s.absent);
  EXPECT_FALSE(step_pedestrian(d, s, kStep)) << "still absent: nothing to publish";
  for (int i = 0; i < 20 && s.absent; ++i) step_pedestrian(d, s, kStep);
  EXPECT_FALSE(s.absent);
  EXPECT_EQ(s.x, fresh.x);
  EXPECT_EQ(s.y, fresh.y);
  EXPECT_EQ(s.arc, 0.0);
}

}  // namespace
}  // namespace convoy::road_users
