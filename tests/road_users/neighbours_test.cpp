// The neighbours that matter: the leader on a path (in the lane, ahead of my front, within
// the radius), the leader and follower in a band of the road in my frame, a free spot.
#include "road_users/neighbours.h"

#include <gtest/gtest.h>

#include <cmath>

namespace convoy::road_users {
namespace {

// A car 4 m long, its box centred on its reference point unless offset.
Neighbour car(double x, double y, double speed, double width = 1.8, double offset = 0) {
  return {"n", x, y, 0, speed, 4.0, width, offset};
}

class LeaderOn : public ::testing::Test {
 protected:
  // East along y = 0 from x 0 to 100; me at x 10 (the path's pose 20), my front at arc 14.
  const Path path = polyline_path({{0, 0}, {100, 0}}, 0.5, 0, 0);
  const Observer me{"me", 10, 0, 0, 10, 100};
  LaneNeighbour leader(const Neighbours& around, const Observer& o) const {
    return leader_on(path, 20, 14, 0.5, o, around);
  }
  LaneNeighbour leader(const Neighbours& around) const { return leader(around, me); }
};

TEST_F(LeaderOn, TheNearestInMyLaneAheadOfMyFront) {
  // At x 30, 0.5 m to the left, its centre 1.5 m ahead: rear at 30 + 1.5 - 2 = 29.5, 15.5 m
  // from my front. One at x 50 is farther; one 2.5 m to the side (more than 1 + 0.9) is not
  // in my lane; one at x 5 (front at 7) is behind me.
  const Neighbours around{car(50, 0, 3), car(30, 0.5, 8, 2.0, 1.5), car(25, 2.5, 1), car(5, 0, 2)};
  const LaneNeighbour l = leader(around);
  EXPECT_TRUE(l.found);
  EXPECT_NEAR(l.gap, 15.5, 1e-9);
  EXPECT_EQ(l.speed, 8);
}

TEST_F(LeaderOn, AnUnknownWidthCountsAs1_8m) {
  // 1.85 m to the side: in my lane when 1.8 m wide (1 + 0.9 >= 1.85) or of unknown width, not
  // when 1.6 m wide (1 + 0.8 < 1.85). Its rear at 23: 9 m from my front.
  EXPECT_NEAR(leader({car(25, 1.85, 4, 0)}).gap, 9, 1e-9);
  EXPECT_NEAR(leader({car(25, 1.85, 4, 1.8)}).gap, 9, 1e-9);
  EXPECT_FALSE(leader({car(25, 1.85, 4, 1.6)}).found);
}

TEST_F(LeaderOn, BesideMeOnlyWhenItsFrontIsAheadOfMine) {
  // Front at 14, as mine: not a leader. Front at 15: a leader overlapping me by 3 m.
  EXPECT_FALSE(leader({car(12, 0, 4)}).found);
  const LaneNeighbour l = leader({car(13, 0, 4)});
  EXPECT_TRUE(l.found);
  EXPECT_NEAR(l.gap, -3, 1e-9);
}

TEST_F(LeaderOn, OnlyWithinItsRadius) {
  // (30, 0.5) is 20.006 m from me.
  Observer near = me;
  near.radius = 20;
  EXPECT_FALSE(leader({car(30, 0.5, 8)}, near).found);
  near.radius = 20.01;
  EXPECT_TRUE(leader({car(30, 0.5, 8)}, near).found);
  EXPECT_FALSE(leader({}).found);
  EXPECT_EQ(leader({}).gap, INFINITY);
}

TEST(LaneNeighbours, LeaderAndFollowerInABandOfMyFrame) {
  // Me at the origin heading north (a 4.5 m car: front 3.6 m ahead of its rear axle, rear
  // 0.9 m behind); the band is the lane to my left: centre 3.5 m (x = -3.5), 1.75 m either way.
  const Observer me{"me", 0, 0, M_PI / 2, 10, 100};
  auto at = [](double x, double y, double speed) {
    return Neighbour{"n", x, y, M_PI / 2, speed, 4.5, 1.8, 1.35};
  };
  // Leader at y 20 (rear at 19.1: 15.5 m from my front), one farther at y 40, follower at
  // y -10 (front at -6.4: 5.5 m behind my rear), one in my own lane, one to my right, one
  // beyond the radius.
  const Neighbours around{at(-3.0, 40, 1), at(-3.5, 20, 10), at(-4, -10, 12),
                          at(0, 10, 2),    at(3.5, 5, 3),    at(-3.5, 150, 4)};
  const LaneNeighbours n = lane_neighbours(me, around, 3.5, 1.75, 3.6, -0.9);
  EXPECT_TRUE(n.leader.found);
  EXPECT_NEAR(n.leader.gap, 15.5, 1e-9);
  EXPECT_EQ(n.leader.speed, 10);
  EXPECT_TRUE(n.follower.found);
  EXPECT_NEAR(n.follower.gap, 5.5, 1e-9);
  EXPECT_EQ(n.follower.speed, 12);
  // My own lane's band: the one at y 10 leads (rear at 9.1: 5.5 m); nobody follows.
  const LaneNeighbours own = lane_neighbours(me, around, 0, 1.75, 3.6, -0.9);
  EXPECT_NEAR(own.leader.gap, 5.5, 1e-9);
  EXPECT_FALSE(own.follower.found);
  // One beside me (front and rear ahead of mine): a leader with a negative gap (MOBIL: blocked);
  // one whose rear is behind mine follows, also overlapping.
  const LaneNeighbours beside = lane_neighbours(me, {at(-3.5, 1, 5)}, 3.5, 1.75, 3.6, -0.9);
  EXPECT_NEAR(beside.leader.gap, 0.1 - 3.6, 1e-9);
  const LaneNeighbours behind = lane_neighbours(me, {at(-3.5, -1, 5)}, 3.5, 1.75, 3.6, -0.9);
  EXPECT_FALSE(behind.leader.found);
  EXPECT_NEAR(behind.follower.gap, -0.9 - 2.6, 1e-9);
}

TEST(StartFree, NobodyWithinTheClearance) {
  const Neighbours around{{"n", 3, 4, 0, 0, 4, 1.8, 0}};  // 5 m from the origin
  EXPECT_TRUE(start_free(around, 0, 0, 5.0));
  EXPECT_FALSE(start_free(around, 0, 0, 5.01));
  EXPECT_TRUE(start_free({}, 0, 0, 100));
}

}  // namespace
}  // namespace convoy::road_users
