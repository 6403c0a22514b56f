#include "systems/initial_speeds.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "model_inserts.h"
#include "physics_world.h"
#include "systems/joint_controllers.h"

namespace convoy::world {
namespace {

// cos 8 degrees: a cylinder this close to the joint's axis is a tyre turning about it.
constexpr double kParallel = 0.99;

const LinkDesc* link_named(const ModelDesc& model, const std::string& name) {
  for (const auto& l : model.links)
    if (l.name == name) return &l;
  return nullptr;
}

bool is_locked(const JointDesc& j) { return !j.axes.empty() && j.axes[0].lower == j.axes[0].upper; }

// The radius of the largest collision sphere of `link`, or cylinder about `axis` (world); 0 if
// none.
double rolling_radius(const LinkDesc& link, const Eigen::Vector3d& axis) {
  double radius = 0;
  for (const auto& c : link.collisions) {
    const bool sphere = c.shape.kind == Shape::kSphere;
    const bool about_axis = c.shape.kind == Shape::kCylinder &&
                            std::abs((link.pose * c.pose).linear().col(2).dot(axis)) >= kParallel;
    if (sphere || about_axis) radius = std::max(radius, c.shape.size.x());
  }
  return radius;
}

}  // namespace

std::vector<WheelDesc> find_wheels(const ModelDesc& model) {
  std::vector<WheelDesc> out;
  for (const auto& j : model.joints) {
    if (j.type != JointDesc::kRevolute && j.type != JointDesc::kContinuous) continue;
    if (j.axes.empty() || (j.type == JointDesc::kRevolute && is_locked(j))) continue;
    const LinkDesc* child = link_named(model, j.child);
    if (!child) continue;
    const Eigen::Vector3d axis = (j.pose.linear() * j.axes[0].xyz).normalized();
    const double radius = rolling_radius(*child, axis);
    if (radius > 0) out.push_back({j.name, axis, radius});
  }
  return out;
}

void InitialSpeeds::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  auto* controllers = ctx.find<JointControllers>();
  const auto inserts = read_model_inserts(config);
  for (size_t i = 0; i < inserts.size(); ++i) {
    const ModelInsert& insert = inserts[i];
    if (insert.init_speed == 0) continue;
    const auto models = models_of(*ctx.desc, insert);
    if (models.empty())
      throw std::runtime_error("GazeboSDFModels/" + std::to_string(i) +
                               "/InitSpeed: no model of this entry in the world");
    const Eigen::Vector3d heading = insert.pose.linear().col(0);
    const Eigen::Vector3d up = insert.pose.linear().col(2);
    for (const ModelDesc* m : models) {
      if (m->is_static) continue;
      models_.push_back({m->name, insert.init_speed * heading});
      for (const WheelDesc& w : find_wheels(*m)) {
        const int joint = ctx.physics->joint_index(w.joint);
        if (joint < 0) continue;
        const double omega = up.cross(heading).dot(w.axis) * insert.init_speed / w.radius;
        spins_.push_back({joint, omega});
        if (controllers) controllers->hold_velocity(joint, omega);
      }
    }
  }
  apply();
}

void InitialSpeeds::apply() const {
  PhysicsWorld& physics = *ctx_->physics;
  for (const auto& m : models_) physics.set_model_velocity(m.model, m.velocity);
  for (const auto& s : spins_) physics.set_joint_velocity(s.joint, s.omega);
}

}  // namespace convoy::world
