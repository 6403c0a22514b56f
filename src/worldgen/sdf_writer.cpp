#include "worldgen/sdf_writer.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace convoy::worldgen {
namespace {

namespace fs = std::filesystem;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4f", std::abs(v) < 5e-5 ? 0.0 : v);
  return buf;
}

std::string pose(const Vec3& p, double yaw) {
  return num(p[0]) + " " + num(p[1]) + " " + num(p[2]) + " 0 0 " + num(yaw);
}

std::string pose6(const std::array<double, 6>& p) {
  std::string out;
  for (size_t i = 0; i < 6; ++i) out += (i ? " " : "") + num(p[i]);
  return out;
}

std::string class_plugin(const std::string& cls) {
  return "      <plugin name='convoy_class' filename='convoy_class'><class>" + cls +
         "</class></plugin>\n";
}

void write_mesh_model(std::ostream& out, const MeshModel& m, const fs::path& dir) {
  const std::string file = "meshes/" + m.name + ".obj";
  m.mesh.write(dir / file, dir / ("meshes/" + m.name + ".mtl"), "Convoy world generator: " + m.name);
  out << "    <model name='" << m.name << "'>\n      <static>true</static>\n"
      << "      <link name='link'>\n"
      << "        <visual name='visual'><geometry><mesh><uri>" << file
      << "</uri></mesh></geometry></visual>\n";
  int k = 0;
  for (const BoxCollision& c : m.collisions) {
    out << "        <collision name='c" << k++ << "'><pose>" << pose(c.centre, c.yaw)
        << "</pose><geometry><box><size>" << num(c.size[0]) << " " << num(c.size[1]) << " "
        << num(c.size[2]) << "</size></box></geometry></collision>\n";
  }
  out << "      </link>\n" << class_plugin(m.cls) << "    </model>\n";
}

void write_placement(std::ostream& out, const Placement& p) {
  const CatalogModel& m = *p.model;
  const std::string scale = num(p.scale[0]) + " " + num(p.scale[1]) + " " + num(p.scale[2]);
  out << "    <model name='" << p.name << "'>\n      <static>true</static>\n"
      << "      <pose>" << pose(p.position, p.yaw) << "</pose>\n      <link name='link'>\n";
  for (const CatalogVisual& v : m.visuals) {
    std::array<double, 6> vp = v.pose;
    for (int i = 0; i < 3; ++i) vp[i] *= p.scale[i];
    out << "        <visual name='" << v.name << "'><pose>" << pose6(vp)
        << "</pose><geometry><mesh><uri>" << Catalog::kUriPrefix << v.mesh << "</uri><scale>"
        << scale << "</scale></mesh></geometry>";
    if (v.colour) {
      const auto& c = *v.colour;
      const std::string rgb = num(c[0]) + " " + num(c[1]) + " " + num(c[2]) + " 1";
      out << "<material><ambient>" << rgb << "</ambient><diffuse>" << rgb << "</diffuse></material>";
    }
    out << "</visual>\n";
  }
  int k = 0;
  for (const CatalogCollision& c : m.collisions) {
    std::array<double, 6> cp = c.pose;
    for (int i = 0; i < 3; ++i) cp[i] *= p.scale[i];
    out << "        <collision name='c" << k++ << "'><pose>" << pose6(cp)
        << "</pose><geometry><box><size>" << num(c.box[0] * p.scale[0]) << " "
        << num(c.box[1] * p.scale[1]) << " " << num(c.box[2] * p.scale[2])
        << "</size></box></geometry></collision>\n";
  }
  out << "      </link>\n" << class_plugin(m.cls);
  if (!p.signal_id.empty()) {
    out << "      <plugin name='convoy_signal' filename='convoy_signal'><signal>" << p.signal_id
        << "</signal>";
    for (const auto& [colour, visual] : m.lamps) {
      out << "<lamp colour='" << colour << "'>" << visual << "</lamp>";
    }
    out << "</plugin>\n";
  }
  out << "    </model>\n";
}

}  // namespace

void write_world(const WorldPlan& plan, const fs::path& dir, const WriteOptions& options) {
  fs::create_directories(dir / "meshes");
  plan.road.write(dir / "meshes/road.obj", dir / "meshes/road.mtl", "Convoy world generator: road");
  plan.ground.write(dir / "meshes/ground.obj", dir / "meshes/ground.mtl",
                    "Convoy world generator: ground and horizon");
  std::ostringstream out;
  const auto& b = plan.bounds;
  const double cx = 0.5 * (b.min[0] + b.max[0]), cy = 0.5 * (b.min[1] + b.max[1]);
  const double sx = b.max[0] - b.min[0] + 200, sy = b.max[1] - b.min[1] + 200;
  out << "<?xml version=\"1.0\"?>\n<!-- " << options.comment << " -->\n<sdf version='1.7'>\n"
      << "  <world name='" << options.world_name << "'>\n"
      << "    <gravity>0 0 -9.81</gravity>\n"
      << "    <physics type=\"ode\"><max_step_size>0.001</max_step_size></physics>\n"
      << "    <scene>\n      <ambient>0.45 0.45 0.45 1</ambient>\n"
      << "      <background>0.55 0.7 0.95 1</background>\n      <shadows>true</shadows>\n"
      << "    </scene>\n"
      << "    <light name='sun' type='directional'>\n      <pose>0 0 50 0 0 0</pose>\n"
      << "      <diffuse>0.9 0.9 0.85 1</diffuse>\n      <specular>0.2 0.2 0.2 1</specular>\n"
      << "      <direction>-0.3 0.4 -0.85</direction>\n    </light>\n"
      << "    <model name='road'>\n      <static>true</static>\n      <link name='link'>\n"
      << "        <collision name='ground'><pose>" << num(cx) << " " << num(cy)
      << " 0 0 0 0</pose><geometry><plane><normal>0 0 1</normal><size>" << num(sx) << " "
      << num(sy) << "</size></plane></geometry></collision>\n"
      << "        <visual name='road'><geometry><mesh><uri>meshes/road.obj</uri></mesh></geometry></visual>\n"
      << "        <visual name='ground'><geometry><mesh><uri>meshes/ground.obj</uri></mesh></geometry></visual>\n"
      << "      </link>\n    </model>\n";
  for (const MeshModel& m : plan.models) write_mesh_model(out, m, dir);
  for (const Placement& p : plan.placements) write_placement(out, p);
  out << "  </world>\n</sdf>\n";
  std::ofstream f(dir / "world.sdf");
  f << out.str();
  if (!f.flush()) throw std::runtime_error((dir / "world.sdf").string() + ": write failed");
}

}  // namespace convoy::worldgen
