#include "nav_sensors/imu_model.h"

#include <stdexcept>
#include <string>

namespace convoy::nav_sensors {

namespace {

constexpr const char* kAxis[3] = {"x", "y", "z"};

NoiseChannel channel(const NoiseParams& p, uint64_t seed, uint64_t stream, const char* what,
                     int axis) {
  try {
    return NoiseChannel(p, seed, stream);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(what) + " " + kAxis[axis] + ": " + e.what());
  }
}

}  // namespace

ImuModel::ImuModel(const ImuParams& params, const Eigen::Vector3d& gravity, uint64_t seed)
    : p_(params), gravity_(gravity) {
  if (!(p_.update_rate >= 0)) throw std::invalid_argument("update_rate: negative");
  for (int i = 0; i < 3; ++i) {
    gyro_[i] = channel(p_.angular_velocity[i], seed, i, "angular_velocity", i);
    accel_[i] = channel(p_.linear_acceleration[i], seed, 3 + i, "linear_acceleration", i);
  }
}

void ImuModel::reset() {
  for (auto& c : gyro_) c.reset();
  for (auto& c : accel_) c.reset();
}

ImuReading ImuModel::measure(const ImuSample& s, double dt) {
  ImuReading r;
  const Eigen::Matrix3d to_sensor = s.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d w = to_sensor * s.angular_velocity;
  const Eigen::Vector3d f = to_sensor * (s.linear_acceleration - gravity_);
  for (int i = 0; i < 3; ++i) {
    r.angular_velocity[i] = gyro_[i].apply(w[i], dt);
    r.linear_acceleration[i] = accel_[i].apply(f[i], dt);
  }
  r.has_orientation = p_.orientation;
  if (p_.orientation) r.orientation = s.rotation.normalized();
  return r;
}

Eigen::Vector3d VelocityDifferentiator::update(const Eigen::Vector3d& velocity, double dt) {
  if (primed_ && dt > 0) acceleration_ = (velocity - last_) / dt;
  last_ = velocity;
  primed_ = true;
  return acceleration_;
}

}  // namespace convoy::nav_sensors
