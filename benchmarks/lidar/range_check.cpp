#include "range_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace convoy::lidar_bench {

BruteForce::BruteForce(const render::Scene& scene) {
  for (const auto& in : scene.instances()) {
    if (!in.visible) continue;
    const render::MeshData& m = scene.meshes()[in.mesh];
    const render::Pose& p = in.world_from_object;
    Part part;
    part.lo.fill(std::numeric_limits<double>::infinity());
    part.hi.fill(-std::numeric_limits<double>::infinity());
    std::vector<double> world(m.positions.size());
    for (size_t v = 0; v < m.vertex_count(); ++v) {
      const double x = m.positions[3 * v], y = m.positions[3 * v + 1], z = m.positions[3 * v + 2];
      for (int k = 0; k < 3; ++k) {
        const double w = p[k] * x + p[4 + k] * y + p[8 + k] * z + p[12 + k];
        world[3 * v + k] = w;
        part.lo[k] = std::min(part.lo[k], w);
        part.hi[k] = std::max(part.hi[k], w);
      }
    }
    part.tris.reserve(m.indices.size() * 3);
    for (uint32_t i : m.indices)
      for (int k = 0; k < 3; ++k) part.tris.push_back(world[3 * i + k]);
    parts_.push_back(std::move(part));
  }
}

double BruteForce::range(const std::array<double, 3>& o, const std::array<double, 3>& d,
                         double tmin, double tmax) const {
  double best = tmax;
  bool hit = false;
  for (const Part& part : parts_) {
    double t0 = tmin, t1 = best;  // slab test against the part's box
    for (int k = 0; k < 3 && t0 <= t1; ++k) {
      const double inv = 1.0 / d[k];
      double a = (part.lo[k] - 1e-6 - o[k]) * inv, b = (part.hi[k] + 1e-6 - o[k]) * inv;
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (t0 > t1) continue;
    const double* t = part.tris.data();
    for (size_t i = 0; i < part.tris.size(); i += 9, t += 9) {  // Moller-Trumbore
      const double e1[3] = {t[3] - t[0], t[4] - t[1], t[5] - t[2]};
      const double e2[3] = {t[6] - t[0], t[7] - t[1], t[8] - t[2]};
      const double q[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2],
                           d[0] * e2[1] - d[1] * e2[0]};
      const double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
      if (std::abs(det) < 1e-15) continue;
      const double inv = 1.0 / det;
      const double s[3] = {o[0] - t[0], o[1] - t[1], o[2] - t[2]};
      const double u = (s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) * inv;
      if (u < 0 || u > 1) continue;
      const double r[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2],
                           s[0] * e1[1] - s[1] * e1[0]};
      const double v = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) * inv;
      if (v < 0 || u + v > 1) continue;
      const double dist = (e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) * inv;
      if (dist >= tmin && dist < best) best = dist, hit = true;
    }
  }
  return hit ? best : -1;
}

}  // namespace convoy::lidar_bench
