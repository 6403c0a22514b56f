#include "wheel_odometry/odometry_model.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "nav_sensors/noise.h"

namespace convoy::wheel_odometry {

namespace {

constexpr uint64_t kStream = 0x4f444f;  // "ODO"

void need(bool ok, const char* field, const char* what, double got) {
  if (!ok)
    throw std::invalid_argument(std::string(field) + ": " + what + ", got " + std::to_string(got));
}

}  // namespace

void OdometryParams::validate() const {
  need(wheel_radius > 0 && std::isfinite(wheel_radius), "wheel_radius", "must be > 0 m",
       wheel_radius);
  need(track > 0 && std::isfinite(track), "track", "must be > 0 m", track);
  need(wheelbase >= 0 && std::isfinite(wheelbase), "wheelbase", "must be >= 0 m", wheelbase);
  need(scale_stddev >= 0 && scale_stddev < 0.5, "scale_stddev", "must be in [0, 0.5)",
       scale_stddev);
  need(slip_stddev >= 0 && std::isfinite(slip_stddev), "slip_stddev", "must be >= 0 m/s",
       slip_stddev);
  need(update_rate >= 0 && std::isfinite(update_rate), "update_rate", "must be >= 0 Hz",
       update_rate);
}

OdometryModel::OdometryModel(const OdometryParams& params, uint64_t seed)
    : p_(params), seed_(seed) {
  p_.validate();
  reset();
}

void OdometryModel::reset() {
  for (int w = 0; w < 2; ++w)
    scale_[w] = 1 + p_.scale_stddev * nav_sensors::standard_normal(seed_, kStream + w, 0);
  samples_ = 0;
  state_ = {};
}

const OdometryState& OdometryModel::update(double left, double right, double steering, double dt) {
  ++samples_;
  double v[2] = {left * p_.wheel_radius * scale_[0], right * p_.wheel_radius * scale_[1]};
  if (p_.slip_stddev > 0)
    for (int w = 0; w < 2; ++w)
      v[w] += p_.slip_stddev * nav_sensors::standard_normal(seed_, kStream + w, samples_);
  OdometryState& s = state_;
  s.speed = 0.5 * (v[0] + v[1]);
  s.steering = steering;
  s.yaw_rate =
      p_.wheelbase > 0 ? s.speed * std::tan(steering) / p_.wheelbase : (v[1] - v[0]) / p_.track;
  if (dt > 0) {
    const double mid = s.yaw + 0.5 * s.yaw_rate * dt;
    s.x += s.speed * dt * std::cos(mid);
    s.y += s.speed * dt * std::sin(mid);
    s.yaw = std::remainder(s.yaw + s.yaw_rate * dt, 2 * M_PI);
    s.distance += std::abs(s.speed) * dt;
  }
  return s;
}

}  // namespace convoy::wheel_odometry
