// Fuzzes the OpenDRIVE reader (src/opendrive): parse an .xodr, then what the tools and the
// world build from it: lane centres, a route from every driving lane, bounds and the road mesh.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

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
  return 0;
}
