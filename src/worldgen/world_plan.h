// What the world generator makes of a map before it is written: the road's meshes, models of
// its own (extruded buildings, walls, tunnels, markings) and placements of catalog models.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "opendrive/network.h"
#include "worldgen/catalog.h"
#include "worldgen/height_field.h"
#include "worldgen/mesh_set.h"

namespace convoy::worldgen {

// A catalog model at a pose (yaw about z), scaled along its axes.
struct Placement {
  std::string name;  // unique in the world
  const CatalogModel* model = nullptr;
  Vec3 position{};
  double yaw = 0;
  Vec3 scale{1, 1, 1};
  std::string signal_id;  // lights: the OpenDRIVE signal whose state they show
};

// A static box collision in world coordinates, turned by yaw.
struct BoxCollision {
  Vec3 centre{};
  Vec3 size{};
  double yaw = 0;
};

// A model made of the generator's own geometry: one ground-truth instance of `cls`.
struct MeshModel {
  std::string name;
  std::string cls;
  MeshSet mesh;  // world coordinates
  std::vector<BoxCollision> collisions;
};

struct WorldPlan {
  MeshSet road;    // surfaces, marks, stop lines, crosswalks, parking bays, embankments
  MeshSet ground;  // the ground plane and the horizon
  double ground_z = 0;
  double plane_z = 0;                       // the collision plane under everything
  std::optional<HeightField> height_field;  // the roads' surface where it is not flat
  opendrive::Bounds bounds;                 // of the roads
  std::vector<MeshModel> models;
  std::vector<Placement> placements;
  std::vector<std::string> warnings;  // "road 3 signal 12: ..." each skipped element

  void warn(const std::string& what) { warnings.push_back(what); }
};

// A point on a road at (s, t), dz above its surface, in world coordinates.
Vec3 road_point(const opendrive::Road& road, double s, double t, double dz = 0);

}  // namespace convoy::worldgen
