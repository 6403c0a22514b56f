// Writing a WorldPlan: OUT_DIR/world.sdf (a world without an ego, like the shipped
// *_no_ego.sdf worlds) with the road and ground as one static ground model (a collision plane,
// so it gets no ground-truth box), one static model per generated solid and per placement,
// each with its ground-truth class (a convoy_class plugin), and OUT_DIR/meshes/*.obj + .mtl.
// Placed catalog models refer to model://convoy_scenery/...; traffic lights carry a
// convoy_signal plugin naming their OpenDRIVE signal and lamp visuals.
#pragma once

#include <filesystem>
#include <string>

#include "worldgen/world_plan.h"

namespace convoy::worldgen {

struct WriteOptions {
  std::string world_name = "default";
  std::string comment;  // written at the top of world.sdf
};

void write_world(const WorldPlan& plan, const std::filesystem::path& out_dir,
                 const WriteOptions& options);

}  // namespace convoy::worldgen
