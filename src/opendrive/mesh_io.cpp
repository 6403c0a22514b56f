#include "opendrive/mesh_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "opendrive/text_file.h"

namespace convoy::opendrive {

void write_obj(const RoadMesh& mesh, const std::filesystem::path& obj,
               const std::string& mtl_file_name) {
  File f = open_for_writing(obj);
  std::fprintf(f.get(), "# Convoy road mesh (ASAM OpenDRIVE lanes), z up, metres\n");
  std::fprintf(f.get(), "mtllib %s\n", mtl_file_name.c_str());
  size_t offset = 1;  // OBJ indices are 1-based and global
  for (const auto& [kind, part] : mesh.parts) {
    const char* name = surface_kind_name(kind);
    std::fprintf(f.get(), "o %s\nusemtl %s\n", name, name);
    for (const auto& p : part.positions) {
      std::fprintf(f.get(), "v %.4f %.4f %.4f\n", p[0], p[1], p[2]);
    }
    for (const auto& n : part.normals) {
      std::fprintf(f.get(), "vn %.5f %.5f %.5f\n", n[0], n[1], n[2]);
    }
    for (const auto& t : part.triangles) {
      const size_t a = t[0] + offset, b = t[1] + offset, c = t[2] + offset;
      std::fprintf(f.get(), "f %zu//%zu %zu//%zu %zu//%zu\n", a, a, b, b, c, c);
    }
    offset += part.positions.size();
  }
  close_checked(std::move(f), obj);
}

void write_mtl(const RoadMesh& mesh, const std::filesystem::path& mtl) {
  File f = open_for_writing(mtl);
  std::fprintf(f.get(), "# Convoy road materials\n");
  for (const auto& [kind, part] : mesh.parts) {
    const auto c = surface_kind_colour(kind);
    const bool mark = kind == SurfaceKind::kMarkWhite || kind == SurfaceKind::kMarkYellow;
    std::fprintf(f.get(), "\nnewmtl %s\n", surface_kind_name(kind));
    std::fprintf(f.get(), "Ka %.3f %.3f %.3f\n", c[0], c[1], c[2]);
    std::fprintf(f.get(), "Kd %.3f %.3f %.3f\n", c[0], c[1], c[2]);
    std::fprintf(f.get(), "Ks %.3f %.3f %.3f\nNs %d\nd 1\nillum 2\n", mark ? 0.2 : 0.05,
                 mark ? 0.2 : 0.05, mark ? 0.2 : 0.05, mark ? 30 : 10);
  }
  close_checked(std::move(f), mtl);
}

void write_road_sdf(const std::filesystem::path& sdf, const std::string& mesh_uri,
                    const Bounds& bounds, const std::string& model_name, double margin) {
  const double cx = 0.5 * (bounds.min[0] + bounds.max[0]);
  const double cy = 0.5 * (bounds.min[1] + bounds.max[1]);
  const double sx = bounds.max[0] - bounds.min[0] + 2 * margin;
  const double sy = bounds.max[1] - bounds.min[1] + 2 * margin;
  File f = open_for_writing(sdf);
  std::fprintf(f.get(),
               "<?xml version=\"1.0\"?>\n"
               "<sdf version=\"1.7\">\n"
               "  <model name=\"%s\">\n"
               "    <static>true</static>\n"
               "    <link name=\"link\">\n"
               "      <collision name=\"ground\">\n"
               "        <pose>%.3f %.3f 0 0 0 0</pose>\n"
               "        <geometry><plane><normal>0 0 1</normal><size>%.3f %.3f</size></plane>"
               "</geometry>\n"
               "      </collision>\n"
               "      <visual name=\"road\">\n"
               "        <cast_shadows>false</cast_shadows>\n"
               "        <geometry><mesh><uri>%s</uri></mesh></geometry>\n"
               "      </visual>\n"
               "    </link>\n"
               "  </model>\n"
               "</sdf>\n",
               model_name.c_str(), cx, cy, sx, sy, mesh_uri.c_str());
  close_checked(std::move(f), sdf);
}

}  // namespace convoy::opendrive
