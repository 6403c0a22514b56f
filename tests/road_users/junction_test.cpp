// Junction yielding at junction j of tests/opendrive/data/lane_graph.xodr. My path is a
// straight line north along x = 190 (not on the map: only the others are located on it) that
// enters j 50 m ahead of my front and leaves it 20 m later; the others come along lane b:1,
// eastwards towards j (b's s falls from 80 at x 100 to 0 at x 180).
#include "road_users/junction.h"

#include <gtest/gtest.h>

#include <cmath>

#include "opendrive/parser.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;

class JunctionWait : public ::testing::Test {
 protected:
  const odr::Network net = odr::load(CONVOY_LANE_GRAPH_XODR);
  const odr::LaneGraph graph{net};
  const Path path = [] {
    Path p = polyline_path({{190, -100}, {190, 100}}, 0.5, 0, 0);
    p.crossings = {{"j", 133.5, 153.5}};
    return p;
  }();
  // Me at (190, -20), 10 m/s, front at arc 83.5: 50 m to j. IDM a 1.5, v0 13.9: I arrive in
  // 2.6 + (50 - 31.07) / 13.9 = 3.96187 s and have left j (74.5 m) at 5.72446 s.
  Approach at{&path, 160, 83.5, 4.5, 9, Idm{.v0 = 13.9, .a = 1.5}};
  Observer me{"me", 190, -20, M_PI / 2, 10, 100};

  // A 4.5 m car on b:1 at x (heading east), its front 3.6 m ahead of its reference point.
  static Neighbour on_b(const char* id, double x, double speed) {
    return {id, x, -1.75, 0, speed, 4.5, 1.8, 1.35};
  }
  double wait(const Neighbours& around, const LightStates* lights = nullptr) const {
    return junction_wait(graph, at, me, around, lights);
  }
};

TEST_F(JunctionWait, FreeWhenNobodyComes) { EXPECT_EQ(wait({}), INFINITY); }

TEST_F(JunctionWait, OneInsideBlocks) {
  // On d:1 inside j.
  EXPECT_EQ(wait({{"in", 185, -1.75, 0, 5, 4.5, 1.8, 1.35}}), 50);
  // One on my own path inside j (along it, heading north) is IDM's business.
  EXPECT_EQ(wait({{"ahead", 190, -1, M_PI / 2, 5, 4.5, 1.8, 1.35}}), INFINITY);
}

TEST_F(JunctionWait, FirstComeFirstServed) {
  // At s 30 (x 150): its front 26.4 m from j at 10 m/s: there in 2.2577 s, before me.
  EXPECT_EQ(wait({on_b("a", 150, 10)}), 50);
  // Standing at s 60 (x 120): 56.4 m in 8.6718 s, after me.
  EXPECT_EQ(wait({on_b("a", 120, 0)}), INFINITY);
}

TEST_F(JunctionWait, ATieGoesToTheSmallerId) {
  // At s 53.6 (x 126.4) at 10 m/s: 50 m from j, as I am, at my speed.
  EXPECT_EQ(wait({on_b("a", 126.4, 10)}), 50);
  EXPECT_EQ(wait({on_b("z", 126.4, 10)}), INFINITY);
}

TEST_F(JunctionWait, OneHeldByItsRedLightIsNotCounted) {
  const LightStates red{{"s1", Light::kRed}}, green{{"s1", Light::kGreen}};
  EXPECT_EQ(wait({on_b("a", 150, 10)}, &red), INFINITY);
  EXPECT_EQ(wait({on_b("a", 150, 10)}, &green), 50);
}

TEST_F(JunctionWait, OneThatCannotStopAnyMoreGoesFirst) {
  // At 14 m/s, its front 60 m from j (s 63.6, x 116.4): there in 4.2857 s, after me, but it
  // would need 14 + 14^2 / 4 = 63 m to stop and arrives before I have left j (+ 0.5 s).
  EXPECT_EQ(wait({on_b("z", 116.4, 14)}), 50);
  // 70 m from j (x 106.4): it can still stop.
  EXPECT_EQ(wait({on_b("z", 106.4, 14)}), INFINITY);
}

TEST_F(JunctionWait, NotWhenFarCommittedOrInside) {
  const Neighbours inside{{"in", 185, -1.75, 0, 5, 4.5, 1.8, 1.35}};
  me.speed = 31;  // 31^2 / 18 = 53.4 m to stop: committed
  EXPECT_EQ(wait(inside), INFINITY);
  me.speed = 30;  // 50 m: it can stop
  EXPECT_EQ(wait(inside), 50);
  me.speed = 10;
  at.front = 30;  // 103.5 m: farther than its radius
  EXPECT_EQ(wait(inside), INFINITY);
  at.front = 140;  // in j already
  EXPECT_EQ(wait(inside), INFINITY);
  at.front = 158.5;  // left it (and its rear by 0.5 m): no junction ahead
  EXPECT_EQ(wait(inside), INFINITY);
}

}  // namespace
}  // namespace convoy::road_users
