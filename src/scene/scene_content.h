// What one datapack tells the scene (scene_state.h), apart from keeping it: road users
// (convoy.data.RoadUser / RoadUsers protobuf, or JSON with RoadUser's keys: a dict, a list of
// dicts or {"users": [...]}), the traffic_lights engine's signal states ({"signals": {id:
// state}}) and a route ({"route": [[x, y], ...]}).
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "datapack/datapack.h"
#include "scene/scene_map.h"

namespace convoy::scene {

// JSON datapacks larger than this (MessagePack bytes) are not looked into: road users and
// signals are small, camera frames as JSON are not.
inline constexpr size_t kMaxSceneJsonBytes = 256 * 1024;

struct SceneContent {
  std::vector<data::RoadUser> users;
  bool user_set = false;  // a whole set (RoadUsers, a list): users it no longer lists are gone
  bool has_signals = false;
  std::map<std::string, std::string> signals;  // OpenDRIVE signal id -> state
  std::vector<Point3> route;
  bool empty() const { return users.empty() && !user_set && !has_signals && route.empty(); }
};

// Never throws: a datapack that holds none of these, or holds them malformed, gives nothing.
SceneContent read_scene_content(const datapack::View& dp);

// A RoadUser from a dict with its field names ("id", "category", "x", ...); false unless it
// has a string "id" and numeric "x" and "y". Keys that are no field, or of another type, are
// left out.
bool road_user_from_json(const nlohmann::json& j, data::RoadUser* out);

}  // namespace convoy::scene
