// A walker's road crossing on hand-computed cases: the threat a vehicle is to a crossing leg,
// gap acceptance, the lights, and how far it may walk once on the road.
#include "road_users/walker.h"

#include <gtest/gtest.h>

#include <cmath>

namespace convoy::road_users {
namespace {

// A 6 m leg from (0, 0) northwards; a car 4 m long, 2 m wide, heading east at 10 m/s.
const CrossingLeg kLeg{0, 0, 0, 1, 6};

CrossingVehicle car(double x, double y) { return {x, y, 0, 10, 4, 2, 0}; }

TEST(Walker, ThreatOfAVehicleCrossingTheLine) {
  // Its front at (-18, 2): 18 m from the line, reaching it 2 m along the leg in 1.8 s.
  const auto t = crossing_threat(kLeg, car(-20, 2));
  ASSERT_TRUE(t);
  EXPECT_DOUBLE_EQ(t->front, 18);
  EXPECT_DOUBLE_EQ(t->u, 2);
  EXPECT_DOUBLE_EQ(t->tta, 1.8);
  EXPECT_EQ(t->half_width, 1);
  EXPECT_EQ(t->speed, 10);
  // Its front 2 m over the line (back 2 m short of passing): arriving now.
  const auto over = crossing_threat(kLeg, car(0, 2));
  ASSERT_TRUE(over);
  EXPECT_DOUBLE_EQ(over->front, -2);
  EXPECT_EQ(over->tta, 0);
  // Standing: never arrives; no width given: 1.8 m.
  CrossingVehicle still = car(-20, 2);
  still.speed = 0;
  still.width = 0;
  EXPECT_EQ(crossing_threat(kLeg, still)->tta, INFINITY);
  EXPECT_EQ(crossing_threat(kLeg, still)->half_width, 0.9);
}

TEST(Walker, NoThreat) {
  // Along the leg, not across it.
  CrossingVehicle along = car(-3, -20);
  along.yaw = M_PI / 2;
  EXPECT_FALSE(crossing_threat(kLeg, along));
  // Beyond the leg's end by more than its half width + 1 m (6 + 2 = 8 m), not at 7.5 m.
  EXPECT_FALSE(crossing_threat(kLeg, car(-20, 8.5)));
  EXPECT_TRUE(crossing_threat(kLeg, car(-20, 7.5)));
  EXPECT_FALSE(crossing_threat(kLeg, car(-20, -2.5)));
  // Its back past the line (front 5 m over, beyond its 4 m length).
  EXPECT_FALSE(crossing_threat(kLeg, car(3, 2)));
}

TEST(Walker, GapAcceptance) {
  CrossingThreat a, b;
  a.tta = 5;
  b.tta = 3.9;
  EXPECT_FALSE(gap_accepted({a, b}, 4));
  EXPECT_TRUE(gap_accepted({a, b}, 3.9));
  EXPECT_TRUE(gap_accepted({}, 4));
}

TEST(Walker, Lights) {
  EXPECT_TRUE(walker_lights_allow({"green"}, {"green"}));  // its own lights decide
  EXPECT_FALSE(walker_lights_allow({"green", "red"}, {}));
  EXPECT_TRUE(walker_lights_allow({"off", ""}, {"red"}));  // none on: the traffic's
  EXPECT_FALSE(walker_lights_allow({"off"}, {"red", "yellow"}));
  EXPECT_TRUE(walker_lights_allow({}, {"", "off"}));
  EXPECT_TRUE(walker_lights_allow({}, {}));
}

TEST(Walker, WhileCrossing) {
  // The leg starts at arc 10; a vehicle's lane at u = 5 +- (1 + 0.5): [3.5, 6.5] on the leg.
  const CrossingCaution caution{8, 4};
  CrossingThreat t;
  t.u = 5;
  t.half_width = 1;
  t.speed = 2;
  t.front = 20;
  t.tta = 10;
  // 1.5 m before its lane or more: on.
  EXPECT_EQ(crossing_limit({t}, 10, 12, 1, caution, 30), 30);
  // 1 m before it, far and late (10 s > 4 + 1 s to clear it): on; within 8 m: waits 0.2 m short.
  EXPECT_EQ(crossing_limit({t}, 10, 12.5, 1, caution, 30), 30);
  t.front = 7;
  EXPECT_NEAR(crossing_limit({t}, 10, 12.5, 1, caution, 30), 13.3, 1e-12);
  // In its lane (u 4): within 4 m, it steps back out; far but arriving before it clears the
  // lane forwards (2.5 s + 0.5 s) while backing out (0.5 s) is shorter: back out too.
  t.front = 3;
  EXPECT_NEAR(crossing_limit({t}, 10, 14, 1, caution, 30), 13.3, 1e-12);
  t.front = 20;
  t.tta = 2.9;
  EXPECT_NEAR(crossing_limit({t}, 10, 14, 1, caution, 30), 13.3, 1e-12);
  t.tta = 3.1;
  EXPECT_EQ(crossing_limit({t}, 10, 14, 1, caution, 30), 30);
  // Standing before the line: ignored. Over the line: it does not step back, waits before.
  t.speed = 0.4;
  t.front = 5;
  EXPECT_EQ(crossing_limit({t}, 10, 12.5, 1, caution, 30), 30);
  t.front = -1;
  EXPECT_EQ(crossing_limit({t}, 10, 14, 1, caution, 30), 30);
  EXPECT_NEAR(crossing_limit({t}, 10, 12.5, 1, caution, 30), 13.3, 1e-12);
  // Never beyond the limit given, never behind where it is when waiting.
  EXPECT_EQ(crossing_limit({t}, 10, 12.5, 1, caution, 11), 11);
  EXPECT_EQ(crossing_limit({t}, 10, 13.4, 1, caution, 30), 13.4);
}

}  // namespace
}  // namespace convoy::road_users
