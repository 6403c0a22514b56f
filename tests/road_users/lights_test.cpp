// Traffic lights: whether a lane's light holds one at its stop line (the light s1 of
// tests/opendrive/data/lane_graph.xodr, on lane b:1 at s 5, driven towards s 0), and the stop
// line to stop at on a path.
#include "road_users/lights.h"

#include <gtest/gtest.h>

#include <cmath>

#include "opendrive/parser.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;

TEST(RedFor, HeldBeforeTheStopLineOfItsLanesLight) {
  const odr::Network net = odr::load(CONVOY_LANE_GRAPH_XODR);
  const odr::LaneGraph graph(net);
  const odr::LaneIndex b1 = graph.find("b", 1, 40);
  const odr::LaneIndex a_lane = graph.find("a", -1, 40);
  ASSERT_NE(b1, odr::kNoLane);
  ASSERT_FALSE(graph.lane(b1).forward);
  const LightStates red{{"s1", Light::kRed}};
  // b:1 runs towards s 0: before the line at s > 5, held until 0.5 m past it (s 4.5).
  EXPECT_TRUE(red_for(graph, red, b1, 30));
  EXPECT_TRUE(red_for(graph, red, b1, 4.6));
  EXPECT_FALSE(red_for(graph, red, b1, 4.4));
  EXPECT_TRUE(red_for(graph, {{"s1", Light::kRedYellow}}, b1, 30));
  EXPECT_FALSE(red_for(graph, {{"s1", Light::kYellow}}, b1, 30));
  EXPECT_FALSE(red_for(graph, {{"s1", Light::kGreen}}, b1, 30));
  EXPECT_FALSE(red_for(graph, {}, b1, 30));                     // not in it: green
  EXPECT_FALSE(red_for(graph, {{"s2", Light::kRed}}, b1, 30));  // another light
  EXPECT_FALSE(red_for(graph, red, a_lane, 30));                // not a:-1's light
}

class StopLineGap : public ::testing::Test {
 protected:
  // Stop lines at arcs 50 (s1) and 70 (s2); my front at 20, at 10 m/s, b 2 m/s^2.
  Path path = [] {
    Path p = polyline_path({{0, 0}, {100, 0}}, 0.5, 0, 0);
    p.stops = {{50, "s1"}, {70, "s2"}};
    return p;
  }();
  double gap(const LightStates& lights, double front = 20, double speed = 10) const {
    return stop_line_gap(path, lights, front, speed, 2, 100);
  }
};

TEST_F(StopLineGap, StopsAtTheNextLightWhenRed) {
  EXPECT_EQ(gap({{"s1", Light::kRed}}), 30);
  EXPECT_EQ(gap({{"s1", Light::kRedYellow}}), 30);
  EXPECT_EQ(stop_line_gap(path, {{"s1", Light::kRed}}, 20, 10, 2, 25), INFINITY);  // too far
  // Only the next light counts: green (or not given) there, it goes on.
  EXPECT_EQ(gap({{"s2", Light::kRed}}), INFINITY);
  EXPECT_EQ(gap({{"s1", Light::kGreen}, {"s2", Light::kRed}}), INFINITY);
  EXPECT_EQ(gap({{"s1", Light::kOff}, {"s2", Light::kRed}}), INFINITY);
}

TEST_F(StopLineGap, YellowStopsOnlyWhenItComfortablyCan) {
  // 10 m/s brakes to a stop in 25 m at 2 m/s^2: it stops 30 m ahead; at 12 m/s (36 m) it goes.
  EXPECT_EQ(gap({{"s1", Light::kYellow}}), 30);
  EXPECT_EQ(gap({{"s1", Light::kYellow}}, 20, 12), INFINITY);
}

TEST_F(StopLineGap, ALinePassedByUpTo0_5mStillHolds) {
  EXPECT_NEAR(gap({{"s1", Light::kRed}}, 50.3), -0.3, 1e-12);
  // Passed by 0.6 m: the next one counts.
  EXPECT_NEAR(gap({{"s1", Light::kRed}, {"s2", Light::kRed}}, 50.6), 19.4, 1e-12);
  EXPECT_EQ(gap({{"s1", Light::kRed}}, 50.6), INFINITY);
}

}  // namespace
}  // namespace convoy::road_users
