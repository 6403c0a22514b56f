// neighbour_views: the users within the radius of each centre, in index order, against a
// brute-force search; the agent itself left out; time_ns appended as RoadUsers' field 2.
#include "python/neighbour_views.h"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

namespace convoy::python {
namespace {

TEST(NeighbourViews, TheUsersWithinTheRadiusInIndexOrder) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> coord(-250, 250);
  std::vector<std::string> names;
  std::vector<double> xs, ys;
  for (int i = 0; i < 400; ++i) {
    names.push_back("<" + std::to_string(i) + ">");
    xs.push_back(coord(rng));
    ys.push_back(coord(rng));
  }
  // Users exactly on the radius of user 0 count; a hair beyond does not.
  xs.push_back(xs[0] + 40);
  ys.push_back(ys[0]);
  names.push_back("<on>");
  xs.push_back(xs[0]);
  ys.push_back(ys[0] - 40.000001);
  names.push_back("<off>");
  const std::vector<std::string_view> frames(names.begin(), names.end());
  std::vector<ViewCentre> centres;
  for (int i = 0; i < 60; ++i) centres.push_back({xs[i], ys[i], i, 0});
  centres.push_back({coord(rng), coord(rng), -1, 0});
  const double radius = 40;
  const std::vector<std::string> got = neighbour_views(frames, xs, ys, centres, radius);
  ASSERT_EQ(got.size(), centres.size());
  for (size_t c = 0; c < centres.size(); ++c) {
    std::string want;
    for (size_t j = 0; j < frames.size(); ++j) {
      const double dx = xs[j] - centres[c].x, dy = ys[j] - centres[c].y;
      if (dx * dx + dy * dy <= radius * radius && static_cast<int64_t>(j) != centres[c].me)
        want += names[j];
    }
    EXPECT_EQ(got[c], want) << "centre " << c;
  }
  EXPECT_NE(got[0].find("<on>"), std::string::npos);
  EXPECT_EQ(got[0].find("<off>"), std::string::npos);
  EXPECT_EQ(got[0].find("<0>"), std::string::npos);  // not itself
}

TEST(NeighbourViews, TimeIsFieldTwoAsAVarint) {
  const std::vector<std::string_view> frames = {"a"};
  const auto got =
      neighbour_views(frames, {0.0}, {0.0}, {{1, 0, -1, 300}, {1, 0, -1, 0}, {500, 0, -1, 1}}, 10);
  EXPECT_EQ(got[0], std::string("a\x10\xac\x02"));  // 300 = 0b10'0101100
  EXPECT_EQ(got[1], "a");                           // 0 is left out, as protobuf does
  EXPECT_EQ(got[2], std::string("\x10\x01"));       // nobody near
}

TEST(NeighbourViews, BadArguments) {
  const std::vector<std::string_view> frames = {"a"};
  EXPECT_THROW(neighbour_views(frames, {0.0, 1.0}, {0.0}, {}, 10), std::invalid_argument);
  EXPECT_THROW(neighbour_views(frames, {0.0}, {0.0}, {}, 0), std::invalid_argument);
}

}  // namespace
}  // namespace convoy::python
