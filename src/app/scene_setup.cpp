#include "app/scene_setup.h"

#include <map>
#include <mutex>

#include "convoy/road_users.pb.h"
#include "datapack/registry.h"
#include "scene/map_source.h"

namespace convoy::app {

namespace {

std::shared_ptr<const scene::SceneMap> load_once(const std::string& path, RunLog& log) {
  static std::mutex mutex;
  static std::map<std::string, std::shared_ptr<const scene::SceneMap>> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  if (auto it = loaded.find(path); it != loaded.end()) return it->second;
  std::shared_ptr<const scene::SceneMap> map;
  try {
    map = std::make_shared<const scene::SceneMap>(scene::load_scene_map(path));
    log.info("scene: map " + path + " (" + std::to_string(map->lines.size()) + " lines, " +
             std::to_string(map->points()) + " points, " + std::to_string(map->signals.size()) +
             " lights)");
  } catch (const std::exception& e) {
    log.info("warning: scene: no /convoy/map: " + std::string(e.what()));
  }
  loaded.emplace(path, map);
  return map;
}

}  // namespace

SceneSetup scene_setup(const config::SimulationConfig& cfg, RunLog& log) {
  const scene::SceneSource source = scene::scene_source(cfg.json, cfg.dir);
  SceneSetup out;
  out.options.world_engines = source.world_engines;
  out.options.route = source.route;
  if (!source.map.empty()) out.map = load_once(source.map.string(), log);
  return out;
}

std::vector<engine::DataPackId> scene_datapacks(const std::vector<loop::EngineHandle*>& engines) {
  const std::string road_user(datapack::type_name<data::RoadUser>());
  std::vector<engine::DataPackId> out;
  for (const loop::EngineHandle* e : engines) {
    const std::string& type = e->config().type;
    const bool world = type.find("gazebo") != std::string::npos;
    const bool agent = type == "vehicle_agent" || type == "pedestrian_agent";
    if (!world && !agent) continue;
    for (const engine::DataPackId& id : e->registered) {
      if (id.type() != road_user) continue;
      const std::string& name = id.name();
      constexpr std::string_view kEgo = "::road_user";
      if (world && !(name.size() > kEgo.size() &&
                     name.compare(name.size() - kEgo.size(), kEgo.size(), kEgo) == 0))
        continue;
      engine::DataPackId& wanted = out.emplace_back();
      wanted.set_name(name);
      wanted.set_engine_name(e->name());
    }
  }
  return out;
}

}  // namespace convoy::app
