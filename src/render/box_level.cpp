#include "render/box_level.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <glm/glm.hpp>
#include <limits>

namespace convoy::render {
namespace {

using glm::dvec3;

// The point of triangle (a, b, c) closest to p (the Voronoi regions of its vertices, edges and
// face, after Ericson, Real-Time Collision Detection, 5.1.5).
dvec3 closest_on_triangle(const dvec3& p, const dvec3& a, const dvec3& b, const dvec3& c) {
  const dvec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const dvec3 bp = p - b;
  const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const dvec3 cp = p - c;
  const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = va + vb + vc;
  if (!(std::abs(denom) > 0)) return a;  // a degenerate triangle: its first vertex
  return a + ab * (vb / denom) + ac * (vc / denom);
}

// Distance from p, inside the box [lo, hi], to the box's surface.
double to_box_surface(const dvec3& p, const dvec3& lo, const dvec3& hi) {
  double d = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) d = std::min({d, p[k] - lo[k], hi[k] - p[k]});
  return std::max(d, 0.0);
}

MeshData box_mesh(const dvec3& lo, const dvec3& hi) {
  MeshData m;
  // Each face: its axis, its side, then two axes in counter-clockwise order seen from outside.
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const uint32_t base = static_cast<uint32_t>(m.positions.size() / 3);
      const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
      for (const auto& c : corners) {
        dvec3 p;
        p[axis] = side ? hi[axis] : lo[axis];
        p[u] = c[0] ? hi[u] : lo[u];
        p[v] = c[1] ? hi[v] : lo[v];
        dvec3 n(0.0);
        n[axis] = side ? 1 : -1;
        for (int k = 0; k < 3; ++k) {
          m.positions.push_back(static_cast<float>(p[k]));
          m.normals.push_back(static_cast<float>(n[k]));
        }
      }
      // (u, v, axis) is right-handed: u x v = +axis, so 0-1-2 turns counter-clockwise seen
      // from +axis; the low side turns the other way.
      const std::array<uint32_t, 6> ccw{0, 1, 2, 0, 2, 3}, cw{0, 2, 1, 0, 3, 2};
      for (uint32_t i : side ? ccw : cw) m.indices.push_back(base + i);
    }
  }
  return m;
}

}  // namespace

std::optional<BoxLevel> box_level(const MeshData& mesh) {
  const size_t triangles = mesh.triangle_count();
  if (!mesh.uvs.empty() || triangles < kBoxLevelMinTriangles || triangles > kBoxLevelMaxTriangles)
    return std::nullopt;
  const auto& pos = mesh.positions;
  auto vertex = [&pos](uint32_t i) { return dvec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]); };
  dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < mesh.vertex_count(); ++i) {
    lo = glm::min(lo, vertex(static_cast<uint32_t>(i)));
    hi = glm::max(hi, vertex(static_cast<uint32_t>(i)));
  }
  // The mesh's farthest points from the box's surface: vertices and centroids.
  double error = 0;
  for (size_t i = 0; i < mesh.vertex_count(); ++i)
    error = std::max(error, to_box_surface(vertex(static_cast<uint32_t>(i)), lo, hi));
  const auto& idx = mesh.indices;
  for (size_t t = 0; t < triangles; ++t) {
    const dvec3 centroid =
        (vertex(idx[3 * t]) + vertex(idx[3 * t + 1]) + vertex(idx[3 * t + 2])) / 3.0;
    error = std::max(error, to_box_surface(centroid, lo, hi));
  }
  // The box's farthest points from the mesh: corners, edge midpoints and face centres (the
  // 3 x 3 x 3 lattice without its centre).
  for (int s = 0; s < 27; ++s) {
    if (s == 13) continue;
    const dvec3 f(s % 3 * 0.5, s / 3 % 3 * 0.5, s / 9 * 0.5);
    const dvec3 p = lo + (hi - lo) * f;
    double nearest = std::numeric_limits<double>::infinity();
    for (size_t t = 0; t < triangles && nearest > error; ++t) {
      const dvec3 q = closest_on_triangle(p, vertex(idx[3 * t]), vertex(idx[3 * t + 1]),
                                          vertex(idx[3 * t + 2]));
      nearest = std::min(nearest, glm::length(p - q));
    }
    error = std::max(error, nearest);
  }
  return BoxLevel{box_mesh(lo, hi), static_cast<float>(error)};
}

}  // namespace convoy::render
