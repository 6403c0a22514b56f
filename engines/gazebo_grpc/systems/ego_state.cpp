#include "systems/ego_state.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {

void EgoState::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  const auto& models = ctx.desc->models;
  std::vector<std::string> names;
  if (config.contains("EgoModels")) {
    names = config["EgoModels"].get<std::vector<std::string>>();
  } else {
    for (const auto& model : models)
      if (!model.is_static && !model.joint_plugins.empty()) names.push_back(model.name);
  }
  for (const auto& name : names) {
    auto it =
        std::find_if(models.begin(), models.end(), [&](const auto& m) { return m.name == name; });
    if (it == models.end() || it->links.empty())
      throw std::runtime_error("EgoModels: no model '" + name + "' with a link in the world");
    egos_.push_back(make_ego(*it));
  }
}

std::vector<ProvidedDataPack> EgoState::provides() const {
  std::vector<ProvidedDataPack> out;
  for (const auto& e : egos_) out.push_back({e.datapack, datapack::type_name<data::RoadUser>()});
  return out;
}

void EgoState::get_datapack(const std::string& name, datapack::Builder& out) {
  for (auto& e : egos_) {
    if (name == e.datapack) {
      datapack::write_proto(out, state(e));
      return;
    }
  }
}

data::RoadUser EgoState::state(const std::string& model) {
  for (auto& e : egos_)
    if (e.name == model) return state(e);
  throw std::out_of_range("no ego model '" + model + "'");
}

void EgoState::reset() {
  for (auto& e : egos_) {
    e.speed = 0;
    e.speed_ns = -1;
  }
}

EgoState::Ego EgoState::make_ego(const ModelDesc& m) const {
  Ego e;
  e.name = m.name;
  e.cls = class_of(m);
  e.datapack = m.name + "::road_user";
  e.link = ctx_->physics->link_index(m.links.front().name);
  // The box of its collision shapes, in the reference link's frame as loaded.
  const Eigen::Isometry3d ref_inv = m.links.front().pose.inverse();
  Eigen::AlignedBox3d box;
  for (const auto& l : m.links) {
    for (const auto& c : l.collisions) {
      Eigen::Vector3d h = 0.5 * c.shape.size;
      if (c.shape.kind == Shape::kCylinder)
        h = {c.shape.size.x(), c.shape.size.x(), 0.5 * c.shape.size.z()};
      if (c.shape.kind == Shape::kPlane || c.shape.kind == Shape::kMesh ||
          c.shape.kind == Shape::kHeightmap) {
        continue;
      }
      const Eigen::Isometry3d t = ref_inv * l.pose * c.pose;
      for (int k = 0; k < 8; ++k)
        box.extend(t * Eigen::Vector3d((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                                       (k & 4) ? h.z() : -h.z()));
    }
  }
  if (!box.isEmpty()) {
    e.length = box.sizes().x();
    e.width = box.sizes().y();
    e.height = box.sizes().z();
    e.length_offset = box.center().x();
  }
  return e;
}

data::RoadUser EgoState::state(Ego& e) {
  const int64_t now = ctx_->time_ns;
  data::RoadUser u;
  auto s = ctx_->physics->link_state(e.link);
  const Eigen::Matrix3d r = s.rotation.toRotationMatrix();
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  u.set_id(e.name);
  u.set_category(e.cls);
  u.set_model(e.name);
  u.set_x(s.position.x());
  u.set_y(s.position.y());
  u.set_z(s.position.z());
  u.set_yaw(yaw);
  u.set_pitch(pitch);
  u.set_roll(roll);
  const double speed = s.linear_velocity.dot(r.col(0));
  u.set_speed(speed);
  if (e.speed_ns >= 0 && now > e.speed_ns)
    u.set_acceleration((speed - e.speed) / (static_cast<double>(now - e.speed_ns) * 1e-9));
  if (now != e.speed_ns) {
    e.speed = speed;
    e.speed_ns = now;
  }
  u.set_yaw_rate(s.angular_velocity.z());
  u.set_vx(s.linear_velocity.x());
  u.set_vy(s.linear_velocity.y());
  u.set_length(e.length);
  u.set_width(e.width);
  u.set_height(e.height);
  u.set_length_offset(e.length_offset);
  u.set_time_ns(now);
  return u;
}

}  // namespace convoy::world
