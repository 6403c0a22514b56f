// Triangle meshes grouped by material, for the world generator's own geometry (road surfaces,
// markings, walls, extruded buildings, the ground and the horizon), and their OBJ + MTL files.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "opendrive/road_mesh.h"

namespace convoy::worldgen {

using Vec3 = std::array<double, 3>;

struct MaterialDesc {
  std::array<double, 3> diffuse{0.5, 0.5, 0.5};  // linear RGB
  double specular = 0.05;
  std::string texture;  // a file name next to the MTL (map_Kd), or empty
};

// One material's triangles. uvs are either empty or one per position.
struct Part {
  MaterialDesc material;
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;  // one per position
  std::vector<std::array<double, 2>> uvs;
  std::vector<std::array<uint32_t, 3>> triangles;
};

class MeshSet {
 public:
  // The part named `name`, made with `material` the first time.
  Part& part(const std::string& name, const MaterialDesc& material);
  // Adds every surface of a road mesh as a part named after its kind.
  void add_road_mesh(const opendrive::RoadMesh& road);

  // The add_* functions add flat-shaded faces with vertices of their own.
  // A flat-shaded convex polygon (counter-clockwise seen from its normal's side),
  // fan-triangulated from its first corner: only for convex polygons.
  static void add_convex(Part& p, const std::vector<Vec3>& corners);
  // A quad a b c d (counter-clockwise seen from the front), with uvs when given.
  static void add_quad(Part& p, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d,
                       const std::array<std::array<double, 2>, 4>* uv = nullptr);
  // An axis-aligned box in a frame at `centre` turned by `yaw`, size (x, y, z).
  static void add_box(Part& p, const Vec3& centre, const Vec3& size, double yaw);

  size_t triangle_count() const;
  bool empty() const { return parts_.empty(); }
  const std::map<std::string, Part>& parts() const { return parts_; }

  // The triangles split into square tiles of `size` metres by their centroids (x, y), each
  // tile a MeshSet with the same parts: so that a renderer can cull and simplify each tile.
  std::map<std::pair<int, int>, MeshSet> tiles(double size) const;

  // Writes `obj` and `mtl` (next to each other; the OBJ names the MTL by file name).
  void write(const std::filesystem::path& obj, const std::filesystem::path& mtl,
             const std::string& comment) const;

 private:
  std::map<std::string, Part> parts_;
};

}  // namespace convoy::worldgen
