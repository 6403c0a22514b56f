// MOBIL: a change taken for a real gain, refused when the new follower would brake harder
// than b_safe, when someone is beside, and when politeness weighs the others' loss.
#include "road_users/mobil.h"

#include <gtest/gtest.h>

#include <cmath>

namespace convoy::road_users {
namespace {

// T 1.5, s0 2, a 1.5, b 2, delta 4; desired speed 20 m/s, everyone's (the followers' is v0).
const Idm kIdm{.v0 = 20};
const Mobil kMobil;  // politeness 0.3, threshold 0.2, b_safe 4
constexpr double kLength = 4.5;

LaneNeighbour at(double gap, double speed) { return {true, gap, speed}; }

TEST(Mobil, ChangesAwayFromASlowLeaderIntoAnEmptyLane) {
  // 15 m/s (v0 20) 20 m behind one at 5 m/s; the other lane empty.
  // Stay: s* = 2 + 22.5 + 15 * 10 / (2 sqrt 3) = 67.801; 1.5 (1 - 0.75^4 - (s*/20)^2) = -16.2134.
  // Change: 1.5 (1 - 0.75^4) = 1.025390625.
  const LaneNeighbours here{at(20, 5), {}}, there;
  const MobilDecision d = decide_lane_change(kIdm, kMobil, 15, 20, kLength, here, there);
  EXPECT_EQ(d.outcome, LaneChange::kChange);
  EXPECT_NEAR(d.incentive, 1.025390625 + 16.213405272, 1e-6);
}

TEST(Mobil, StaysWithoutAGainOverTheThreshold) {
  // Both lanes empty: no gain at all.
  EXPECT_EQ(decide_lane_change(kIdm, kMobil, 15, 20, kLength, {}, {}).outcome,
            LaneChange::kNotWorth);
  // The same leader in both lanes: no gain either.
  const LaneNeighbours lane{at(20, 5), {}};
  const MobilDecision d = decide_lane_change(kIdm, kMobil, 15, 20, kLength, lane, lane);
  EXPECT_EQ(d.outcome, LaneChange::kNotWorth);
  EXPECT_DOUBLE_EQ(d.incentive, 0);
}

TEST(Mobil, RefusesWhenTheNewFollowerWouldBrakeHarderThanBSafe) {
  // Same gain as above, but one at 20 m/s 3 m behind in the target lane: behind me at 15 m/s
  // it would brake at 1.5 (1 - 1 - ((2 + 30 + 20 * 5 / (2 sqrt 3)) / 3)^2) = -617.5 m/s^2.
  const LaneNeighbours here{at(20, 5), {}}, there{{}, at(3, 20)};
  EXPECT_EQ(decide_lane_change(kIdm, kMobil, 15, 20, kLength, here, there).outcome,
            LaneChange::kUnsafe);
  // With b_safe beyond that and no politeness (0.3 of its loss would outweigh my gain of
  // 17.24), the same change is taken; with b_safe just under 617.4757 it is not.
  Mobil reckless = kMobil;
  reckless.b_safe = 1000;
  reckless.politeness = 0;
  EXPECT_EQ(decide_lane_change(kIdm, reckless, 15, 20, kLength, here, there).outcome,
            LaneChange::kChange);
  reckless.b_safe = 617.47;
  EXPECT_EQ(decide_lane_change(kIdm, reckless, 15, 20, kLength, here, there).outcome,
            LaneChange::kUnsafe);
  reckless.b_safe = 617.48;
  EXPECT_EQ(decide_lane_change(kIdm, reckless, 15, 20, kLength, here, there).outcome,
            LaneChange::kChange);
}

TEST(Mobil, RefusesWhenSomeoneIsBeside) {
  const LaneNeighbours here{at(20, 5), {}};
  EXPECT_EQ(decide_lane_change(kIdm, kMobil, 15, 20, kLength, here, {at(-1, 15), {}}).outcome,
            LaneChange::kBlocked);
  EXPECT_EQ(decide_lane_change(kIdm, kMobil, 15, 20, kLength, here, {{}, at(-0.5, 15)}).outcome,
            LaneChange::kBlocked);
}

TEST(Mobil, PolitenessWeighsTheNewFollowersLoss) {
  // 14 m/s 40 m behind one at 12: a_c = 1.5 (1 - 0.7^4 - (31.0829/40)^2) = 0.234087;
  // the other lane has no leader: a_c2 = 1.5 (1 - 0.7^4) = 1.13985. Its follower, at 14 m/s
  // 20 m behind, goes from free (1.13985) to following me: 1.5 (1 - 0.2401 - (23/20)^2) =
  // -0.8439 (safe). Incentive 0.905763 - politeness * 1.98375.
  const LaneNeighbours here{at(40, 12), {}}, there{{}, at(20, 14)};
  Mobil m = kMobil;
  m.politeness = 0;
  MobilDecision d = decide_lane_change(kIdm, m, 14, 20, kLength, here, there);
  EXPECT_EQ(d.outcome, LaneChange::kChange);
  EXPECT_NEAR(d.incentive, 0.905763, 1e-6);
  m.politeness = 0.3;
  d = decide_lane_change(kIdm, m, 14, 20, kLength, here, there);
  EXPECT_EQ(d.outcome, LaneChange::kChange);
  EXPECT_NEAR(d.incentive, 0.310638, 1e-6);
  m.politeness = 0.5;  // over 0.3558 the others' loss wins
  d = decide_lane_change(kIdm, m, 14, 20, kLength, here, there);
  EXPECT_EQ(d.outcome, LaneChange::kNotWorth);
  EXPECT_NEAR(d.incentive, -0.086112, 1e-6);
}

TEST(Mobil, CountsTheOldFollowersGain) {
  // An old follower 10 m behind at 10 m/s is held up by me (at 10 m/s) and freed when I leave
  // (no leader in my lane): with politeness 1 that gain alone makes the change.
  // a_o = 1.5 (1 - 0.5^4 - (17/10)^2) and a_o2 = 1.5 (1 - 0.5^4): a gain of 1.5 * 1.7^2.
  const LaneNeighbours here{{}, at(10, 10)}, there;
  Mobil m = kMobil;
  m.politeness = 1;
  const MobilDecision d = decide_lane_change(kIdm, m, 10, 20, kLength, here, there);
  EXPECT_EQ(d.outcome, LaneChange::kChange);
  EXPECT_NEAR(d.incentive, 1.5 * 1.7 * 1.7, 1e-9);
}

}  // namespace
}  // namespace convoy::road_users
