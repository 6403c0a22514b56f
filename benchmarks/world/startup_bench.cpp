// World start-up benchmark: the parts of the world engine's initialize() on a world file,
// median of N runs each: parsing the SDF (load_world), the cached load (world_cache.h),
// building the physics and the camera scene.
//
//   build/benchmarks/startup_bench [world.sdf] [runs]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "camera_sensors.h"
#include "physics_world.h"
#include "world_cache.h"
#include "world_description.h"

using namespace convoy::world;

namespace {

template <typename F>
double median_s(int runs, F f) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  std::string file = argc > 1 ? argv[1]
                              : std::string(CONVOY_REPO_DIR) +
                                    "/experiments/autonomous_driving/parkring_world.sdf";
  int runs = argc > 2 ? std::atoi(argv[2]) : 3;
  WorldDesc desc;
  double parse = median_s(runs, [&] { desc = load_world(file); });
  // The cache in a fresh folder: the first load fills it, the next ones hit.
  std::filesystem::path dir = std::filesystem::temp_directory_path() / "convoy-startup-bench";
  std::filesystem::remove_all(dir);
  setenv("CONVOY_CACHE_DIR", dir.c_str(), 1);
  CacheResult res;
  double fill = median_s(1, [&] { load_world_cached(file, {}, &res); });
  if (res != CacheResult::kMiss) std::fprintf(stderr, "expected a miss, got %s\n", to_string(res));
  double cached = median_s(runs, [&] {
    WorldDesc d = load_world_cached(file, {}, &res);
    if (res != CacheResult::kHit) std::fprintf(stderr, "expected a hit, got %s\n", to_string(res));
  });
  const bool same = serialize_world(load_world_cached(file, {}, &res)) == serialize_world(desc);
  std::filesystem::remove_all(dir);
  if (!same) {
    std::fprintf(stderr, "the cached description differs from the parsed one\n");
    return 1;
  }
  double physics = median_s(runs, [&] { PhysicsWorld p(desc); });
  PhysicsWorld p(desc);
  double cameras = median_s(runs, [&] { CameraSensors c(desc, p, 0); });
  std::printf(
      "world start-up parts (%s, %zu models), median of %d: parse SDF %.3f s, "
      "cached load %.3f s (first load, filling the cache: %.3f s), physics %.3f s, "
      "cameras %.3f s\n",
      std::filesystem::path(file).filename().c_str(), desc.models.size(), runs, parse, cached, fill,
      physics, cameras);
  return 0;
}
