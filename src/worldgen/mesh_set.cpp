#include "worldgen/mesh_set.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "opendrive/text_file.h"

namespace convoy::worldgen {
namespace {

using opendrive::close_checked;
using opendrive::File;
using opendrive::open_for_writing;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

Vec3 unit_normal(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 u = sub(b, a), v = sub(c, a);
  Vec3 n = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  const double len = std::hypot(n[0], n[1], n[2]);
  return len > 0 ? Vec3{n[0] / len, n[1] / len, n[2] / len} : Vec3{0, 0, 1};
}

}  // namespace

Part& MeshSet::part(const std::string& name, const MaterialDesc& material) {
  auto [it, added] = parts_.try_emplace(name);
  if (added) it->second.material = material;
  return it->second;
}

void MeshSet::add_road_mesh(const opendrive::RoadMesh& road) {
  for (const auto& [kind, mesh] : road.parts) {
    const bool mark = std::string(opendrive::surface_kind_name(kind)).rfind("mark_", 0) == 0;
    Part& p = part(opendrive::surface_kind_name(kind),
                   {opendrive::surface_kind_colour(kind), mark ? 0.2 : 0.05, ""});
    const auto base = static_cast<uint32_t>(p.positions.size());
    p.positions.insert(p.positions.end(), mesh.positions.begin(), mesh.positions.end());
    p.normals.insert(p.normals.end(), mesh.normals.begin(), mesh.normals.end());
    for (const auto& t : mesh.triangles)
      p.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  }
}

void MeshSet::add_convex(Part& p, const std::vector<Vec3>& corners) {
  if (corners.size() < 3) return;
  const Vec3 n = unit_normal(corners[0], corners[1], corners[2]);
  const auto base = static_cast<uint32_t>(p.positions.size());
  for (const Vec3& c : corners) {
    p.positions.push_back(c);
    p.normals.push_back(n);
  }
  if (!p.uvs.empty()) p.uvs.resize(p.positions.size(), {0, 0});  // uvs stay one per position
  for (uint32_t i = 1; i + 1 < corners.size(); ++i)
    p.triangles.push_back({base, base + i, base + i + 1});
}

void MeshSet::add_quad(Part& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                       const std::array<std::array<double, 2>, 4>* uv) {
  const Vec3 n = unit_normal(a, b, c);
  const auto base = static_cast<uint32_t>(p.positions.size());
  if (uv && p.uvs.size() < p.positions.size()) p.uvs.resize(p.positions.size(), {0, 0});
  int k = 0;
  for (const Vec3* v : {&a, &b, &c, &d}) {
    p.positions.push_back(*v);
    p.normals.push_back(n);
    if (uv)
      p.uvs.push_back((*uv)[k]);
    else if (!p.uvs.empty())
      p.uvs.push_back({0, 0});
    ++k;
  }
  p.triangles.push_back({base, base + 1, base + 2});
  p.triangles.push_back({base, base + 2, base + 3});
}

void MeshSet::add_box(Part& p, const Vec3& centre, const Vec3& size, double yaw) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  auto at = [&](double x, double y, double z) {
    const double hx = 0.5 * size[0] * x, hy = 0.5 * size[1] * y;
    return Vec3{centre[0] + c * hx - s * hy, centre[1] + s * hx + c * hy,
                centre[2] + 0.5 * size[2] * z};
  };
  // corners by sign: (x, y, z) in {-1, 1}^3; each face counter-clockwise seen from outside
  add_quad(p, at(-1, -1, 1), at(1, -1, 1), at(1, 1, 1), at(-1, 1, 1));      // top
  add_quad(p, at(-1, 1, -1), at(1, 1, -1), at(1, -1, -1), at(-1, -1, -1));  // bottom
  add_quad(p, at(1, -1, -1), at(1, 1, -1), at(1, 1, 1), at(1, -1, 1));      // +x
  add_quad(p, at(-1, 1, -1), at(-1, -1, -1), at(-1, -1, 1), at(-1, 1, 1));  // -x
  add_quad(p, at(1, 1, -1), at(-1, 1, -1), at(-1, 1, 1), at(1, 1, 1));      // +y
  add_quad(p, at(-1, -1, -1), at(1, -1, -1), at(1, -1, 1), at(-1, -1, 1));  // -y
}

std::map<std::pair<int, int>, MeshSet> MeshSet::tiles(double size) const {
  std::map<std::pair<int, int>, MeshSet> out;
  for (const auto& [name, p] : parts_) {
    const bool uv = p.uvs.size() == p.positions.size() && !p.uvs.empty();
    // old vertex -> new vertex, per tile
    std::map<std::pair<int, int>, std::map<uint32_t, uint32_t>> remap;
    for (const auto& t : p.triangles) {
      double cx = 0, cy = 0;
      for (uint32_t k : t) cx += p.positions[k][0] / 3, cy += p.positions[k][1] / 3;
      const std::pair<int, int> key{static_cast<int>(std::floor(cx / size)),
                                    static_cast<int>(std::floor(cy / size))};
      Part& q = out[key].part(name, p.material);
      auto& map = remap[key];
      std::array<uint32_t, 3> nt{};
      for (int j = 0; j < 3; ++j) {
        auto [it, added] = map.try_emplace(t[j], static_cast<uint32_t>(q.positions.size()));
        if (added) {
          q.positions.push_back(p.positions[t[j]]);
          q.normals.push_back(p.normals[t[j]]);
          if (uv) q.uvs.push_back(p.uvs[t[j]]);
        }
        nt[j] = it->second;
      }
      q.triangles.push_back(nt);
    }
  }
  return out;
}

size_t MeshSet::triangle_count() const {
  size_t n = 0;
  for (const auto& [name, p] : parts_) n += p.triangles.size();
  return n;
}

void MeshSet::write(const std::filesystem::path& obj, const std::filesystem::path& mtl,
                    const std::string& comment) const {
  File f = open_for_writing(obj);
  std::fprintf(f.get(), "# %s\n# z up, metres\nmtllib %s\n", comment.c_str(),
               mtl.filename().c_str());
  size_t offset = 1, uv_offset = 1;  // OBJ indices are 1-based and global
  for (const auto& [name, p] : parts_) {
    if (p.triangles.empty()) continue;
    std::fprintf(f.get(), "o %s\nusemtl %s\n", name.c_str(), name.c_str());
    for (const auto& v : p.positions) std::fprintf(f.get(), "v %.4f %.4f %.4f\n", v[0], v[1], v[2]);
    for (const auto& n : p.normals) std::fprintf(f.get(), "vn %.4f %.4f %.4f\n", n[0], n[1], n[2]);
    const bool uv = p.uvs.size() == p.positions.size() && !p.uvs.empty();
    if (uv) {
      for (const auto& t : p.uvs) std::fprintf(f.get(), "vt %.4f %.4f\n", t[0], t[1]);
    }
    for (const auto& t : p.triangles) {
      const size_t a = t[0] + offset, b = t[1] + offset, c = t[2] + offset;
      if (uv) {
        const size_t ta = t[0] + uv_offset, tb = t[1] + uv_offset, tc = t[2] + uv_offset;
        std::fprintf(f.get(), "f %zu/%zu/%zu %zu/%zu/%zu %zu/%zu/%zu\n", a, ta, a, b, tb, b, c, tc,
                     c);
      } else {
        std::fprintf(f.get(), "f %zu//%zu %zu//%zu %zu//%zu\n", a, a, b, b, c, c);
      }
    }
    offset += p.positions.size();
    if (uv) uv_offset += p.uvs.size();
  }
  close_checked(std::move(f), obj);

  File m = open_for_writing(mtl);
  std::fprintf(m.get(), "# %s\n", comment.c_str());
  for (const auto& [name, p] : parts_) {
    if (p.triangles.empty()) continue;
    const auto& c = p.material.diffuse;
    const double k = p.material.specular;
    std::fprintf(m.get(), "\nnewmtl %s\nKa %.3f %.3f %.3f\nKd %.3f %.3f %.3f\n", name.c_str(), c[0],
                 c[1], c[2], c[0], c[1], c[2]);
    std::fprintf(m.get(), "Ks %.3f %.3f %.3f\nNs %d\nd 1\nillum 2\n", k, k, k, k > 0.1 ? 30 : 10);
    if (!p.material.texture.empty())
      std::fprintf(m.get(), "map_Kd %s\n", p.material.texture.c_str());
  }
  close_checked(std::move(m), mtl);
}

}  // namespace convoy::worldgen
