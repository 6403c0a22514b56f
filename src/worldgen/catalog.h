// The scenery catalog (engines/gazebo_grpc/scenery/scenery_models.json, written by
// tools/assets/make_scenery.py): the models the world generator places, with their
// ground-truth class, size, visuals and collision boxes.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace convoy::worldgen {

struct CatalogVisual {
  std::string name;
  std::string mesh;                             // relative to the catalog's folder
  std::array<double, 6> pose{};                 // x y z roll pitch yaw in the model's frame
  std::optional<std::array<double, 3>> colour;  // overrides the mesh's diffuse colour
};

struct CatalogCollision {
  std::array<double, 6> pose{};
  std::array<double, 3> box{};
};

struct CatalogModel {
  std::string name;
  std::string kind;              // building, tree, shrub, street_light, bench, bin, bus_stop, ...
  std::string cls;               // ground-truth class
  std::array<double, 3> size{};  // length (x), width (y), height (z) of its bounding box
  std::vector<CatalogVisual> visuals;
  std::vector<CatalogCollision> collisions;
  std::string sign_type;  // signs: stop, yield, no_entry, speed_limit, warning, priority
  double sign_value = 0;  // speed limits: km/h
  std::map<std::string, std::string> lamps;  // lights: colour -> visual name
};

class Catalog {
 public:
  // Reads the catalog; throws std::runtime_error naming the file and the entry.
  static Catalog load(const std::filesystem::path& file);
  // The catalog next to the binaries (share/convoy/models/convoy_scenery), else the source's.
  static std::filesystem::path default_path();

  const CatalogModel* find(const std::string& name) const;
  // Names of the models of one kind, sorted (deterministic choice by seed).
  std::vector<const CatalogModel*> of_kind(const std::string& kind) const;
  // The sign for a type (and a speed limit's value, the nearest one shipped), or null.
  const CatalogModel* sign(const std::string& type, double value = 0) const;
  // The URI prefix of the catalog's meshes in a world (model://convoy_scenery/).
  static constexpr const char* kUriPrefix = "model://convoy_scenery/";
  bool empty() const { return models_.empty(); }

 private:
  std::map<std::string, CatalogModel> models_;
};

}  // namespace convoy::worldgen
