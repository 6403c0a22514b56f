#include "nav_sensors/navsat_model.h"

#include <stdexcept>
#include <string>

namespace convoy::nav_sensors {

namespace {

NoiseChannel channel(const NoiseParams& p, uint64_t seed, uint64_t stream, const char* what) {
  try {
    return NoiseChannel(p, seed, stream);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(what) + ": " + e.what());
  }
}

}  // namespace

NavSatModel::NavSatModel(const NavSatParams& params, const GeoFrame& frame, uint64_t seed)
    : p_(params), frame_(frame) {
  if (!(p_.update_rate >= 0)) throw std::invalid_argument("update_rate: negative");
  const char* ph = "position_sensing horizontal";
  const char* vh = "velocity_sensing horizontal";
  position_ = {channel(p_.position_horizontal, seed, 0, ph),
               channel(p_.position_horizontal, seed, 1, ph),
               channel(p_.position_vertical, seed, 2, "position_sensing vertical")};
  velocity_ = {channel(p_.velocity_horizontal, seed, 3, vh),
               channel(p_.velocity_horizontal, seed, 4, vh),
               channel(p_.velocity_vertical, seed, 5, "velocity_sensing vertical")};
}

void NavSatModel::reset() {
  for (auto& c : position_) c.reset();
  for (auto& c : velocity_) c.reset();
}

NavSatReading NavSatModel::measure(const Eigen::Vector3d& position, const Eigen::Vector3d& velocity,
                                   double dt) {
  Eigen::Vector3d enu = frame_.to_enu(position);
  Eigen::Vector3d v = frame_.to_enu(velocity);
  for (int i = 0; i < 3; ++i) {
    enu[i] = position_[i].apply(enu[i], dt);
    v[i] = velocity_[i].apply(v[i], dt);
  }
  NavSatReading r;
  r.position = frame_.to_geodetic(frame_.from_enu(enu));
  r.velocity_enu = v;
  return r;
}

}  // namespace convoy::nav_sensors
