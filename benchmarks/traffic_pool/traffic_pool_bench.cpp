// The pooled host's step alone (src/traffic_pool): N vehicles with IDM, MOBIL, junction
// yielding and lights on an OpenDRIVE map, stepped at --dt for --seconds simulated seconds.
// For each N prints the wall time per step, vehicle updates per wall second, the real-time
// factor (simulated / wall), lane changes, junction entries, respawns and the collisions: pairs
// of vehicles whose boxes begin to overlap (each pair counted once per contact).
//
//   traffic_pool_bench MAP.xodr [--counts 1000,5000,10000] [--seconds 60] [--dt 0.05]
//                      [--seed 1]
// Last line: `pool step alone at real time: N` (the largest N with a factor >= 1).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace odr = convoy::opendrive;
namespace tp = convoy::traffic_pool;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: traffic_pool_bench MAP.xodr [--counts N,N] [--seconds S] "
                 "[--dt DT] [--seed K]\n");
    return 2;
  }
  std::string counts = "1000,5000,10000";
  double seconds = 60, dt = 0.05;
  uint64_t seed = 1;
  for (int i = 2; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--counts")) counts = argv[i + 1];
    if (!std::strcmp(argv[i], "--seconds")) seconds = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--dt")) dt = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--seed")) seed = std::strtoull(argv[i + 1], nullptr, 10);
  }
  try {
    const odr::Network map = odr::load(argv[1]);
    const odr::LaneGraph graph(map);
    const tp::PoolNetwork net(graph);
    size_t lights = 0;
    for (const tp::PoolJunction& j : net.junctions()) lights += j.lights;
    std::printf(
        "map %s: %zu driving lanes, %zu junctions (%zu with lights); dt %g s, %g s "
        "simulated\n",
        argv[1], net.lanes().size(), net.junctions().size(), lights, dt, seconds);
    size_t best = 0;
    std::stringstream list(counts);
    for (std::string item; std::getline(list, item, ',');) {
      const size_t n = std::strtoull(item.c_str(), nullptr, 10);
      tp::VehicleSpec base;
      tp::Pool pool(net, tp::spawn(net, n, seed, base));
      std::set<std::pair<uint32_t, uint32_t>> touching;
      size_t collisions = 0;
      const int steps = static_cast<int>(seconds / dt + 0.5);
      double step_wall = 0, check_wall = 0, speed_sum = 0;
      for (int k = 0; k < steps; ++k) {
        const auto t0 = Clock::now();
        pool.step(dt);
        const auto t1 = Clock::now();
        std::set<std::pair<uint32_t, uint32_t>> now;
        for (const auto& p : pool.overlaps()) {
          now.insert(p);
          if (!touching.count(p)) ++collisions;
        }
        touching.swap(now);
        check_wall += std::chrono::duration<double>(Clock::now() - t1).count();
        step_wall += std::chrono::duration<double>(t1 - t0).count();
      }
      for (size_t i = 0; i < pool.size(); ++i) speed_sum += pool.speed(i);
      const double rtf = seconds / step_wall;
      std::printf(
          "  N = %6zu: %.3f ms per step, %.0f vehicle updates/s, real-time factor "
          "%.1fx; mean speed at the end %.1f m/s; lane changes %llu, junction entries "
          "%llu, respawns %llu; collisions %zu (check %.3f ms per step)\n",
          n, 1e3 * step_wall / steps, n * steps / step_wall, rtf,
          speed_sum / static_cast<double>(n),
          static_cast<unsigned long long>(pool.stats().lane_changes),
          static_cast<unsigned long long>(pool.stats().junction_entries),
          static_cast<unsigned long long>(pool.stats().respawns), collisions,
          1e3 * check_wall / steps);
      std::fflush(stdout);
      if (rtf >= 1.0) best = std::max(best, n);
    }
    std::printf("pool step alone at real time: %zu\n", best);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "traffic_pool_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
