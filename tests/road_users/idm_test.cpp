// IDM: free-road acceleration, steady following, and the approach to a standing leader.
#include "road_users/idm.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace convoy::road_users {
namespace {

// Defaults: v0 13.9, T 1.5, s0 2, a 1.5, b 2, delta 4.
const Idm kIdm;

TEST(Idm, FreeRoadAcceleration) {
  EXPECT_DOUBLE_EQ(kIdm.accel(0, INFINITY, 0, 20), 1.5);  // standing: a
  // Half its desired speed: a (1 - (1/2)^4) = 1.5 * 15/16.
  EXPECT_DOUBLE_EQ(kIdm.accel(10, INFINITY, 0, 20), 1.40625);
  EXPECT_NEAR(kIdm.accel(20, INFINITY, 0, 20), 0, 1e-12);               // at v0: none
  EXPECT_NEAR(kIdm.accel(40, INFINITY, 0, 20), 1.5 * (1 - 16), 1e-12);  // twice v0: brakes
  // Reversing counts as standing; a desired speed of 0 counts as 0.1 m/s.
  EXPECT_DOUBLE_EQ(kIdm.accel(-1, INFINITY, 0, 20), 1.5);
  EXPECT_NEAR(kIdm.accel(0.05, INFINITY, 0, 0), 1.5 * (1 - 0.0625), 1e-12);
}

TEST(Idm, FollowingAtTheLeadersSpeed) {
  // v = vl = 10, v0 = 20, gap 20: s* = 2 + 10 * 1.5 = 17;
  // 1.5 (1 - 0.5^4 - (17/20)^2) = 1.5 (1 - 0.0625 - 0.7225) = 0.3225.
  EXPECT_NEAR(kIdm.accel(10, 20, 10, 20), 0.3225, 1e-12);
  // Closing in on a standing leader: v 10, v0 13.9, gap 30:
  // s* = 2 + 15 + 10 * 10 / (2 sqrt(3)) = 45.8675; 1.5 (1 - (10/13.9)^4 - (s*/30)^2).
  const double s_star = 2 + 15 + 100 / (2 * std::sqrt(3.0));
  const double expected = 1.5 * (1 - std::pow(10 / 13.9, 4) - (s_star / 30) * (s_star / 30));
  EXPECT_NEAR(kIdm.accel(10, 30, 0, 13.9), expected, 1e-12);
  EXPECT_NEAR(kIdm.accel(10, 30, 0, 13.9), -2.408202, 1e-6);
  // A gap of nothing is taken as 0.01 m: standing behind, s* = s0 = 2: -1.5 * 200^2.
  EXPECT_NEAR(kIdm.accel(0, 0, 0, 13.9), 1.5 - 1.5 * 40000, 1e-6);
  // Far faster leader: the max(0, ...) keeps s* at s0 at least.
  EXPECT_NEAR(kIdm.accel(1, 100, 30, 13.9),
              1.5 * (1 - std::pow(1 / 13.9, 4) - (2.0 / 100) * (2.0 / 100)), 1e-12);
}

TEST(Idm, StopsBehindAStandingLeaderAtTheJamDistance) {
  // 100 m behind a standing car at 10 m/s, Euler steps of 50 ms as the engine takes them.
  double x = 0, v = 10, min_gap = INFINITY, hardest = 0;
  const double leader = 100, dt = 0.05;
  for (int i = 0; i < 2400; ++i) {
    const double acc = std::clamp(kIdm.accel(v, leader - x, 0, 13.9), -9.0, kIdm.a);
    v = std::max(0.0, v + acc * dt);
    x += v * dt;
    min_gap = std::min(min_gap, leader - x);
    hardest = std::min(hardest, acc);
  }
  EXPECT_EQ(v, 0);
  EXPECT_NEAR(leader - x, kIdm.s0, 0.01);  // stands at s0 (1.9999 m)
  EXPECT_GT(min_gap, 1.99);                // never closer
  EXPECT_GT(hardest, -kIdm.b);             // and never braking harder than b (-1.64)
  EXPECT_LT(hardest, -1.5);
}

}  // namespace
}  // namespace convoy::road_users
