// Routing on the lane graph of tests/opendrive/data/lane_graph.xodr: a:-1 east (x 0..100, two
// sections), b:1 on to x 180, then junction j forks: d:1 straight on to e:-1 (x 200..250, a
// dead end) or f:-1 right to g:-1 (south, a dead end).
#include "road_users/routing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "opendrive/parser.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;

struct Map {
  odr::Network net = odr::load(CONVOY_LANE_GRAPH_XODR);
  odr::LaneGraph graph{net};
  odr::LaneIndex a = graph.find("a", -1, 0), b = graph.find("b", 1, 40);
  odr::LaneIndex e = graph.find("e", -1, 25), g = graph.find("g", -1, 25);
  // The ends of e:-1 and g:-1 (both run along their roads).
  Goal e_end{e, 50}, g_end{g, 50};
};

const Map& map() {
  static const Map m;
  return m;
}

std::string last_road(const odr::LaneRoute& r) { return r.segments.back().road_id; }

TEST(Routing, OnwardDrawsOneChoicePerFork) {
  const Map& m = map();
  for (uint64_t seed = 0; seed < 8; ++seed) {
    std::mt19937_64 rng(seed), before(seed);
    bool open = true;
    const odr::LaneRoute r = onward(m.graph, m.a, 0, 1000, rng, &open);
    EXPECT_FALSE(open);  // both ways end at a dead end
    // One fork (at j, two ways): one draw, and the way it picked.
    const bool straight = before() % 2 == 0;
    EXPECT_EQ(rng, before);
    const odr::LaneNode& d = m.graph.lane(m.graph.successors(m.b)[0]);
    EXPECT_EQ(last_road(r), (d.road->id == "d") == straight ? "e" : "g");
    EXPECT_EQ(r.segments.front().s_from, 0);
    EXPECT_EQ(r.cost, r.length);
    ASSERT_EQ(r.junctions.size(), 1u);
    EXPECT_EQ(r.junctions[0], "j");
    if (last_road(r) == "e") {
      EXPECT_NEAR(r.length, 250, 1e-6);
    }
  }
}

TEST(Routing, OnwardStopsAfterItsLength) {
  const Map& m = map();
  std::mt19937_64 rng(1), before(1);
  bool open = false;
  // a:-1's first section (50 m) is longer than 30 m: that section alone, the lane graph open.
  const odr::LaneRoute r = onward(m.graph, m.a, 10, 30, rng, &open);
  EXPECT_TRUE(open);
  ASSERT_EQ(r.segments.size(), 1u);
  EXPECT_EQ(r.segments[0].s_from, 10);
  EXPECT_EQ(r.segments[0].s_to, 50);
  EXPECT_NEAR(r.length, 40, 1e-9);
  EXPECT_EQ(rng, before);  // no fork: no draw
}

TEST(Routing, ThroughItsGoals) {
  const Map& m = map();
  std::mt19937_64 rng(3);
  const RoutePlan plan{m.graph, 600, rng};
  bool open = true;
  size_t failed = 9;
  auto r = route_from(plan, {m.e_end}, false, m.a, 0, 0, &open, &failed);
  ASSERT_TRUE(r);
  EXPECT_FALSE(open);
  EXPECT_EQ(last_road(*r), "e");
  EXPECT_EQ(r->segments.back().s_to, 50);
  EXPECT_NEAR(r->length, 250, 1e-6);
  // From the first goal on (the others passed): the same to e from anywhere before it.
  r = route_from(plan, {m.g_end, m.e_end}, false, m.a, 0, 1, &open, &failed);
  ASSERT_TRUE(r);
  EXPECT_EQ(last_road(*r), "e");
  // A goal it cannot reach (e is a dead end, a behind it): nullopt naming it, open untouched.
  open = true;
  r = route_from(plan, {m.e_end, Goal{m.a, 20}}, false, m.a, 0, 0, &open, &failed);
  EXPECT_FALSE(r);
  EXPECT_EQ(failed, 1u);
  EXPECT_TRUE(open);
  // At its goal already: one segment of no length there.
  r = route_from(plan, {}, false, m.e, 30, 0, &open, &failed);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->segments.size(), 1u);
  EXPECT_EQ(r->segments[0].road_id, "e");
  EXPECT_EQ(r->segments[0].s_from, 30);
  EXPECT_EQ(r->segments[0].s_to, 30);
  EXPECT_FALSE(open);
}

TEST(Routing, OnwardAfterItsGoalsAndGivingThemUp) {
  const Map& m = map();
  std::mt19937_64 rng(5), same(5);
  const RoutePlan plan{m.graph, 600, rng};
  bool open = true;
  size_t failed = 0;
  // Through b's end, then onward: the same as onward alone from a's start.
  const Goal b_end{m.b, 0};
  auto r = route_from(plan, {b_end}, true, m.a, 0, 0, &open, &failed);
  ASSERT_TRUE(r);
  bool open2 = true;
  const odr::LaneRoute direct = onward(m.graph, m.a, 0, 1000, same, &open2);
  EXPECT_EQ(last_road(*r), last_road(direct));
  EXPECT_EQ(r->segments.size(), direct.segments.size());
  EXPECT_FALSE(open);
  // A goal it cannot reach from e: given up, onward from there (e's end).
  std::vector<Goal> goals{Goal{m.a, 20}};
  bool go_on = false;
  const odr::LaneRoute p = plan_from(plan, goals, go_on, m.e, 10, &open);
  EXPECT_TRUE(goals.empty());
  EXPECT_TRUE(go_on);
  ASSERT_EQ(p.segments.size(), 1u);
  EXPECT_EQ(p.segments[0].s_from, 10);
  EXPECT_EQ(p.segments[0].s_to, 50);
  EXPECT_FALSE(open);
  // One it can reach: kept.
  goals = {m.e_end};
  go_on = false;
  EXPECT_EQ(last_road(plan_from(plan, goals, go_on, m.a, 0, &open)), "e");
  EXPECT_EQ(goals.size(), 1u);
  EXPECT_FALSE(go_on);
}

TEST(Routing, KeepingALane) {
  const Map& m = map();
  std::mt19937_64 rng(7);
  const RoutePlan plan{m.graph, 600, rng};
  bool open = false;
  // No goals and not onward: none; onward: the lane graph on from the target.
  EXPECT_FALSE(route_keeping(plan, {}, false, m.a, 10, 1, &open));
  auto r = route_keeping(plan, {}, true, m.a, 10, 1, &open);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->segments.front().s_from, 10);
  // Into a:-1 from a:-2 (shift +1): e has no lane 0, so any route to the goal, e's end.
  const odr::LaneIndex a2 = m.graph.find("a", -2, 10);
  ASSERT_NE(a2, odr::kNoLane);
  r = route_keeping(plan, {m.e_end}, false, m.a, 10, 1, &open);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->segments.front().lane, m.a);
  EXPECT_EQ(last_road(*r), "e");
  // Through a first goal on b and then the second, e's end.
  r = route_keeping(plan, {Goal{m.b, 40}, m.e_end}, false, m.a, 10, 0, &open);
  ASSERT_TRUE(r);
  EXPECT_EQ(last_road(*r), "e");
  EXPECT_EQ(r->segments.back().s_to, 50);
  // The second goal out of reach: none.
  EXPECT_FALSE(route_keeping(plan, {m.e_end, Goal{m.a, 20}}, false, m.a, 10, 0, &open));
}

TEST(Routing, GoalArcsAlongThePath) {
  const Map& m = map();
  const Path p = make_path(m.graph, *m.graph.route("a", -1, "e", -1), 0.5);
  // b's s 40 is x 140; e's end (clamped 1 mm inside it) is x 250.
  const std::vector<double> arcs = goal_arcs(m.graph, p, {Goal{m.b, 40}, m.e_end});
  ASSERT_EQ(arcs.size(), 2u);
  EXPECT_NEAR(arcs[0], 140, 1e-6);
  EXPECT_NEAR(arcs[1], 250 - 1e-3, 1e-6);
  EXPECT_TRUE(goal_arcs(m.graph, p, {}).empty());
}

TEST(Routing, ExtendedFrom30MetresBehind) {
  const Map& m = map();
  const Path p = make_path(m.graph, *m.graph.route("a", -1, "b", 1), 0.5);
  ASSERT_GE(p.route.segments.size(), 3u);  // a:-1 in its two sections, b:1
  std::mt19937_64 rng(11), before(11);
  const RoutePlan plan{m.graph, 600, rng};
  bool open = true;
  // At arc 170 the first section of a (to x 50) is more than one segment behind 140: dropped.
  odr::LaneRoute r = extended(plan, p, 170, &open);
  EXPECT_FALSE(open);
  EXPECT_EQ(r.segments.front().road_id, "a");
  EXPECT_EQ(r.segments.front().s_from, 50);
  EXPECT_FALSE(r.segments.front().lane_change);
  EXPECT_TRUE(last_road(r) == "e" || last_road(r) == "g");
  before();
  EXPECT_EQ(rng, before);  // one fork, one draw
  // Near the start: all of it kept.
  r = extended(plan, p, 20, &open);
  EXPECT_EQ(r.segments.front().s_from, 0);
  // b's segment goes on into the onward part (no segment repeats b).
  int on_b = 0;
  for (const auto& s : r.segments) on_b += s.road_id == "b";
  EXPECT_EQ(on_b, 1);
}

}  // namespace
}  // namespace convoy::road_users
