// An independent check of LiDAR ranges: the same ray intersected in double precision with
// every triangle of every visible instance of the render::Scene (brute force, behind a
// bounding-box test per instance), for the benchmark's range-error figure.
#pragma once

#include <array>
#include <vector>

#include "render/scene.h"

namespace convoy::lidar_bench {

class BruteForce {
 public:
  // Transforms every visible instance's triangles to the world frame (double).
  explicit BruteForce(const render::Scene& scene);
  // The nearest hit along origin + t dir (dir unit) with t in [tmin, tmax]; -1 if none.
  double range(const std::array<double, 3>& origin, const std::array<double, 3>& dir, double tmin,
               double tmax) const;

 private:
  struct Part {
    std::array<double, 3> lo, hi;
    std::vector<double> tris;  // 9 per triangle, world frame
  };
  std::vector<Part> parts_;
};

}  // namespace convoy::lidar_bench
