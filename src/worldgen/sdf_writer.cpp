#include "worldgen/sdf_writer.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace convoy::worldgen {
namespace {

namespace fs = std::filesystem;

constexpr double kRoadTile = 128;  // m

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

// Model names unique in the world: a map may give two signals or objects of a road one id.
class Names {
 public:
  std::string operator()(const std::string& name) {
    std::string n = name;
    for (int k = 2; !taken_.insert(n).second; ++k) n = name + "_" + std::to_string(k);
    return n;
  }

 private:
  std::set<std::string> taken_;
};

void write_mesh_model(std::ostream& out, const MeshModel& m, const std::string& name,
                      const fs::path& dir) {
  const std::string file = "meshes/" + name + ".obj";
  m.mesh.write(dir / file, dir / ("meshes/" + name + ".mtl"), "Convoy world generator: " + name);
  out << "    <model name='" << name << "'>\n      <static>true</static>\n"
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

void write_placement(std::ostream& out, const Placement& p, const std::string& name) {
  const CatalogModel& m = *p.model;
  const std::string scale = num(p.scale[0]) + " " + num(p.scale[1]) + " " + num(p.scale[2]);
  out << "    <model name='" << name << "'>\n      <static>true</static>\n"
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
      out << "<material><ambient>" << rgb << "</ambient><diffuse>" << rgb
          << "</diffuse></material>";
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
  // The road in tiles: the renderer culls each tile outside the view and simplifies the far.
  std::vector<std::string> road_tiles;
  for (const auto& [key, tile] : plan.road.tiles(kRoadTile)) {
    const std::string name = "road_" + std::to_string(key.first) + "_" + std::to_string(key.second);
    tile.write(dir / ("meshes/" + name + ".obj"), dir / ("meshes/" + name + ".mtl"),
               "Convoy world generator: road tile " + name);
    road_tiles.push_back(name);
  }
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
      << "        <collision name='ground'><pose>" << num(cx) << " " << num(cy) << " "
      << num(plan.plane_z) << " 0 0 0</pose><geometry><plane><normal>0 0 1</normal><size>"
      << num(sx) << " " << num(sy) << "</size></plane></geometry></collision>\n"
      << "        <visual name='ground'><cast_shadows>false</cast_shadows><geometry><mesh><uri>"
         "meshes/ground.obj</uri></mesh></geometry></visual>\n";
  if (plan.height_field) {
    // Gazebo's <heightmap>: the image spans <size> (from the first sample's centre to the
    // last's) around <pos>, its values 0..65535 standing for pos.z .. pos.z + size.z.
    const HeightField& f = *plan.height_field;
    write_pgm(f, dir / "meshes/road_heights.pgm");
    const double sx = (f.columns - 1) * f.cell, sy = (f.rows - 1) * f.cell;
    out << "        <collision "
           "name='surface'><geometry><heightmap><uri>meshes/road_heights.pgm</uri>"
        << "<size>" << num(sx) << " " << num(sy) << " " << num(std::max(1e-6, f.max() - f.min()))
        << "</size><pos>" << num(f.x0 + 0.5 * sx) << " " << num(f.y0 + 0.5 * sy) << " "
        << num(f.min()) << "</pos></heightmap></geometry></collision>\n";
  }
  for (const std::string& t : road_tiles) {
    // flat but for 12 cm curbs: their shadows are not worth a second drawing of the road
    out << "        <visual name='" << t << "'><cast_shadows>false</cast_shadows><geometry><mesh>"
        << "<uri>meshes/" << t << ".obj</uri></mesh></geometry></visual>\n";
  }
  out << "      </link>\n    </model>\n";
  Names names;
  for (const MeshModel& m : plan.models) write_mesh_model(out, m, names(m.name), dir);
  for (const Placement& p : plan.placements) write_placement(out, p, names(p.name));
  out << "  </world>\n</sdf>\n";
  std::ofstream f(dir / "world.sdf");
  f << out.str();
  if (!f.flush()) throw std::runtime_error((dir / "world.sdf").string() + ": write failed");
}

}  // namespace convoy::worldgen
