// Roadside scenery placed by seed beside a map's roads, never on them: with "roadside",
// trees and bushes in irregular rows and now and then a street light; with "urban",
// buildings facing the street behind the sidewalk, street lights, benches, bins, bus stops and
// trees between the buildings. An occupancy grid of the road area (every drawn lane, the
// objects the map placed, and what was placed before) keeps each footprint off the road and
// off each other. Deterministic for a seed.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "opendrive/network.h"
#include "worldgen/catalog.h"
#include "worldgen/world_plan.h"

namespace convoy::worldgen {

enum class Scenery { kNone, kRoadside, kUrban };

// "none", "roadside" or "urban"; throws std::invalid_argument naming the value otherwise.
Scenery parse_scenery(const std::string& name);

// A grid of `cell`-metre cells over the map: marked cells are taken.
class Occupancy {
 public:
  Occupancy(const opendrive::Bounds& bounds, double margin, double cell = 1.0);
  // Marks every lane of type other than none, grown by `grow` metres.
  void mark_roads(const opendrive::Network& net, double grow);
  // Whether a rectangle (centre, size along its yaw, yaw) is free, and marking one.
  bool free(double x, double y, double length, double width, double yaw) const;
  void mark(double x, double y, double length, double width, double yaw);
  bool taken(double x, double y) const;

 private:
  template <typename F>
  void for_cells(double x, double y, double length, double width, double yaw, F&& f) const;

  double x0_, y0_, cell_;
  int nx_, ny_;
  std::vector<uint8_t> cells_;
};

void scatter_scenery(const opendrive::Network& net, const Catalog& catalog, Scenery kind,
                     uint64_t seed, Occupancy& occupancy, WorldPlan& plan);

}  // namespace convoy::worldgen
