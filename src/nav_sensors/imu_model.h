// An IMU as SDF's <imu> describes it (and Gazebo's IMU sensor reads): the sensor frame's
// angular velocity and specific force (linear acceleration minus gravity, so a level IMU at
// rest reads +g upwards) in its own axes, each axis through its <noise>, and its orientation
// relative to the world frame (ENU: x east, y north, z up, as Gazebo's default
// <localization>), unless <enable_orientation> is false.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cstdint>

#include "nav_sensors/noise.h"

namespace convoy::nav_sensors {

struct ImuParams {
  std::array<NoiseParams, 3> angular_velocity{};     // x, y, z (rad/s)
  std::array<NoiseParams, 3> linear_acceleration{};  // x, y, z (m/s^2)
  bool orientation = true;
  double update_rate = 0;  // Hz; 0: every engine step
};

// The sensor frame's motion, in the world frame.
struct ImuSample {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();   // sensor -> world
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // rad/s
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // m/s^2, of the frame's origin
};

struct ImuReading {
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // sensor -> world
  bool has_orientation = true;
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     // sensor axes, rad/s
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  // sensor axes, m/s^2
};

class ImuModel {
 public:
  // Throws std::invalid_argument naming the channel ("angular_velocity x: stddev: ...").
  ImuModel(const ImuParams& params, const Eigen::Vector3d& gravity, uint64_t seed);

  // The reading of `s`, `dt` seconds after the previous one.
  ImuReading measure(const ImuSample& s, double dt);
  void reset();

  const ImuParams& params() const { return p_; }

 private:
  ImuParams p_;
  Eigen::Vector3d gravity_;
  std::array<NoiseChannel, 3> gyro_, accel_;
};

// The acceleration of a point from its velocity sampled every physics step (a backward
// difference; zero for the first sample).
class VelocityDifferentiator {
 public:
  Eigen::Vector3d update(const Eigen::Vector3d& velocity, double dt);
  void reset() {
    primed_ = false;
    acceleration_ = Eigen::Vector3d::Zero();
  }

 private:
  Eigen::Vector3d last_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d acceleration_ = Eigen::Vector3d::Zero();
  bool primed_ = false;
};

}  // namespace convoy::nav_sensors
