// One LiDAR revolution as a labelled point cloud (as SemanticKITTI labels its scans): the
// returns only, in ray order (ring-major: ring 0's columns, then ring 1's, ...), in the
// sensor's frame. A plain array of 32-byte records so that a datapack can carry it as one
// blob without conversion.
#pragma once

#include <cstdint>
#include <vector>

namespace convoy::lidar {

struct Point {
  float x, y, z;      // metres, sensor frame
  float intensity;    // 0-1: the surface's reflectivity x cos(incidence) x weather
  uint32_t instance;  // ground truth: the render::Scene instance's model_id (0: none)
  uint32_t label;     // ground truth: its class_id (0: none)
  uint16_t ring;      // vertical sample, 0 = lowest
  uint16_t column;    // horizontal sample
  uint32_t flags;     // kSpurious, or 0
  static constexpr uint32_t kSpurious = 1;  // a return from rain, snow or fog (no ground truth)
};
static_assert(sizeof(Point) == 32);

struct PointCloud {
  double time = 0;  // simulated seconds of the scan
  int rings = 0, columns = 0;
  std::vector<Point> points;
};

}  // namespace convoy::lidar
