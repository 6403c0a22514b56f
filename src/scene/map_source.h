// What a run's config says about its scene: the OpenDRIVE map (an engine's "Map" or
// "OpenDriveFile", else the .xodr a world generated from a map names in its comments),
// the ego's route (the scenario engine's "EgoRoute") and the world engines (whose RoadUser
// datapacks are the ego's).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "scene/scene_map.h"

namespace convoy::scene {

struct SceneSource {
  std::filesystem::path map;  // empty: no map found
  std::vector<Point3> route;
  std::set<std::string> world_engines;
};

// `config` is the loaded config (paths already absolute, as config::SimulationConfig::json
// holds it); relative paths are taken against `dir`. Never throws: what cannot be read is left
// out.
SceneSource scene_source(const nlohmann::json& config, const std::filesystem::path& dir);

// The first .xodr named in a comment of a world file's first 4 kB ("<!-- made from city.xodr
// by the build -->", as the generated worlds say), resolved against the world's folder, that
// exists; else empty.
std::filesystem::path map_of_world(const std::filesystem::path& world);

}  // namespace convoy::scene
