#include "render/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace convoy::render {
namespace {

constexpr double kPi = 3.14159265358979323846;

void push3(std::vector<float>* v, double x, double y, double z) {
  v->push_back(static_cast<float>(x));
  v->push_back(static_cast<float>(y));
  v->push_back(static_cast<float>(z));
}

void push2(std::vector<float>* v, double x, double y) {
  v->push_back(static_cast<float>(x));
  v->push_back(static_cast<float>(y));
}

void check_positive(const char* what, double value) {
  if (!(value > 0) || !std::isfinite(value)) {
    throw std::invalid_argument(std::string(what) + " must be > 0, got " + std::to_string(value));
  }
}

}  // namespace

MeshData make_box(float sx, float sy, float sz) {
  check_positive("make_box: size x", sx);
  check_positive("make_box: size y", sy);
  check_positive("make_box: size z", sz);
  const double half[3] = {sx / 2.0, sy / 2.0, sz / 2.0};
  MeshData m;
  // One quad per face; (e_b, e_c) spans the face with e_b x e_c = e_a, so the corners below
  // run counter-clockwise seen from outside.
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int s : {1, -1}) {
      const uint32_t base = static_cast<uint32_t>(m.vertex_count());
      const int corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& corner : corners) {
        double p[3], n[3] = {0, 0, 0};
        p[a] = s * half[a];
        p[b] = corner[0] * s * half[b];
        p[c] = corner[1] * half[c];
        n[a] = s;
        push3(&m.positions, p[0], p[1], p[2]);
        push3(&m.normals, n[0], n[1], n[2]);
        push2(&m.uvs, (corner[0] + 1) / 2.0, (corner[1] + 1) / 2.0);
      }
      for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
  }
  return m;
}

MeshData make_cylinder(float radius, float length, int segments) {
  check_positive("make_cylinder: radius", radius);
  check_positive("make_cylinder: length", length);
  if (segments < 3) {
    throw std::invalid_argument("make_cylinder: segments must be >= 3, got " +
                                std::to_string(segments));
  }
  MeshData m;
  const double h = length / 2.0;
  // Side: a bottom and a top vertex per segment boundary, smooth normals.
  for (int k = 0; k <= segments; ++k) {
    const double t = 2 * kPi * k / segments, c = std::cos(t), s = std::sin(t);
    for (int top = 0; top < 2; ++top) {
      push3(&m.positions, radius * c, radius * s, top ? h : -h);
      push3(&m.normals, c, s, 0);
      push2(&m.uvs, static_cast<double>(k) / segments, top);
    }
  }
  for (int k = 0; k < segments; ++k) {
    const uint32_t b0 = 2 * k, t0 = b0 + 1, b1 = b0 + 2, t1 = b0 + 3;
    for (uint32_t i : {b0, b1, t1, b0, t1, t0}) m.indices.push_back(i);
  }
  // Caps: a centre and a ring each, flat normals.
  for (int top = 0; top < 2; ++top) {
    const double z = top ? h : -h, nz = top ? 1 : -1;
    const uint32_t centre = static_cast<uint32_t>(m.vertex_count());
    push3(&m.positions, 0, 0, z);
    push3(&m.normals, 0, 0, nz);
    push2(&m.uvs, 0.5, 0.5);
    for (int k = 0; k <= segments; ++k) {
      const double t = 2 * kPi * k / segments, c = std::cos(t), s = std::sin(t);
      push3(&m.positions, radius * c, radius * s, z);
      push3(&m.normals, 0, 0, nz);
      push2(&m.uvs, 0.5 + 0.5 * c, 0.5 + 0.5 * s);
    }
    for (int k = 0; k < segments; ++k) {
      const uint32_t r0 = centre + 1 + k, r1 = r0 + 1;
      m.indices.insert(m.indices.end(), {centre, top ? r0 : r1, top ? r1 : r0});
    }
  }
  return m;
}

MeshData make_sphere(float radius, int stacks, int slices) {
  check_positive("make_sphere: radius", radius);
  if (stacks < 2 || slices < 3) {
    throw std::invalid_argument("make_sphere: need stacks >= 2 and slices >= 3, got " +
                                std::to_string(stacks) + " and " + std::to_string(slices));
  }
  MeshData m;
  for (int i = 0; i <= stacks; ++i) {
    const double phi = kPi * i / stacks, sp = std::sin(phi), cp = std::cos(phi);
    for (int j = 0; j <= slices; ++j) {
      const double theta = 2 * kPi * j / slices;
      const double n[3] = {sp * std::cos(theta), sp * std::sin(theta), cp};
      push3(&m.positions, radius * n[0], radius * n[1], radius * n[2]);
      push3(&m.normals, n[0], n[1], n[2]);
      push2(&m.uvs, static_cast<double>(j) / slices, 1.0 - static_cast<double>(i) / stacks);
    }
  }
  const uint32_t row = slices + 1;
  for (int i = 0; i < stacks; ++i) {
    for (int j = 0; j < slices; ++j) {
      const uint32_t a = i * row + j, b = a + row;
      // The triangle touching a pole would be degenerate; leave it out.
      if (i != 0) {
        for (uint32_t k : {b, a + 1, a}) m.indices.push_back(k);
      }
      if (i != stacks - 1) {
        for (uint32_t k : {b, b + 1, a + 1}) m.indices.push_back(k);
      }
    }
  }
  return m;
}

MeshLevels sphere_levels(float radius, int stacks, int slices) {
  MeshLevels out;
  for (;;) {
    out.meshes.push_back(make_sphere(radius, stacks, slices));
    // The vertices lie on the sphere; the surface is farthest from it at a facet's centre,
    // half a slice and half a stack from its corners.
    out.errors.push_back(
        static_cast<float>(radius * (1 - std::cos(kPi / slices) * std::cos(kPi / (2.0 * stacks)))));
    if (slices / 2 < 8 || stacks / 2 < 2) break;
    slices /= 2;
    stacks /= 2;
  }
  return out;
}

MeshLevels cylinder_levels(float radius, float length, int segments) {
  MeshLevels out;
  for (;;) {
    out.meshes.push_back(make_cylinder(radius, length, segments));
    out.errors.push_back(static_cast<float>(radius * (1 - std::cos(kPi / segments))));
    if (segments / 2 < 8) break;
    segments /= 2;
  }
  return out;
}

namespace {

// One clustering pass over `mesh` (normals present) with cells of side `cell`, vertices that
// face different ways kept apart if `by_normal`; *error gets the farthest a vertex moved.
MeshData cluster(const MeshData& mesh, double cell, bool by_normal, float* error) {
  const size_t n = mesh.vertex_count();
  const float* p = mesh.positions.data();
  const float* nr = mesh.normals.data();
  std::array<double, 3> lo{p[0], p[1], p[2]};
  for (size_t i = 1; i < n; ++i)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], static_cast<double>(p[3 * i + k]));
  // Key: the cell (21 bits an axis) and the normal's dominant axis and sign (3 bits).
  std::unordered_map<uint64_t, uint32_t> id_of;
  std::vector<uint32_t> vertex_cluster(n);
  std::vector<std::array<double, 7>> sums;  // position, normal, count
  for (size_t i = 0; i < n; ++i) {
    uint64_t key = 0;
    for (int k = 0; k < 3; ++k) {
      const auto c = static_cast<uint64_t>(std::floor((p[3 * i + k] - lo[k]) / cell));
      key = (key << 21) | (c & 0x1fffff);
    }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (std::abs(nr[3 * i + k]) > std::abs(nr[3 * i + axis])) axis = k;
    key = (key << 3) |
          (by_normal ? static_cast<uint64_t>(2 * axis + (nr[3 * i + axis] < 0 ? 1 : 0)) : 0);
    auto [it, fresh] = id_of.try_emplace(key, static_cast<uint32_t>(sums.size()));
    if (fresh) sums.push_back({0, 0, 0, 0, 0, 0, 0});
    vertex_cluster[i] = it->second;
    auto& s = sums[it->second];
    for (int k = 0; k < 3; ++k) s[k] += p[3 * i + k], s[3 + k] += nr[3 * i + k];
    s[6] += 1;
  }
  MeshData out;
  out.positions.reserve(3 * sums.size());
  out.normals.reserve(3 * sums.size());
  for (const auto& s : sums) {
    push3(&out.positions, s[0] / s[6], s[1] / s[6], s[2] / s[6]);
    const double len = std::sqrt(s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
    if (len > 0)
      push3(&out.normals, s[3] / len, s[4] / len, s[5] / len);
    else
      push3(&out.normals, 0, 0, 1);
  }
  double moved = 0;
  for (size_t i = 0; i < n; ++i) {
    const float* q = &out.positions[3 * vertex_cluster[i]];
    const double dx = p[3 * i] - q[0], dy = p[3 * i + 1] - q[1], dz = p[3 * i + 2] - q[2];
    moved = std::max(moved, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  *error = static_cast<float>(moved);
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const uint32_t a = vertex_cluster[mesh.indices[t]], b = vertex_cluster[mesh.indices[t + 1]],
                   c = vertex_cluster[mesh.indices[t + 2]];
    if (a == b || b == c || a == c) continue;
    out.indices.insert(out.indices.end(), {a, b, c});
  }
  return out;
}

}  // namespace

float horizontal_extent(const MeshData& mesh) {
  if (mesh.positions.empty()) return 0;
  float lo[2] = {mesh.positions[0], mesh.positions[1]}, hi[2] = {lo[0], lo[1]};
  for (size_t i = 0; i < mesh.vertex_count(); ++i)
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * i + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * i + k]);
    }
  return std::max(hi[0] - lo[0], hi[1] - lo[1]);
}

std::vector<MeshData> split_into_tiles(const MeshData& mesh, float tile) {
  if (!(tile > 0)) throw std::invalid_argument("split_into_tiles: tile must be > 0");
  const float* p = mesh.positions.data();
  auto cell = [&](uint32_t a, uint32_t b, uint32_t c, int k) {
    const float centroid = (p[3 * a + k] + p[3 * b + k] + p[3 * c + k]) / 3;
    return static_cast<int64_t>(std::floor(centroid / tile));
  };
  std::map<std::pair<int64_t, int64_t>, MeshData> tiles;  // (row y, column x)
  std::map<std::pair<int64_t, int64_t>, std::unordered_map<uint32_t, uint32_t>> remap;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const uint32_t* v = &mesh.indices[3 * t];
    const std::pair<int64_t, int64_t> key{cell(v[0], v[1], v[2], 1), cell(v[0], v[1], v[2], 0)};
    MeshData& out = tiles[key];
    auto& index_of = remap[key];
    for (int j = 0; j < 3; ++j) {
      auto [it, fresh] = index_of.try_emplace(v[j], static_cast<uint32_t>(out.vertex_count()));
      if (fresh) {
        const size_t i = v[j];
        out.positions.insert(out.positions.end(), p + 3 * i, p + 3 * i + 3);
        if (!mesh.normals.empty())
          out.normals.insert(out.normals.end(), &mesh.normals[3 * i], &mesh.normals[3 * i] + 3);
        if (!mesh.uvs.empty())
          out.uvs.insert(out.uvs.end(), &mesh.uvs[2 * i], &mesh.uvs[2 * i] + 2);
      }
      out.indices.push_back(it->second);
    }
  }
  std::vector<MeshData> out;
  out.reserve(tiles.size());
  for (auto& [key, m] : tiles) out.push_back(std::move(m));
  return out;
}

MeshLevels simplified_levels(MeshData mesh) {
  MeshLevels out;
  if (mesh.normals.empty()) compute_normals(&mesh);
  const bool textured = !mesh.uvs.empty();
  const size_t n = mesh.vertex_count();
  out.meshes.push_back(std::move(mesh));
  out.errors.push_back(0.0f);
  if (textured || n < 64) return out;
  const MeshData& fine = out.meshes.front();
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (size_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], static_cast<double>(fine.positions[3 * i + k]));
      hi[k] = std::max(hi[k], static_cast<double>(fine.positions[3 * i + k]));
    }
  const double diagonal =
      std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                (hi[2] - lo[2]) * (hi[2] - lo[2]));
  if (!(diagonal > 0)) return out;
  // The last two levels merge across facing too: foliage and folds, whose normals scatter,
  // barely merge by facing.
  const std::pair<double, bool> passes[] = {
      {1.0 / 48, true}, {1.0 / 24, true}, {1.0 / 12, true}, {1.0 / 8, false}, {1.0 / 5, false}};
  for (auto [fraction, by_normal] : passes) {
    float error = 0;
    MeshData coarse = cluster(out.meshes.front(), diagonal * fraction, by_normal, &error);
    if (coarse.triangle_count() == 0 ||
        coarse.triangle_count() > 0.6 * out.meshes.back().triangle_count())
      continue;
    if (!by_normal) {  // the merged normals of opposite faces cancel: smooth ones instead
      coarse.normals.clear();
      compute_normals(&coarse);
    }
    out.errors.push_back(std::max(error, out.errors.back()));
    out.meshes.push_back(std::move(coarse));
  }
  return out;
}

MeshData make_plane(float sx, float sy) {
  check_positive("make_plane: size x", sx);
  check_positive("make_plane: size y", sy);
  MeshData m;
  const double x = sx / 2.0, y = sy / 2.0;
  const double corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (const auto& c : corners) {
    push3(&m.positions, c[0] * x, c[1] * y, 0);
    push3(&m.normals, 0, 0, 1);
    push2(&m.uvs, (c[0] + 1) / 2, (c[1] + 1) / 2);
  }
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

void compute_normals(MeshData* mesh) {
  const auto& p = mesh->positions;
  std::vector<double> n(p.size(), 0.0);
  for (size_t t = 0; t + 2 < mesh->indices.size(); t += 3) {
    const uint32_t i0 = mesh->indices[t], i1 = mesh->indices[t + 1], i2 = mesh->indices[t + 2];
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
      e1[k] = static_cast<double>(p[3 * i1 + k]) - p[3 * i0 + k];
      e2[k] = static_cast<double>(p[3 * i2 + k]) - p[3 * i0 + k];
    }
    // The cross product's length is twice the area: larger faces weigh more.
    const double c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    for (uint32_t i : {i0, i1, i2}) {
      for (int k = 0; k < 3; ++k) n[3 * i + k] += c[k];
    }
  }
  mesh->normals.assign(p.size(), 0.0f);
  for (size_t v = 0; v < n.size(); v += 3) {
    const double len = std::sqrt(n[v] * n[v] + n[v + 1] * n[v + 1] + n[v + 2] * n[v + 2]);
    if (len > 0) {
      for (int k = 0; k < 3; ++k) mesh->normals[v + k] = static_cast<float>(n[v + k] / len);
    } else {
      mesh->normals[v + 2] = 1.0f;
    }
  }
}

void validate_mesh(const MeshData& mesh, const char* what) {
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument(std::string(what) + ": " + why);
  };
  if (mesh.positions.size() % 3 != 0) fail("positions.size() is not a multiple of 3");
  const size_t n = mesh.vertex_count();
  if (!mesh.normals.empty() && mesh.normals.size() != 3 * n) {
    fail("normals.size() = " + std::to_string(mesh.normals.size()) + ", expected " +
         std::to_string(3 * n));
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != 2 * n) {
    fail("uvs.size() = " + std::to_string(mesh.uvs.size()) + ", expected " + std::to_string(2 * n));
  }
  if (mesh.indices.size() % 3 != 0) fail("indices.size() is not a multiple of 3");
  for (uint32_t i : mesh.indices) {
    if (i >= n) {
      fail("index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
    }
  }
  for (float x : mesh.positions) {
    if (!std::isfinite(x)) fail("non-finite vertex position");
  }
}

}  // namespace convoy::render
