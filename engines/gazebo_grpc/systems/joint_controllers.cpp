#include "systems/joint_controllers.h"

#include <limits>

#include "convoy/datapacks.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"
#include "systems/brakes.h"
#include "world_description.h"

namespace convoy::world {

void JointControllers::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  brakes_ = ctx.find<Brakes>();
  for (size_t m = 0; m < ctx.desc->models.size(); ++m) {
    const ModelDesc& model = ctx.desc->models[m];
    for (const auto& [plugin, pids] : model.joint_plugins) {
      for (const auto& pid : pids) {
        int index = ctx.physics->joint_index(pid.joint);
        if (index < 0)
          throw std::runtime_error("joint '" + pid.joint + "' has no degree of freedom");
        controllers_.push_back({index, pid.velocity, pid.target,
                                JointPid(pid.p, pid.i, pid.d, pid.i_max, pid.i_min), 0,
                                pid.target});
        std::string short_name = pid.joint.substr(model.name.size() + 2);
        for (const std::string& n : {plugin + "::" + short_name, pid.joint}) {
          by_datapack_[n] = controllers_.size() - 1;
          provided_.push_back({n, datapack::type_name<data::Joint>(), static_cast<int>(m)});
        }
      }
    }
  }
}

bool JointControllers::set_datapack(const datapack::View& dp) {
  auto it = by_datapack_.find(dp.id().name());
  if (it == by_datapack_.end()) return false;
  if (dp.proto_type() != datapack::type_name<data::Joint>())
    throw std::runtime_error("datapack '" + dp.id().name() + "' must be a GazeboJointDataPack");
  const auto j = datapack::read_proto<data::Joint>(dp);
  auto& c = controllers_[it->second];
  c.target = c.velocity ? j.velocity() : j.position();
  c.feed_forward = j.effort();
  return true;
}

void JointControllers::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  auto s = ctx_->physics->joint_state(controllers_[it->second].joint);
  data::Joint j;
  j.set_position(static_cast<float>(s.position));
  j.set_velocity(static_cast<float>(s.velocity));
  j.set_effort(static_cast<float>(s.effort));
  datapack::write_proto(out, j);
}

void JointControllers::update(double dt) {
  PhysicsWorld& physics = *ctx_->physics;
  for (auto& c : controllers_) {
    if (brakes_ && brakes_->braking(c.joint)) {
      physics.set_joint_effort(c.joint, 0.0);
      c.pid.reset();
      continue;
    }
    auto s = physics.joint_state(c.joint);
    double error = (c.velocity ? s.velocity : s.position) - c.target;
    physics.set_joint_effort(c.joint, c.pid.update(error, dt) + c.feed_forward);
  }
}

// The initial targets again, no feed-forward, the PIDs from rest.
void JointControllers::reset() {
  for (auto& c : controllers_) {
    c.target = c.initial_target;
    c.feed_forward = 0;
    c.pid.reset();
  }
}

void JointControllers::hold_velocity(int joint, double velocity) {
  for (auto& c : controllers_)
    if (c.joint == joint && c.velocity) c.target = c.initial_target = velocity;
}

double JointControllers::target(const std::string& name) const {
  auto it = by_datapack_.find(name);
  return it == by_datapack_.end() ? std::numeric_limits<double>::quiet_NaN()
                                  : controllers_[it->second].target;
}

}  // namespace convoy::world
