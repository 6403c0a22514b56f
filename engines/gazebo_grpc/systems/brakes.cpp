#include "systems/brakes.h"

#include <algorithm>
#include <cmath>

#include "convoy/datapacks.pb.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {

void Brakes::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  for (size_t m = 0; m < ctx.desc->models.size(); ++m) {
    const ModelDesc& model = ctx.desc->models[m];
    for (const auto& bp : model.brake_plugins) {
      for (const auto& b : bp.brakes) {
        Brake brake;
        brake.joint = ctx.physics->joint_index(b.joint);
        if (brake.joint < 0)
          throw std::runtime_error("brake plugin '" + bp.name + "': joint '" + b.joint +
                                   "' has no degree of freedom");
        brake.max_torque = b.max_torque;
        brake.abs = bp.abs;
        brake.slip = bp.slip;
        brakes_.push_back(brake);
        const std::string n = bp.name + "::" + b.joint.substr(model.name.size() + 2);
        by_datapack_[n] = brakes_.size() - 1;
        provided_.push_back({n, datapack::type_name<data::Joint>(), static_cast<int>(m)});
      }
    }
  }
}

bool Brakes::set_datapack(const datapack::View& dp) {
  auto it = by_datapack_.find(dp.id().name());
  if (it == by_datapack_.end()) return false;
  if (dp.empty()) return true;
  if (dp.proto_type() != datapack::type_name<data::Joint>())
    throw std::runtime_error("datapack '" + dp.id().name() + "' must be a GazeboJointDataPack");
  const double torque = datapack::read_proto<data::Joint>(dp).effort();
  Brake& brake = brakes_[it->second];
  if (!(torque >= 0))
    throw std::runtime_error(ctx_->where(dp.id().name()) +
                             "the brake torque (effort) must be >= 0 Nm, got " +
                             std::to_string(torque));
  brake.command = std::min(torque, brake.max_torque);
  return true;
}

// A joint's state; the effort is the torque the ABS applies.
void Brakes::get_datapack(const std::string& name, datapack::Builder& out) {
  auto it = by_datapack_.find(name);
  if (it == by_datapack_.end()) return;
  const Brake& b = brakes_[it->second];
  auto s = ctx_->physics->joint_state(b.joint);
  data::Joint j;
  j.set_position(static_cast<float>(s.position));
  j.set_velocity(static_cast<float>(s.velocity));
  j.set_effort(static_cast<float>(b.applied));
  datapack::write_proto(out, j);
}

bool Brakes::braking(int joint) const {
  for (const auto& b : brakes_)
    if (b.joint == joint && b.command > 0) return true;
  return false;
}

double Brakes::applied(const std::string& name) const {
  auto it = by_datapack_.find(name);
  return it == by_datapack_.end() ? -1.0 : brakes_[it->second].applied;
}

void Brakes::pre_update(double dt) {
  for (auto& b : brakes_) update_brake(b, dt);
}

// The gains place the slip loop's poles at 30 rad/s (damping 0.7) at 10 m/s, from the
// wheel's inertia I and radius r: slip' = r / (v I) (brake torque - road torque). The brake
// starts at the full command; near the target the tyre slides at its full grip (Coulomb
// friction), and the wheel never locks. While a wheel over the target spins up again, the
// integral holds (as an ABS holds its pressure once the wheel accelerates).
void Brakes::update_brake(Brake& b, double dt) {
  PhysicsWorld& physics = *ctx_->physics;
  const double command_before = b.last_command;
  b.last_command = b.command;
  if (b.command <= 0) {
    b.applied = 0;
    physics.set_joint_brake(b.joint, 0.0);
    return;
  }
  const auto* wheel = physics.joint_child(b.joint);
  const Eigen::Vector3d axis = physics.joint_axis_world(b.joint);
  Eigen::Vector3d rolling = axis.cross(Eigen::Vector3d::UnitZ());
  const double n = rolling.norm();
  const double radius = wheel_radius(b);
  double v = 0, w = 0;
  if (n > 1e-6 && radius > 0) {
    rolling /= n;
    v = wheel->getLinearVelocity().dot(rolling);  // ground speed along the wheel's path
    w = wheel->getAngularVelocity().dot(axis);
    if (v < 0) {  // forward is where it travels
      v = -v;
      w = -w;
    }
  }
  const double slip = v > 1e-3 ? (v - w * radius) / v : 0.0;
  if (command_before <= 0) b.integral = b.command;  // brakes just pressed
  if (!b.abs || v < 2.0 || radius <= 0) {
    b.applied = b.command;
  } else {
    const double inertia = std::max(axis.dot(wheel->getInertia().getMoment() * axis), 1e-3);
    const double wn = 30.0, zeta = 0.7, v_ref = 10.0;
    const double ki = wn * wn * v_ref * inertia / radius;
    const double kp = 2 * zeta * wn * v_ref * inertia / radius;
    const double e = slip - b.slip;
    // Over the target but the wheel already spinning up: the torque is under the grip
    // already, and lowering it further would only lose braking.
    const bool recovering = e > 0 && w > b.last_omega;
    if (!recovering) b.integral = std::clamp(b.integral - ki * e * dt, 0.0, b.command);
    b.applied = std::clamp(b.integral - kp * e, 0.0, b.command);
  }
  b.last_omega = w;
  physics.set_joint_brake(b.joint, b.applied);
}

// A braked wheel's radius: its collision cylinder's or sphere's (0: none).
double Brakes::wheel_radius(Brake& b) {
  if (b.radius >= 0) return b.radius;
  b.radius = 0;
  const auto* body = ctx_->physics->joint_child(b.joint);
  for (const auto* node : body->getShapeNodesWith<dart::dynamics::CollisionAspect>()) {
    const auto* shape = node->getShape().get();
    if (auto* c = dynamic_cast<const dart::dynamics::CylinderShape*>(shape))
      b.radius = std::max(b.radius, c->getRadius());
    else if (auto* sp = dynamic_cast<const dart::dynamics::SphereShape*>(shape))
      b.radius = std::max(b.radius, sp->getRadius());
  }
  return b.radius;
}

// The commands are released; the ABS's integral and the wheels' radii are kept (the
// integral starts again from the command when a brake is pressed).
void Brakes::reset() {
  for (auto& b : brakes_) b.command = b.applied = b.last_command = b.last_omega = 0;
}

}  // namespace convoy::world
