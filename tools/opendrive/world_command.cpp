// convoy-odr world MAP.xodr OUT_DIR [--scenery none|roadside|urban] [--seed N] [--catalog FILE]
#include <chrono>
#include <cstdio>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "opendrive/parser.h"
#include "worldgen/world_gen.h"

namespace odr = convoy::opendrive;
namespace wg = convoy::worldgen;

// Exit codes as the other commands: 0 done, 1 output not written, 2 bad command line or map.
int world_command(const std::vector<std::string>& positional,
                  const std::map<std::string, std::string>& options) {
  auto option = [&](const char* name, const std::string& fallback) {
    auto it = options.find(name);
    return it == options.end() ? fallback : it->second;
  };
  const auto t0 = std::chrono::steady_clock::now();
  wg::WorldOptions wo;
  std::string catalog_file;
  try {
    wo.scenery = wg::parse_scenery(option("scenery", "none"));
    const std::string seed = option("seed", "1");
    size_t used = 0;
    const unsigned long long v = std::stoull(seed, &used);
    if (used != seed.size()) throw std::invalid_argument("x");
    wo.seed = v;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    std::fprintf(
        stderr, "convoy-odr world: %s\n",
        what == "x" || what == "stoull" ? "--seed must be a whole number >= 0" : what.c_str());
    return 2;
  }
  catalog_file = option("catalog", wg::Catalog::default_path().string());
  odr::Network net;
  wg::Catalog catalog;
  try {
    odr::LoadOptions lenient;
    lenient.skip_bad_roads = true;
    net = odr::load(positional[0], lenient);
    catalog = wg::Catalog::load(catalog_file);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "convoy-odr world: %s\n", e.what());
    return 2;
  }
  for (const auto& w : net.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  wg::WorldStats stats;
  try {
    stats = wg::generate_world(net, catalog, wo, positional[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "convoy-odr world: %s: %s\n", positional[0].c_str(), e.what());
    return 1;
  }
  for (const auto& w : stats.warnings) {
    std::fprintf(stderr, "warning: %s: %s\n", positional[0].c_str(), w.c_str());
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "%s/world.sdf: %zu models (%zu placed, %zu signals), %zu triangles generated, "
      "%zu warnings, in %.3f s\n",
      positional[1].c_str(), stats.models, stats.placements, stats.signals, stats.triangles,
      stats.warnings.size(), s);
  return 0;
}
