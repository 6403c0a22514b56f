// The engine config's GazeboSDFModels: models added to the world file's, each
//   {"Name": "smart_car", "File": "model.sdf", "InitPose": [x, y, z, roll, pitch, yaw],
//    "InitSpeed": 10}
// Name: the model's name (default: its SDF name). InitPose: [x, y, z] or six numbers (also as
// one string "x y z roll pitch yaw"). InitSpeed: m/s >= 0 along the pose's x axis at the
// start (default 0; systems/initial_speeds.h).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "world_description.h"

namespace convoy::world {

// The entries of GazeboSDFModels, in order. Throws std::runtime_error naming the entry and
// key: "GazeboSDFModels/0/InitSpeed: must be a number >= 0 (m/s), got -1".
std::vector<ModelInsert> read_model_inserts(const nlohmann::json& config);

// The models that insert `i` of `inserts` made in `desc` (load_world puts them after the world
// file's): the one named its Name, or without a Name the last top-level model read from its
// File, and that model's nested models ("name::..."). Empty if none.
std::vector<const ModelDesc*> models_of(const WorldDesc& desc, const ModelInsert& insert);

}  // namespace convoy::world
