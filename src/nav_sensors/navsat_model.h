// A GNSS receiver as SDF's <navsat> describes it (and Gazebo's NavSat sensor reads): the
// sensor's position as latitude, longitude and altitude on the world's GeoFrame, and its
// velocity east, north and up. The <position_sensing> noise acts in metres on the east and
// north components (horizontal) and on up (vertical) before the conversion to degrees; the
// <velocity_sensing> noise on the velocity's components the same way.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "nav_sensors/geodetic.h"
#include "nav_sensors/noise.h"

namespace convoy::nav_sensors {

struct NavSatParams {
  NoiseParams position_horizontal, position_vertical;  // m
  NoiseParams velocity_horizontal, velocity_vertical;  // m/s
  double update_rate = 0;                              // Hz; 0: every engine step
};

struct NavSatReading {
  Geodetic position;
  Eigen::Vector3d velocity_enu = Eigen::Vector3d::Zero();  // east, north, up (m/s)
};

class NavSatModel {
 public:
  // Throws std::invalid_argument naming the channel ("position_sensing horizontal: ...").
  NavSatModel(const NavSatParams& params, const GeoFrame& frame, uint64_t seed);

  // The reading at world-frame `position` and `velocity`, `dt` s after the previous one.
  NavSatReading measure(const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                        double dt);
  void reset();

 private:
  NavSatParams p_;
  GeoFrame frame_;
  std::array<NoiseChannel, 3> position_, velocity_;  // east, north, up
};

}  // namespace convoy::nav_sensors
