// Paths: lookups by arc and projection on a hand-built polyline, and a path on the lane graph
// of tests/opendrive/data/lane_graph.xodr with its stop line and junction crossing.
#include "road_users/path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "opendrive/parser.h"

namespace convoy::road_users {
namespace {

namespace odr = convoy::opendrive;

TEST(Path, AlongAPolyline) {
  // 5 m from (0, 0) to (3, 4): ten poses 0.5 m apart (eleven with both ends).
  const Path p = polyline_path({{0, 0}, {3, 4}}, 0.5, 0, 0);
  ASSERT_EQ(p.poses.size(), 11u);
  EXPECT_NEAR(p.length(), 5, 1e-12);
  for (size_t i = 0; i < p.poses.size(); ++i) {
    EXPECT_NEAR(p.arc[i], 0.5 * i, 1e-12);
    EXPECT_NEAR(p.poses[i].heading, std::atan2(4, 3), 1e-15);
  }
  const odr::Pose2 mid = p.at(2.5);
  EXPECT_NEAR(mid.x, 1.5, 1e-12);
  EXPECT_NEAR(mid.y, 2.0, 1e-12);
  const odr::Pose2 q = p.at(0.8);  // between poses 1 and 2
  EXPECT_NEAR(q.x, 0.48, 1e-12);
  EXPECT_NEAR(q.y, 0.64, 1e-12);
  // Clamped at both ends.
  EXPECT_EQ(p.at(-1).x, 0);
  EXPECT_EQ(p.at(7).x, 3);
  // A second segment goes on from the first; a repeated point adds nothing.
  const Path bent = polyline_path({{0, 0}, {2, 0}, {2, 0}, {2, 1}}, 0.5, 0, 0);
  ASSERT_EQ(bent.poses.size(), 7u);
  EXPECT_NEAR(bent.length(), 3, 1e-12);
  EXPECT_NEAR(bent.poses.back().heading, M_PI / 2, 1e-15);
}

TEST(Path, OnePointIsAPoseTowardsIt) {
  const Path p = polyline_path({{5, 5}}, 0.5, 0, 0);
  ASSERT_EQ(p.poses.size(), 1u);
  EXPECT_EQ(p.length(), 0);
  EXPECT_NEAR(p.poses[0].heading, M_PI / 4, 1e-15);
  EXPECT_EQ(p.at(3).x, 5);
}

TEST(Path, ProjectsOntoTheNearestPose) {
  const Path p = polyline_path({{0, 0}, {3, 4}}, 0.5, 0, 0);
  // (3, 0): 1.8 m along the line, 2.4 m to its right (nearest pose: (1.2, 1.6)).
  const Path::Proj pr = p.project(3, 0);
  EXPECT_EQ(pr.index, 4u);
  EXPECT_NEAR(pr.arc, 1.8, 1e-12);
  EXPECT_NEAR(pr.lateral, -2.4, 1e-12);
  EXPECT_NEAR(pr.d2, 1.8 * 1.8 + 1.6 * 1.6, 1e-12);
  // Only among poses [lo, hi): the nearest of 8..10 is 8.
  const Path::Proj far = p.project(3, 0, 8);
  EXPECT_EQ(far.index, 8u);
  EXPECT_NEAR(far.arc, 1.8, 1e-12);  // the same foot point from another pose on the line
  // An empty range: nothing.
  EXPECT_FALSE(std::isfinite(p.project(3, 0, 5, 5).d2));
}

// project skips poses it can prove farther than the best one: the same answer as trying
// every pose, on a path that winds back near itself, for points on, beside and far from it,
// with or without a hint of where to look.
TEST(Path, ProjectionSkipsOnlyFartherPoses) {
  Points pts;
  for (int k = 0; k <= 400; ++k) {
    const double t = 0.05 * k;
    pts.push_back({30 * std::cos(t) + 2 * t, 20 * std::sin(1.5 * t)});
  }
  const Path p = polyline_path(pts, 0.7, 0, 0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> coord(-80, 80);
  std::uniform_int_distribution<size_t> index(0, p.poses.size());
  for (int n = 0; n < 3000; ++n) {
    const double x = coord(rng), y = coord(rng);
    size_t lo = index(rng), hi = index(rng);
    if (n % 3 == 0) lo = 0, hi = SIZE_MAX;
    size_t want = 0;
    double want_d2 = INFINITY;
    for (size_t i = lo; i < std::min(hi, p.poses.size()); ++i) {
      const double dx = x - p.poses[i].x, dy = y - p.poses[i].y;
      const double d2 = dx * dx + dy * dy;
      if (d2 < want_d2) want_d2 = d2, want = i;
    }
    const size_t hint = n % 2 ? index(rng) : SIZE_MAX;  // anywhere: only speed depends on it
    const Path::Proj got = p.project(x, y, lo, hi, hint);
    ASSERT_EQ(got.d2, want_d2) << x << " " << y << " [" << lo << ", " << hi << ")";
    if (std::isfinite(want_d2)) {
      ASSERT_EQ(got.index, want);
    }
  }
}

TEST(Path, HeadingInterpolatesTheShortWayRound) {
  Path p;
  p.poses = {{0, 0, 3.1, 0}, {1, 0, -3.1, 0}};
  p.arc = {0, 1};
  EXPECT_NEAR(p.at(0.5).heading, 3.1 + 0.5 * (2 * M_PI - 6.2), 1e-12);
}

TEST(Path, AppendSkipsRepeatedPoses) {
  Path p;
  p.append({{1, 1, 0, 0}});
  ASSERT_EQ(p.arc, std::vector<double>{0.0});
  // (4, 5) is 5 m on; a pose 1e-7 m from the last is dropped; then 2 m back along x.
  p.append({{4, 5, 0.3, 0}, {4 + 1e-7, 5, 0.4, 0}, {2, 5, M_PI, 0}});
  ASSERT_EQ(p.poses.size(), 3u);
  EXPECT_EQ(p.arc, (std::vector<double>{0.0, 5.0, 7.0}));
  EXPECT_EQ(p.poses[1].heading, 0.3);
  EXPECT_EQ(p.length(), 7.0);
}

TEST(Path, OnTheLaneGraph) {
  const odr::Network net = odr::load(CONVOY_LANE_GRAPH_XODR);
  const odr::LaneGraph graph(net);
  // a:-1 east along y = -1.75 from x 0 to 100, b:1 on to 180 (its light s1 at b's s 5, x 175),
  // through junction j on d:1 (x 180..200) to the end of e:-1 (x 250).
  const auto route = graph.route("a", -1, "e", -1);
  ASSERT_TRUE(route);
  const Path p = make_path(graph, *route, 0.5);
  EXPECT_NEAR(p.length(), 250, 1e-6);
  EXPECT_NEAR(p.poses.front().x, 0, 1e-9);
  EXPECT_NEAR(p.poses.back().x, 250, 1e-9);
  for (size_t i = 1; i < p.poses.size(); ++i) {
    ASSERT_LE(p.arc[i] - p.arc[i - 1], 0.5 + 1e-9);
    ASSERT_NEAR(p.poses[i].y, -1.75, 1e-9);
  }
  ASSERT_EQ(p.stops.size(), 1u);
  EXPECT_NEAR(p.stops[0].first, 175, 1e-6);
  EXPECT_EQ(p.stops[0].second, "s1");
  ASSERT_EQ(p.crossings.size(), 1u);
  EXPECT_EQ(p.crossings[0].junction, "j");
  EXPECT_NEAR(p.crossings[0].enter, 180, 1e-6);
  EXPECT_NEAR(p.crossings[0].exit, 200, 1e-6);
  EXPECT_EQ(p.route.segments.size(), route->segments.size());
  // The way to g turns right in the junction: a crossing as long as the quarter circle, radius
  // 18.25 m, of lane f:-1.
  const Path turn = make_path(graph, *graph.route("a", -1, "g", -1), 0.5);
  ASSERT_EQ(turn.crossings.size(), 1u);
  EXPECT_NEAR(turn.crossings[0].exit - turn.crossings[0].enter, 18.25 * M_PI / 2, 0.02);
}

}  // namespace
}  // namespace convoy::road_users
