#include "sumo_persons.h"

#include <libsumo/libsumo.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

namespace convoy::engines::sumo {

namespace {

void mark_absent(data::RoadUser& u, int64_t time_ns) {
  u.set_absent(true);
  u.set_speed(0);
  u.set_acceleration(0);
  u.set_vx(0);
  u.set_vy(0);
  u.set_yaw_rate(0);
  u.set_time_ns(time_ns);
}

}  // namespace

const PersonReader::Size& PersonReader::size_of(const std::string& type) {
  auto it = sizes_.find(type);
  if (it != sizes_.end()) return it->second;
  Size s{libsumo::VehicleType::getLength(type), libsumo::VehicleType::getWidth(type),
         libsumo::VehicleType::getHeight(type)};
  return sizes_.emplace(type, s).first->second;
}

void PersonReader::read(int64_t time_ns, double dt, data::RoadUsers& out) {
  std::vector<std::string> ids;
  for (auto& id : libsumo::Person::getIDList())  // walking ones: a rider moves with its vehicle
    if (libsumo::Person::getVehicle(id).empty()) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  out.Clear();
  out.set_time_ns(time_ns);
  for (auto it = tracked_.begin(); it != tracked_.end();) {
    if (std::binary_search(ids.begin(), ids.end(), it->first)) {
      ++it;
      continue;
    }
    data::RoadUser* u = out.add_users();
    *u = std::move(it->second.last);
    mark_absent(*u, time_ns);
    it = tracked_.erase(it);
  }
  for (const auto& id : ids) {
    auto [it, fresh] = tracked_.try_emplace(id);
    Tracked& tr = it->second;
    data::RoadUser& u = tr.last;
    if (fresh) {
      const std::string type = libsumo::Person::getTypeID(id);
      const Size& s = size_of(type);
      u.set_id(prefix_ + id);
      u.set_category("pedestrian");
      u.set_model(type);
      u.set_length(s.length);
      u.set_width(s.width);
      u.set_height(s.height);
    }
    const libsumo::TraCIPosition p = libsumo::Person::getPosition3D(id);
    const double yaw = yaw_from_sumo_angle(libsumo::Person::getAngle(id));
    const double speed = libsumo::Person::getSpeed(id);
    u.set_x(p.x - offset_.x);
    u.set_y(p.y - offset_.y);
    u.set_z(p.z);
    u.set_yaw_rate(fresh || dt <= 0 ? 0.0 : std::remainder(yaw - tr.yaw, 2 * M_PI) / dt);
    tr.yaw = yaw;
    u.set_yaw(yaw);
    u.set_acceleration(fresh || dt <= 0 ? 0.0 : (speed - u.speed()) / dt);
    u.set_speed(speed);
    u.set_vx(speed * std::cos(yaw));
    u.set_vy(speed * std::sin(yaw));
    u.set_time_ns(time_ns);
    *out.add_users() = u;
  }
}

}  // namespace convoy::engines::sumo
