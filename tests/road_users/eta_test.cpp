// The junction arrival time: accelerating only, up to v0 then on at it, already faster, and
// the edge cases.
#include "road_users/eta.h"

#include <gtest/gtest.h>

#include <cmath>

namespace convoy::road_users {
namespace {

TEST(Eta, NothingToCover) {
  EXPECT_EQ(eta(0, 5, 1, 10), 0);
  EXPECT_EQ(eta(-3, 5, 1, 10), 0);
}

TEST(Eta, WhileStillAccelerating) {
  // From standing at 1 m/s^2: 8 m in sqrt(2 * 8) = 4 s (it reaches v0 10 only at 50 m).
  EXPECT_DOUBLE_EQ(eta(8, 0, 1, 10), 4);
  // From 2 m/s at 2 m/s^2: 2t + t^2 = 8, t = 2.
  EXPECT_DOUBLE_EQ(eta(8, 2, 2, 10), 2);
  // A negative speed counts as standing.
  EXPECT_DOUBLE_EQ(eta(8, -3, 1, 10), 4);
}

TEST(Eta, ThenAtItsDesiredSpeed) {
  // From standing at 1 m/s^2 to 10 m/s: 10 s and 50 m, then 20 m more at 10 m/s.
  EXPECT_DOUBLE_EQ(eta(70, 0, 1, 10), 12);
  EXPECT_DOUBLE_EQ(eta(50, 0, 1, 10), 10);  // just as it reaches v0
  // From 6 m/s at 2 m/s^2: 2 s and 16 m, then 24 m at 10.
  EXPECT_DOUBLE_EQ(eta(40, 6, 2, 10), 4.4);
}

TEST(Eta, FasterThanItsDesiredSpeedKeepsItsSpeed) {
  EXPECT_DOUBLE_EQ(eta(30, 15, 1, 10), 2);  // 30 m at 15 m/s
  EXPECT_DOUBLE_EQ(eta(30, 10, 1, 10), 3);  // exactly at v0
  // Standing with a desired speed of 0: never gets there, but at 0.1 m/s it is finite.
  EXPECT_DOUBLE_EQ(eta(1, 0, 1, 0), 10);
}

}  // namespace
}  // namespace convoy::road_users
