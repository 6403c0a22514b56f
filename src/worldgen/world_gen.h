// The world generator: an OpenDRIVE map becomes a world SDF without an ego, with its meshes
// (convoy-odr world MAP OUT_DIR). See docs/worlds.md.
//
//   - road surfaces with a material per lane type, road marks, stop lines, crosswalks and
//     parking bays (road_mesh.h with lane_materials, markings.h);
//   - signals as traffic lights and signs (signals.h), objects, tunnels and bridges
//     (objects.h);
//   - scenery by seed beside the roads (scenery.h), a ground and a horizon (ground.h).
//
// Elements it cannot build are skipped with a warning naming the road and element; only a map
// that cannot be parsed is an error. The output folder appears whole or not at all: the world
// is written into a temporary sibling folder that replaces OUT_DIR when everything is written.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "opendrive/network.h"
#include "worldgen/catalog.h"
#include "worldgen/scenery.h"

namespace convoy::worldgen {

struct WorldOptions {
  Scenery scenery = Scenery::kNone;
  uint64_t seed = 1;
  // The roads' surface of maps that are not flat as a height field (height_field.h): the road
  // model's <heightmap> collision, the plane moved under the lowest ground.
  bool height_field = true;
};

struct WorldStats {
  size_t triangles = 0;   // generated geometry (road, ground, solids), without catalog models
  size_t models = 0;      // models in the world, the road included
  size_t placements = 0;  // catalog models placed
  size_t signals = 0;     // traffic lights and signs placed
  std::vector<std::string> warnings;
};

WorldStats generate_world(const opendrive::Network& net, const Catalog& catalog,
                          const WorldOptions& options, const std::filesystem::path& out_dir);

}  // namespace convoy::worldgen
