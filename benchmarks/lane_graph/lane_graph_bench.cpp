// Lane graph build and route query times on an OpenDRIVE map: parsing, building the graph,
// shortest routes between every pair of driving lanes at road ends (up to --pairs of them, in
// a fixed order), and locate() of lane-centre points. Prints the median of --runs runs.
//
//   lane_graph_bench MAP.xodr [--runs 5] [--pairs 2000]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"

namespace odr = convoy::opendrive;
using Clock = std::chrono::steady_clock;

namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double since(Clock::time_point t0, double scale) {
  return std::chrono::duration<double>(Clock::now() - t0).count() * scale;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: lane_graph_bench MAP.xodr [--runs 5] [--pairs 2000]\n");
    return 2;
  }
  int runs = 5;
  size_t max_pairs = 2000;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--runs")) runs = std::max(1, std::atoi(argv[i + 1]));
    if (!std::strcmp(argv[i], "--pairs")) max_pairs = std::max(1, std::atoi(argv[i + 1]));
  }
  try {
    std::vector<double> parse_ms, build_ms, route_us, found_route_us, locate_us;
    size_t lanes = 0, pairs = 0, found = 0, located = 0;
    for (int run = 0; run < runs; ++run) {
      auto t0 = Clock::now();
      const odr::Network net = odr::load(argv[1]);
      parse_ms.push_back(since(t0, 1e3));
      t0 = Clock::now();
      const odr::LaneGraph graph(net);
      build_ms.push_back(since(t0, 1e3));
      lanes = graph.lanes().size();
      std::vector<odr::LaneIndex> ends;  // driving lanes outside junctions
      for (const odr::LaneNode& n : graph.lanes()) {
        if (n.drivable() && n.junction == "-1") ends.push_back(n.index);
      }
      std::vector<std::pair<odr::LaneIndex, odr::LaneIndex>> queries;
      for (size_t i = 0; i < ends.size() && queries.size() < max_pairs; ++i) {
        for (size_t j = 0; j < ends.size() && queries.size() < max_pairs; ++j) {
          queries.emplace_back(ends[i], ends[(i + j * 7 + 1) % ends.size()]);
        }
      }
      pairs = queries.size();
      found = 0;
      double found_us = 0;
      t0 = Clock::now();
      for (const auto& [a, b] : queries) {
        const odr::LaneNode& na = graph.lane(a);
        const odr::LaneNode& nb = graph.lane(b);
        const auto q0 = Clock::now();
        const bool ok =
            graph.route(a, na.forward ? na.s0 : na.s1, b, nb.forward ? nb.s1 : nb.s0).has_value();
        if (ok) {
          found_us += since(q0, 1e6);
          ++found;
        }
      }
      route_us.push_back(since(t0, 1e6) / static_cast<double>(std::max<size_t>(1, pairs)));
      found_route_us.push_back(found_us / static_cast<double>(std::max<size_t>(1, found)));
      located = 0;
      t0 = Clock::now();
      for (const odr::LaneNode& n : graph.lanes()) {
        const double s = 0.5 * (n.s0 + n.s1);
        const odr::WorldPose w = graph.world_pose(n.road->id, n.lane_id, s, 0.1);
        located += graph.locate(w.x, w.y, w.heading).has_value();
      }
      locate_us.push_back(since(t0, 1e6) / static_cast<double>(std::max<size_t>(1, lanes)));
    }
    std::printf("map: %s, %zu lanes\n", argv[1], lanes);
    std::printf("parse: %.3f ms (median of %d)\n", median(parse_ms), runs);
    std::printf("lane graph build: %.3f ms\n", median(build_ms));
    std::printf(
        "route query: %.2f us mean over %zu lane pairs; %.2f us mean over the %zu with a "
        "route\n",
        median(route_us), pairs, median(found_route_us), found);
    std::printf("locate: %.2f us per point (%zu of %zu lanes)\n", median(locate_us), located,
                lanes);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lane_graph_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
