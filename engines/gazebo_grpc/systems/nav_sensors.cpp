#include "systems/nav_sensors.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "convoy/nav_sensors.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"

namespace convoy::world {

namespace {

std::string sensor_where(const NavSensorDesc& d) {
  return "model '" + d.model + "' link '" + d.link + "' sensor '" + d.name + "': ";
}

double update_rate(const NavSensorDesc& d) {
  return d.kind == NavSensorDesc::kImu ? d.imu.update_rate : d.navsat.update_rate;
}

void check_rate(const WorldContext& ctx, const NavSensorDesc& d, double step_s) {
  if (step_s <= 0 || update_rate(d) <= 1.0 / step_s * (1 + 1e-9)) return;
  std::ostringstream s;
  s << "engine '" << ctx.engine << "': " << sensor_where(d) << "<update_rate>: " << update_rate(d)
    << " Hz is above the engine's step rate (1 / EngineTimestep = " << 1.0 / step_s << " Hz)";
  throw std::runtime_error(s.str());
}

template <typename V>
void put(google::protobuf::RepeatedField<double>* f, const V& v) {
  for (int i = 0; i < v.size(); ++i) f->Add(v[i]);
}

}  // namespace

void NavSensors::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  const double step_s = config.value("EngineTimestep", 0.01);
  const uint64_t seed = config.value("GazeboRNGSeed", uint64_t{0});
  const nav_sensors::GeoFrame frame(ctx.desc->geo);
  for (size_t m = 0; m < ctx.desc->models.size(); ++m)
    for (const auto& link : ctx.desc->models[m].links)
      for (const auto& d : link.nav_sensors) {
        check_rate(ctx, d, step_s);
        Sensor s;
        s.desc = &d;
        s.link = ctx.physics->link_index(link.name);
        s.link_pose = link.pose;
        const uint64_t k = nav_sensors::random_bits(seed, 0x4e4156 /* "NAV" */, sensors_.size());
        try {
          if (d.kind == NavSensorDesc::kImu)
            s.imu.emplace(d.imu, ctx.desc->gravity, k);
          else
            s.navsat.emplace(d.navsat, frame, k);
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error("engine '" + ctx.engine + "': " + sensor_where(d) + e.what());
        }
        const std::string type = d.kind == NavSensorDesc::kImu
                                     ? datapack::type_name<data::Imu>()
                                     : datapack::type_name<data::NavSat>();
        std::vector<std::string> names{d.scoped_name};
        if (!d.plugin_name.empty()) names.push_back(d.plugin_name + "::" + d.name);
        for (const auto& n : names) {
          by_datapack_[n] = sensors_.size();
          provided_.push_back({n, type, static_cast<int>(m)});
        }
        sensors_.push_back(std::move(s));
      }
}

void NavSensors::sample(Sensor& s, double dt) {
  Eigen::Isometry3d link = s.link_pose;
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();
  if (s.link >= 0) {
    const LinkState st = ctx_->physics->link_state(s.link);
    link = ctx_->physics->link_pose(s.link);
    v = st.linear_velocity;
    w = st.angular_velocity;
  }
  const Eigen::Isometry3d pose = link * s.desc->pose;
  const Eigen::Vector3d offset = pose.translation() - link.translation();
  s.position = pose.translation();
  s.velocity = v + w.cross(offset);  // the sensor frame's origin
  s.motion.rotation = Eigen::Quaterniond(pose.linear());
  s.motion.angular_velocity = w;
  s.motion.linear_acceleration = s.accel.update(s.velocity, dt);
}

void NavSensors::post_update(double dt) {
  for (auto& s : sensors_) sample(s, dt);
}

void NavSensors::read(Sensor& s) {
  const double t = ctx_->time_s();
  const double dt = s.readings > 0 ? t - s.last_read : 0.0;
  if (s.imu)
    s.imu_reading = s.imu->measure(s.motion, dt);
  else
    s.navsat_reading = s.navsat->measure(s.position, s.velocity, dt);
  s.last_read = t;
  ++s.readings;
  const double rate = update_rate(*s.desc), period = rate > 0 ? 1.0 / rate : 0;
  s.next_update = period > 0 ? std::max(s.next_update + period, t) : t;
  if (period > 0 && s.next_update <= t) s.next_update = t + period;
}

void NavSensors::after_step() {
  const double t = ctx_->time_s(), half_step = 0.5 * ctx_->physics->step_size();
  for (auto& s : sensors_)  // due from half a physics step early, as the cameras
    if (s.readings == 0 || t + half_step >= s.next_update) read(s);
}

void NavSensors::fill(const Sensor& s, datapack::Builder& out) const {
  const int64_t time_ns = std::llround(s.last_read * 1e9);
  if (s.imu) {
    data::Imu m;
    m.set_time_ns(time_ns);
    m.set_frame(s.desc->scoped_name);
    const auto& r = s.imu_reading;
    if (r.has_orientation) put(m.mutable_orientation(), r.orientation.coeffs());  // x y z w
    put(m.mutable_angular_velocity(), r.angular_velocity);
    put(m.mutable_linear_acceleration(), r.linear_acceleration);
    datapack::write_proto(out, m);
    return;
  }
  data::NavSat m;
  m.set_time_ns(time_ns);
  m.set_frame(s.desc->scoped_name);
  const auto& r = s.navsat_reading;
  m.set_latitude_deg(r.position.latitude_deg);
  m.set_longitude_deg(r.position.longitude_deg);
  m.set_altitude(r.position.altitude_m);
  m.set_velocity_east(r.velocity_enu.x());
  m.set_velocity_north(r.velocity_enu.y());
  m.set_velocity_up(r.velocity_enu.z());
  datapack::write_proto(out, m);
}

void NavSensors::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  Sensor& s = sensors_[it->second];
  if (s.readings == 0) {  // asked before the first step: read the pose at rest
    sample(s, 0);
    read(s);
  }
  fill(s, out);
  sent_[name] = s.readings;
}

bool NavSensors::unchanged(const std::string& name) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return false;
  auto sent = sent_.find(name);
  return sent != sent_.end() && sent->second == sensors_[it->second].readings;
}

void NavSensors::reset() {
  sent_.clear();
  for (auto& s : sensors_) {
    if (s.imu) s.imu->reset();
    if (s.navsat) s.navsat->reset();
    s.accel.reset();
    s.motion = {};
    s.next_update = s.last_read = 0;
    s.readings = 0;
  }
}

}  // namespace convoy::world
