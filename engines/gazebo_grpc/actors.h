// Road users as actors of the world: the library of actor models (a JSON table: model ->
// SDF file, class, size) and the road-user state read from RoadUser / RoadUsers datapacks
// (protobuf, or python_json dicts with the same keys). See docs/architecture.md, Actors.
#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "world_description.h"

namespace convoy::world {

// One entry of the actor-model table.
struct ActorModel {
  std::string key;  // the table's key ("sedan", "walker"...)
  std::filesystem::path file;
  std::string cls;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();  // length width height at scale 1
  double length_offset = 0;
  ModelDesc desc;  // the parsed SDF model, its frame the actor's (box centre on the ground)
  // A walker's animation (the table's "walk_cycle" and "stand"): the poses of its walking
  // cycle, pose k at walk_phase k / walk_cycle.size(), and its standing model; empty when
  // the model is not animated. Shown in place of `desc` by the cameras (docs/road_users.md).
  std::vector<ModelDesc> walk_cycle;
  std::vector<ModelDesc> stand;  // none or one
};

class ActorLibrary {
 public:
  // The table next to the engine's build/install (share/convoy/actors/actor_models.json),
  // or `table` if not empty. Throws std::runtime_error naming the file.
  explicit ActorLibrary(const std::filesystem::path& table = {});

  // The model for a road user: `model` if the table has it, else its category's default.
  // Throws std::runtime_error naming both when neither is known.
  const ActorModel& find(const std::string& model, const std::string& category);
  const std::filesystem::path& table() const { return table_; }

 private:
  std::filesystem::path table_;
  nlohmann::json json_;
  std::map<std::string, ActorModel> loaded_;
};

// `m` (link poses in its own frame) scaled by `s` along its axes: shapes and poses.
ModelDesc scaled(const ModelDesc& m, const Eigen::Vector3d& s);

// Road users from a datapack's JSON content: a dict with RoadUser's keys, or {"users": [...]}
// (RoadUsers), or a list of dicts. Unknown keys and wrong types throw std::runtime_error.
std::vector<data::RoadUser> road_users_from_json(const nlohmann::json& j);

// The pose of the reference point a road user gives.
Eigen::Isometry3d road_user_pose(const data::RoadUser& u);

}  // namespace convoy::world
