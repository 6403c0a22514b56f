// Pool networks of the tests' maps, each read once for a test binary: map() is the 3x3 SUMO
// grid (CONVOY_POOL_GRID_XODR), city() the city map with sidewalks, crosswalks and lights
// (CONVOY_CITY_XODR, experiments/city_traffic/city.xodr).
#pragma once

#include <functional>
#include <string>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "traffic_pool/pool.h"

namespace convoy::traffic_pool {

struct Map {
  explicit Map(const char* xodr) : net(opendrive::load(xodr)) {}
  opendrive::Network net;
  opendrive::LaneGraph graph{net};
  PoolNetwork pool{graph};
};

// The PoolError message `f` throws ("" when it throws none).
inline std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const PoolError& e) {
    return e.what();
  }
  return "";
}

// A vehicle placed `s` m along `lane`.
inline VehicleSpec at(const std::string& id, const PoolLane& lane, double s) {
  VehicleSpec v;
  v.id = id;
  v.road = lane.road_id;
  v.lane = lane.lane_id;
  v.s = s;
  return v;
}

#ifdef CONVOY_POOL_GRID_XODR
inline const Map& map() {
  static const Map* m = new Map(CONVOY_POOL_GRID_XODR);
  return *m;
}
#endif

#ifdef CONVOY_CITY_XODR
inline const Map& city() {
  static const Map* m = new Map(CONVOY_CITY_XODR);
  return *m;
}
#endif

}  // namespace convoy::traffic_pool
