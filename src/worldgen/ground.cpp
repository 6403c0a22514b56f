#include "worldgen/ground.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace convoy::worldgen {

double build_ground(const opendrive::Bounds& b, const GroundOptions& options, uint64_t seed,
                    MeshSet& out) {
  const double z = std::min(0.0, b.min[2]) - options.below_road;
  const double cx = 0.5 * (b.min[0] + b.max[0]), cy = 0.5 * (b.min[1] + b.max[1]);
  const double half = 0.5 * std::hypot(b.max[0] - b.min[0], b.max[1] - b.min[1]);
  const double r = half + options.margin;  // the ground's radius; the hills stand at its rim
  const MaterialDesc grass{{0.3, 0.45, 0.2}, 0.02, ""};
  const MaterialDesc paved{{0.42, 0.4, 0.37}, 0.02, ""};
  const MaterialDesc hills{{0.33, 0.42, 0.36}, 0.0, ""};
  Part& ground = out.part("ground", options.urban ? paved : grass);
  Part& rim = out.part("hills", hills);
  constexpr int kSegments = 72;
  // hill heights: a few sines with seeded phases, 0.02 to 0.06 of the radius, at most 80 m
  uint64_t state = seed * 0x9E3779B97F4A7C15ull + 1;
  auto uniform = [&]() {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return (state >> 11) * 0x1.0p-53;
  };
  double phase[3];
  for (double& p : phase) p = 2 * std::numbers::pi * uniform();
  std::vector<Vec3> inner, outer;
  for (int i = 0; i <= kSegments; ++i) {
    const double a = 2 * std::numbers::pi * i / kSegments;
    const double h = std::min(
        80.0, r * (0.04 + 0.012 * std::sin(3 * a + phase[0]) + 0.01 * std::sin(7 * a + phase[1]) +
                   0.006 * std::sin(13 * a + phase[2])));
    inner.push_back({cx + r * std::cos(a), cy + r * std::sin(a), z});
    outer.push_back({cx + 1.15 * r * std::cos(a), cy + 1.15 * r * std::sin(a), z + h});
  }
  const Vec3 centre{cx, cy, z};
  for (int i = 0; i < kSegments; ++i) {
    MeshSet::add_convex(ground, {centre, inner[i], inner[i + 1]});
    // the hills' slope faces the centre: counter-clockwise seen from inside
    MeshSet::add_quad(rim, inner[i], outer[i], outer[i + 1], inner[i + 1]);
  }
  return z;
}

}  // namespace convoy::worldgen
