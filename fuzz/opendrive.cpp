// Fuzzes the OpenDRIVE reader (src/opendrive): parse an .xodr, then what the tools and the
// world build from it: lane centres, a route from every driving lane, bounds, the road mesh and
// the lane graph (routes between lanes, locating lane points).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "opendrive/lane_graph.h"
#include "opendrive/parser.h"
#include "opendrive/road_mesh.h"
#include "opendrive/sampling.h"

using namespace convoy::opendrive;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  Network network;
  try {
    network = parse(std::string(reinterpret_cast<const char*>(data), size), "fuzz.xodr");
  } catch (const std::runtime_error&) {
    return 0;
  }
  try {
    (void)network_bounds(network);
  } catch (const std::runtime_error&) {
  }
  for (const Road& road : network.roads) {
    if (road.sections.empty()) continue;
    for (const Lane& lane : road.sections.front().lanes) {
      try {
        (void)sample_lane_centre(network, road.id, lane.id, 1.0);
        (void)sample_route(network, road.id, lane.id, 1.0);
      } catch (const std::runtime_error&) {
      }
    }
  }
  try {
    (void)build_road_mesh(network);
  } catch (const std::runtime_error&) {
  }
  try {
    const LaneGraph graph(network);
    const size_t n = std::min<size_t>(graph.lanes().size(), 16);
    RouteOptions walk;
    walk.lane_types = {"sidewalk", "driving"};
    walk.both_directions = true;
    for (size_t i = 0; i < n; ++i) {
      const LaneNode& a = graph.lane(static_cast<LaneIndex>(i));
      const LaneNode& b = graph.lane(static_cast<LaneIndex>(n - 1 - i));
      if (auto r = graph.route(a.index, a.s0, b.index, b.s1)) (void)graph.sample(*r, 1.0);
      (void)graph.route(a.index, a.s1, b.index, b.s0, walk);
      const WorldPose w = graph.world_pose(a.road->id, a.lane_id, 0.5 * (a.s0 + a.s1), 0.1);
      (void)graph.locate(w.x, w.y, w.heading);
      (void)graph.speed_limit(a.index, a.s0);
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
