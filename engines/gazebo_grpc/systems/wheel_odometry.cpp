#include "systems/wheel_odometry.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "convoy/radar.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "nav_sensors/noise.h"
#include "physics_world.h"

namespace convoy::world {

namespace {

std::string where(const WorldContext& ctx, const OdometryDesc& d) {
  return "engine '" + ctx.engine + "': model '" + d.model + "' link '" + d.link + "' sensor '" +
         d.name + "': ";
}

int joint(const WorldContext& ctx, const OdometryDesc& d, const std::string& name,
          const char* element) {
  const int j = ctx.physics->joint_index(d.model + "::" + name);
  if (j < 0)
    throw std::runtime_error(where(ctx, d) + "<" + element + ">: model '" + d.model +
                             "' has no joint '" + name + "'");
  return j;
}

}  // namespace

void WheelOdometry::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  const double step_s = config.value("EngineTimestep", 0.01);
  const uint64_t seed = config.value("GazeboRNGSeed", uint64_t{0});
  for (size_t m = 0; m < ctx.desc->models.size(); ++m)
    for (const auto& link : ctx.desc->models[m].links)
      for (const auto& d : link.odometers) {
        if (step_s > 0 && d.odometry.update_rate > 1.0 / step_s * (1 + 1e-9)) {
          std::ostringstream s;
          s << where(ctx, d) << "<update_rate>: " << d.odometry.update_rate
            << " Hz is above the engine's step rate (1 / EngineTimestep = " << 1.0 / step_s
            << " Hz)";
          throw std::runtime_error(s.str());
        }
        Sensor s;
        s.desc = &d;
        s.left = joint(ctx, d, d.left_joint, "left_joint");
        s.right = joint(ctx, d, d.right_joint, "right_joint");
        if (!d.steering_joint.empty())
          s.steering = joint(ctx, d, d.steering_joint, "steering_joint");
        try {
          s.model.emplace(d.odometry,
                          nav_sensors::random_bits(seed, 0x4f444f /* "ODO" */, sensors_.size()));
        } catch (const std::invalid_argument& e) {
          throw std::runtime_error(where(ctx, d) + e.what());
        }
        std::vector<std::string> names{d.scoped_name};
        if (!d.plugin_name.empty()) names.push_back(d.plugin_name + "::" + d.name);
        for (const auto& n : names) {
          by_datapack_[n] = sensors_.size();
          provided_.push_back({n, datapack::type_name<data::Odometry>(), static_cast<int>(m)});
        }
        sensors_.push_back(std::move(s));
      }
}

void WheelOdometry::post_update(double dt) {
  for (auto& s : sensors_) {
    const double steer = s.steering >= 0 ? ctx_->physics->joint_state(s.steering).position : 0;
    s.model->update(ctx_->physics->joint_state(s.left).velocity,
                    ctx_->physics->joint_state(s.right).velocity, steer, dt);
  }
}

void WheelOdometry::read(Sensor& s) {
  s.reading = s.model->state();
  s.time = ctx_->time_s();
  ++s.readings;
  const double rate = s.desc->odometry.update_rate, period = rate > 0 ? 1.0 / rate : 0;
  s.next_update = period > 0 ? std::max(s.next_update + period, s.time) : s.time;
  if (period > 0 && s.next_update <= s.time) s.next_update = s.time + period;
}

void WheelOdometry::after_step() {
  const double t = ctx_->time_s(), half_step = 0.5 * ctx_->physics->step_size();
  for (auto& s : sensors_)
    if (s.readings == 0 || t + half_step >= s.next_update) read(s);
}

void WheelOdometry::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  Sensor& s = sensors_[it->second];
  if (s.readings == 0) read(s);
  data::Odometry m;
  m.set_time_ns(std::llround(s.time * 1e9));
  m.set_frame(s.desc->scoped_name);
  const auto& r = s.reading;
  m.set_x(r.x);
  m.set_y(r.y);
  m.set_yaw(r.yaw);
  m.set_speed(r.speed);
  m.set_yaw_rate(r.yaw_rate);
  m.set_steering(r.steering);
  m.set_distance(r.distance);
  datapack::write_proto(out, m);
  sent_[name] = s.readings;
}

bool WheelOdometry::unchanged(const std::string& name) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return false;
  auto sent = sent_.find(name);
  return sent != sent_.end() && sent->second == sensors_[it->second].readings;
}

void WheelOdometry::reset() {
  sent_.clear();
  for (auto& s : sensors_) {
    s.model->reset();
    s.reading = {};
    s.time = s.next_update = 0;
    s.readings = 0;
  }
}

}  // namespace convoy::world
