// The pooled host's step alone (src/traffic_pool): N vehicles with IDM, MOBIL, junction
// yielding and lights on an OpenDRIVE map, stepped at --dt for --seconds simulated seconds.
// For each N prints the wall time per step, vehicle updates per wall second, the real-time
// factor (simulated / wall), lane changes, junction entries, respawns and the collisions: pairs
// of vehicles whose boxes begin to overlap (each pair counted once per contact).
//
//   traffic_pool_bench MAP.xodr [--counts 1000,5000,10000] [--seconds 60] [--dt 0.05]
//                      [--seed 1] [--walkers W]
// --walkers W adds W pooled walkers (spawn_walkers, the same seed) and prints their trips,
// crossings, mean speed (at the end and over the run), how many are on the road at the end (and
// standing there), the vehicle-walker collisions (a vehicle's box beginning to overlap a
// walker's) and the walker-walker ones (two walkers' boxes, length x width along their yaw as
// the world engine's pedestrian collision box, beginning to overlap).
// Last line: `pool step alone at real time: N` (the largest N with a factor >= 1).
//
// With --flows FILE the vehicles come from flows instead of a count (flow_run.h; used by
// benchmarks/realism): --warmup S simulated first, then --seconds traced; --trace FILE writes
// one CSV row per vehicle every --trace-every steps (t, id, road, lane, pool lane, s, lane
// length, speed, acceleration, speed limit, junction id, x, y, length). --routable FILE prints
// which flows of FILE the pool can drive (a path without lane changes) and exits.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "flow_run.h"
#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace odr = convoy::opendrive;
namespace tp = convoy::traffic_pool;
using Clock = std::chrono::steady_clock;

namespace {

// The pool at each count of `counts`, from spawned vehicles; returns the largest count at >= 1x.
// Pairs that begin to overlap now (not in `touching`), which becomes `now`.
size_t new_contacts(const std::vector<std::pair<uint32_t, uint32_t>>& now_list,
                    std::set<std::pair<uint32_t, uint32_t>>& touching) {
  std::set<std::pair<uint32_t, uint32_t>> now(now_list.begin(), now_list.end());
  size_t fresh = 0;
  for (const auto& p : now) fresh += !touching.count(p);
  touching.swap(now);
  return fresh;
}

size_t run_counts(const tp::PoolNetwork& net, const std::string& counts, double seconds, double dt,
                  uint64_t seed, size_t walkers) {
  size_t best = 0;
  std::stringstream list(counts);
  for (std::string item; std::getline(list, item, ',');) {
    const size_t n = std::strtoull(item.c_str(), nullptr, 10);
    tp::VehicleSpec base;
    tp::Pool pool(net, tp::spawn(net, n, seed, base));
    if (walkers > 0) pool.set_walkers(tp::spawn_walkers(net, walkers, seed));
    std::set<std::pair<uint32_t, uint32_t>> touching, touching_walkers, touching_ww;
    size_t collisions = 0, walker_collisions = 0, ww_collisions = 0;
    const int steps = static_cast<int>(seconds / dt + 0.5);
    double step_wall = 0, check_wall = 0, speed_sum = 0, walker_speed_sum = 0, walker_samples = 0;
    for (int k = 0; k < steps; ++k) {
      const auto t0 = Clock::now();
      pool.step(dt);
      const auto t1 = Clock::now();
      collisions += new_contacts(pool.overlaps(), touching);
      walker_collisions += new_contacts(pool.walker_overlaps(), touching_walkers);
      if (pool.walkers()) ww_collisions += new_contacts(pool.walkers()->overlaps(), touching_ww);
      check_wall += std::chrono::duration<double>(Clock::now() - t1).count();
      if (const tp::PoolWalkers* w = pool.walkers()) {
        for (size_t i = 0; i < w->size(); ++i) walker_speed_sum += w->speed(i);
        walker_samples += static_cast<double>(w->size());
      }
      step_wall += std::chrono::duration<double>(t1 - t0).count();
    }
    for (size_t i = 0; i < pool.size(); ++i) speed_sum += pool.speed(i);
    const double rtf = seconds / step_wall;
    std::printf(
        "  N = %6zu: %.3f ms per step, %.0f vehicle updates/s, real-time factor "
        "%.1fx; mean speed at the end %.1f m/s; lane changes %llu, junction entries "
        "%llu, respawns %llu; collisions %zu (check %.3f ms per step)\n",
        n, 1e3 * step_wall / steps, n * steps / step_wall, rtf, speed_sum / static_cast<double>(n),
        static_cast<unsigned long long>(pool.stats().lane_changes),
        static_cast<unsigned long long>(pool.stats().junction_entries),
        static_cast<unsigned long long>(pool.stats().respawns), collisions,
        1e3 * check_wall / steps);
    if (const tp::PoolWalkers* w = pool.walkers()) {
      double walked = 0;
      size_t on_road = 0, stopped_on_road = 0;
      for (size_t i = 0; i < w->size(); ++i) {
        walked += w->speed(i);
        on_road += w->on_road(i);
        stopped_on_road += w->on_road(i) && w->speed(i) < 0.05;
      }
      std::printf(
          "    walkers %zu: trips %llu, crossings %llu, respawns %llu, mean speed at the end "
          "%.2f m/s (mean over the run %.2f), on the road at the end %zu (standing %zu); "
          "vehicle-walker collisions %zu, walker-walker collisions %zu\n",
          w->size(), static_cast<unsigned long long>(w->stats().trips),
          static_cast<unsigned long long>(w->stats().crossings),
          static_cast<unsigned long long>(w->stats().respawns),
          walked / static_cast<double>(w->size()), walker_speed_sum / walker_samples, on_road,
          stopped_on_road, walker_collisions, ww_collisions);
    }
    std::fflush(stdout);
    if (rtf >= 1.0) best = std::max(best, n);
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc % 2 != 0) {
    std::fprintf(stderr,
                 "usage: traffic_pool_bench MAP.xodr [--counts N,N] [--seconds S] "
                 "[--dt DT] [--seed K] [--walkers W] [--flows FILE [--trace FILE] [--warmup S] "
                 "[--trace-every K]] [--routable FILE]\n");
    return 2;
  }
  std::string counts = "1000,5000,10000", routable;
  size_t walkers = 0;
  convoy::bench::FlowRunOptions flow;
  flow.seconds = 60;
  const std::map<std::string, std::function<void(const std::string&)>> options = {
      {"--counts", [&](const std::string& v) { counts = v; }},
      {"--seconds", [&](const std::string& v) { flow.seconds = std::atof(v.c_str()); }},
      {"--dt", [&](const std::string& v) { flow.dt = std::atof(v.c_str()); }},
      {"--seed", [&](const std::string& v) { flow.seed = std::strtoull(v.c_str(), nullptr, 10); }},
      {"--flows", [&](const std::string& v) { flow.flows_path = v; }},
      {"--trace", [&](const std::string& v) { flow.trace_path = v; }},
      {"--warmup", [&](const std::string& v) { flow.warmup_s = std::atof(v.c_str()); }},
      {"--trace-every",
       [&](const std::string& v) { flow.trace_every = std::max(1, std::atoi(v.c_str())); }},
      {"--routable", [&](const std::string& v) { routable = v; }},
      {"--walkers",
       [&](const std::string& v) { walkers = std::strtoull(v.c_str(), nullptr, 10); }}};
  for (int i = 2; i + 1 < argc; i += 2) {
    const auto it = options.find(argv[i]);
    if (it == options.end()) {
      std::fprintf(stderr, "traffic_pool_bench: unknown option '%s'\n", argv[i]);
      return 2;
    }
    it->second(argv[i + 1]);
  }
  if (!(flow.dt > 0) || !(flow.seconds > 0) || !(flow.warmup_s >= 0)) {
    std::fprintf(stderr, "traffic_pool_bench: --dt and --seconds must be > 0, --warmup >= 0\n");
    return 2;
  }
  try {
    const odr::Network map = odr::load(argv[1]);
    const odr::LaneGraph graph(map);
    const tp::PoolNetwork net(graph);
    if (!routable.empty()) {
      convoy::bench::print_routable(net, routable);
      return 0;
    }
    size_t lights = 0;
    for (const tp::PoolJunction& j : net.junctions()) lights += j.lights;
    std::printf(
        "map %s: %zu driving lanes, %zu junctions (%zu with lights); dt %g s, %g s "
        "simulated\n",
        argv[1], net.lanes().size(), net.junctions().size(), lights, flow.dt,
        flow.seconds + (flow.flows_path.empty() ? 0 : flow.warmup_s));
    if (!flow.flows_path.empty()) {
      convoy::bench::run_flows(net, flow);
      return 0;
    }
    const size_t best = run_counts(net, counts, flow.seconds, flow.dt, flow.seed, walkers);
    std::printf("pool step alone at real time: %zu\n", best);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "traffic_pool_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
