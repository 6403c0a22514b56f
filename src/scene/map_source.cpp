#include "scene/map_source.h"

#include <fstream>
#include <regex>

namespace convoy::scene {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr size_t kWorldHeadBytes = 4096;  // where a world's comments name its map

fs::path existing(const json& value, const fs::path& dir) {
  if (!value.is_string()) return {};
  fs::path p = value.get<std::string>();
  if (p.empty()) return {};
  if (p.is_relative()) p = dir / p;
  std::error_code ec;
  return fs::is_regular_file(p, ec) ? p.lexically_normal() : fs::path();
}

std::vector<Point3> route_of(const json& value) {
  std::vector<Point3> out;
  if (!value.is_array()) return out;
  for (const json& p : value) {
    if (p.is_array() && p.size() >= 2 && p[0].is_number() && p[1].is_number())
      out.push_back({p[0].get<double>(), p[1].get<double>(),
                     p.size() > 2 && p[2].is_number() ? p[2].get<double>() : 0.0});
  }
  return out;
}

}  // namespace

fs::path map_of_world(const fs::path& world) {
  std::ifstream in(world);
  if (!in) return {};
  std::string head(kWorldHeadBytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  static const std::regex kXodr(R"(([A-Za-z0-9_./-]+\.xodr))");
  for (size_t open = head.find("<!--"); open != std::string::npos;
       open = head.find("<!--", open + 4)) {
    const size_t close = head.find("-->", open);
    const std::string comment =
        head.substr(open, close == std::string::npos ? std::string::npos : close - open);
    for (auto it = std::sregex_iterator(comment.begin(), comment.end(), kXodr);
         it != std::sregex_iterator(); ++it) {
      fs::path p = existing(json((*it)[1].str()), world.parent_path());
      if (!p.empty()) return p;
    }
  }
  return {};
}

SceneSource scene_source(const json& config, const fs::path& dir) {
  SceneSource out;
  const auto engines = config.find("EngineConfigs");
  if (engines == config.end() || !engines->is_array()) return out;
  fs::path from_world;
  for (const json& e : *engines) {
    if (!e.is_object()) continue;
    const std::string type = e.value("EngineType", std::string());
    if (type.find("gazebo") != std::string::npos) {
      out.world_engines.insert(e.value("EngineName", std::string()));
      if (from_world.empty() && e.contains("GazeboWorldFile"))
        from_world = map_of_world(existing(e["GazeboWorldFile"], dir));
    }
    for (const char* key : {"Map", "OpenDriveFile"}) {
      if (!out.map.empty() || !e.contains(key)) continue;
      const fs::path p = existing(e[key], dir);
      if (p.extension() == ".xodr") out.map = p;
    }
    if (out.route.empty() && e.contains("EgoRoute")) out.route = route_of(e["EgoRoute"]);
  }
  if (out.map.empty()) out.map = from_world;
  return out;
}

}  // namespace convoy::scene
