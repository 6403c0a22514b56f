#include "physics_world.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "contact_cap.h"
#include "skeleton_builder.h"

namespace convoy::world {

namespace dd = dart::dynamics;

PhysicsWorld::PhysicsWorld(const WorldDesc& desc) {
  world_ = dart::simulation::World::create(desc.name);
  world_->setGravity(desc.gravity);
  world_->setTimeStep(desc.max_step_size > 0 ? desc.max_step_size : 0.001);
  detector_ = CappedBulletDetector::create(desc.max_contacts);
  world_->getConstraintSolver()->setCollisionDetector(detector_);
  for (const auto& model : desc.models) build_model(model);
  gate_every_ = std::max<int64_t>(1, std::llround(0.02 / world_->getTimeStep()));
}

void PhysicsWorld::build_model(const ModelDesc& model) {
  if (!needs_physics(model)) return;
  BuiltModel built = build_skeleton(model);
  for (const auto& [shape, limit] : built.contact_limits) detector_->limit_shape(shape, limit);
  for (const auto& l : built.links) add_link(l.name, l.body, l.offset);
  for (const auto& j : built.joints) add_joint(j.name, j.joint);
  add_skeleton(built.skeleton, model);
}

void PhysicsWorld::add_link(const std::string& name, dd::BodyNode* body,
                            const Eigen::Isometry3d& offset) {
  links_.push_back({body, offset, offset.isApprox(Eigen::Isometry3d::Identity(), 0)});
  link_names_.push_back(name);
  link_by_name_[name] = static_cast<int>(links_.size() - 1);
}

void PhysicsWorld::add_joint(const std::string& name, dd::Joint* joint) {
  joints_.push_back({name, joint, 0, joint->getNumDofs() > 0 ? joint->getCoulombFriction(0) : 0.0});
  joint_by_name_[name] = static_cast<int>(joints_.size() - 1);
}

void PhysicsWorld::add_skeleton(const dd::SkeletonPtr& skel, const ModelDesc& model) {
  // Static scenery stays out of the DART world: it has no dynamics, and DART would still visit
  // it every step. gate_scenery() enters it into collision detection while a moving body is
  // near.
  const bool scenery = is_scenery(model);
  skeleton_by_model_[model.name] = skel;
  if (scenery)
    scenery_.push_back({skel, {}, false});
  else
    world_->addSkeleton(skel);
  for (size_t b = 0; b < skel->getNumBodyNodes(); ++b) {
    dd::BodyNode* bn = skel->getBodyNode(b);
    const Eigen::AlignedBox3d box = collision_box(bn);
    if (box.isEmpty()) continue;
    if (scenery) {
      scenery_.back().box.extend(transformed(box, bn->getWorldTransform()));
    } else if (!model.is_static) {
      moving_.push_back({bn, farthest_corner(box)});
    }
  }
  // Wheels and vehicles, for the weather.
  if (scenery || model.is_static) return;
  bool has_wheels = false;
  for (size_t b = 0; b < skel->getNumBodyNodes(); ++b) {
    dd::BodyNode* bn = skel->getBodyNode(b);
    if (!dynamic_cast<dd::RevoluteJoint*>(bn->getParentJoint())) continue;
    for (dd::ShapeNode* node : bn->getShapeNodesWith<dd::CollisionAspect>()) {
      if (auto* dyn = node->getDynamicsAspect()) {
        wheels_.push_back({node, dyn->getFrictionCoeff()});
        has_wheels = true;
      }
    }
  }
  if (has_wheels) {
    dd::BodyNode* root = skel->getRootBodyNode();
    const Eigen::AlignedBox3d box = collision_box(root);
    const Eigen::Vector3d size = box.isEmpty() ? Eigen::Vector3d(4.0, 1.8, 1.5) : box.sizes();
    vehicles_.push_back({root, size.y() * size.z(), size.x() * size.z()});
  }
}

void PhysicsWorld::set_wheel_friction(double mu) {
  for (auto& w : wheels_) w.shape->getDynamicsAspect()->setFrictionCoeff(mu * w.sdf_mu);
}

void PhysicsWorld::set_wind(const Eigen::Vector3d& wind) { wind_ = wind; }

Eigen::Vector3d PhysicsWorld::wind_force(int vehicle) const { return vehicles_[vehicle].force; }

void PhysicsWorld::set_joint_brake(int index, double torque) {
  JointRef& j = joints_[index];
  j.joint->setCoulombFriction(0, j.base_friction + std::max(0.0, torque));
}

dd::BodyNode* PhysicsWorld::joint_child(int index) const {
  return joints_[index].joint->getChildBodyNode();
}

Eigen::Vector3d PhysicsWorld::joint_axis_world(int index) const {
  const dd::Joint* j = joints_[index].joint;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  if (auto* r = dynamic_cast<const dd::RevoluteJoint*>(j)) axis = r->getAxis();
  // The axis is in the child's frame (DART: the joint frame of the child).
  return j->getChildBodyNode()->getWorldTransform().linear() *
         (j->getTransformFromChildBodyNode().linear() * axis);
}

void PhysicsWorld::compute_reach() {
  const double window = static_cast<double>(gate_every_) * world_->getTimeStep();
  reach_.clear();
  for (const auto& m : moving_) {
    reach_.emplace_back(m.body->getWorldTransform().translation(),
                        m.radius + 2.0 * m.body->getLinearVelocity().norm() * window + 0.5);
  }
}

// Actors stand still between two set_actor_pose calls, and each call brings a new decision
// before the next step: a moving body's reach covers the time until then.
void PhysicsWorld::gate_actors() {
  actors_posed_ = false;
  for (auto& a : actors_) {
    if (!a.present) continue;
    const Eigen::Vector3d p = a.pose.translation();
    bool near = false;
    for (const auto& [centre, reach] : reach_) {
      if ((p - centre).norm() <= reach + a.radius) {
        near = true;
        break;
      }
    }
    if (near == a.colliding) continue;
    // Out of the DART world, not only out of collision detection: its constraint solver
    // visits every skeleton of the world at every step.
    if (near) {
      if (a.skeleton_stale) pose_skeleton(a);
      world_->addSkeleton(a.skeleton);
    } else
      world_->removeSkeleton(a.skeleton);
    a.colliding = near;
  }
}

void PhysicsWorld::gate_scenery() {
  // A moving body travels at most about |v| * window before the next decision; twice that
  // plus half a metre keeps every contact that can happen before then.
  compute_reach();
  auto group = world_->getConstraintSolver()->getCollisionGroup();
  for (auto& s : scenery_) {
    bool near = false;
    for (const auto& [centre, reach] : reach_) {
      if (s.box.exteriorDistance(centre) <= reach) {
        near = true;
        break;
      }
    }
    if (near == s.active) continue;
    if (near)
      group->subscribeTo(dd::ConstSkeletonPtr(s.skeleton));
    else
      group->unsubscribeFrom(s.skeleton.get());
    s.active = near;
  }
}

void PhysicsWorld::step() {
  for (auto& j : joints_) {
    if (j.effort != 0) j.joint->setForce(0, j.effort);
  }
  const bool gate = steps_++ % gate_every_ == 0;
  if (gate) gate_scenery();
  if (gate || actors_posed_) {
    if (!gate) compute_reach();
    gate_actors();
  }
  for (auto& v : vehicles_) {
    v.force.setZero();
    if (wind_.squaredNorm() == 0) continue;
    // 1/2 rho |w| Cd A w per body axis (air density 1.225 kg/m^3).
    const Eigen::Matrix3d r = v.root->getWorldTransform().linear();
    const Eigen::Vector3d w = r.transpose() * wind_;
    const double q = 0.5 * 1.225 * wind_.norm();
    const Eigen::Vector3d f_body(q * 0.4 * v.area_x * w.x(), q * 1.0 * v.area_y * w.y(), 0.0);
    v.force = r * f_body;
    v.root->addExtForce(v.force, v.root->getLocalCOM(), /*isForceLocal=*/false,
                        /*isOffsetLocal=*/true);
  }
  world_->step();
}

int PhysicsWorld::add_actor(const std::string& name, const ModelDesc& model) {
  auto skel = dd::Skeleton::create("actor:" + name);
  dd::FreeJoint::Properties jp;
  jp.mName = "actor:" + name;
  auto [joint, body] = skel->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, jp);
  (void)joint;
  for (const auto& l : model.links) {
    for (const auto& c : l.collisions) {
      Eigen::Isometry3d shape_offset = c.pose;
      auto shape = make_shape(c.shape, &shape_offset);
      auto* node = body->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(
          shape, l.name + "::" + c.name);
      node->setRelativeTransform(l.pose * shape_offset);
      node->getDynamicsAspect()->setFrictionCoeff(c.mu);
      if (c.max_contacts > 0) detector_->limit_shape(node, c.max_contacts);
    }
  }
  skel->setMobile(false);
  const Eigen::AlignedBox3d box = collision_box(body);
  actors_.push_back({skel, false, false, box.isEmpty() ? 0.0 : farthest_corner(box),
                     skel->getRootBodyNode()->getWorldTransform(), false});
  return static_cast<int>(actors_.size() - 1);
}

void PhysicsWorld::set_actor_pose(int actor, const Eigen::Isometry3d& pose) {
  Actor& a = actors_[actor];
  a.pose = pose;
  a.skeleton_stale = true;
  if (a.colliding) pose_skeleton(a);
  actors_posed_ = true;
}

void PhysicsWorld::pose_skeleton(Actor& a) {
  a.skeleton->getRootJoint()->setPositions(dd::FreeJoint::convertToPositions(a.pose));
  a.skeleton_stale = false;
}

void PhysicsWorld::set_actor_name(int actor, const std::string& name) {
  auto& skel = actors_[actor].skeleton;
  skel->setName("actor:" + name);
  skel->getRootJoint()->setName("actor:" + name);
}

void PhysicsWorld::set_actor_present(int actor, bool present) {
  Actor& a = actors_[actor];
  if (a.present == present) return;
  // In the DART world only while near a moving body: gate_actors() decides before the next
  // step.
  if (!present && a.colliding) world_->removeSkeleton(a.skeleton);
  a.present = present;
  a.colliding = a.colliding && present;
  actors_posed_ = true;
}

const dd::Skeleton* PhysicsWorld::model_skeleton(const std::string& model) const {
  auto it = skeleton_by_model_.find(model);
  return it == skeleton_by_model_.end() ? nullptr : it->second.get();
}

void PhysicsWorld::contact_pairs(
    std::vector<std::pair<const dd::Skeleton*, const dd::Skeleton*>>* out) const {
  out->clear();
  const auto& result = world_->getLastCollisionResult();
  for (const auto& c : result.getContacts()) {
    auto skeleton_of = [](const dart::collision::CollisionObject* o) -> const dd::Skeleton* {
      const auto* node = dynamic_cast<const dd::ShapeNode*>(o->getShapeFrame());
      return node ? node->getSkeleton().get() : nullptr;
    };
    const dd::Skeleton* a = skeleton_of(c.collisionObject1);
    const dd::Skeleton* b = skeleton_of(c.collisionObject2);
    if (!a || !b || a == b) continue;
    if (b < a) std::swap(a, b);
    out->emplace_back(a, b);
  }
  std::sort(out->begin(), out->end());
  out->erase(std::unique(out->begin(), out->end()), out->end());
}

int PhysicsWorld::joint_index(const std::string& name) const {
  auto it = joint_by_name_.find(name);
  return it == joint_by_name_.end() ? -1 : it->second;
}

JointState PhysicsWorld::joint_state(int index) const {
  const auto& j = joints_[index];
  return {j.joint->getPosition(0), j.joint->getVelocity(0), j.effort};
}

void PhysicsWorld::set_joint_effort(int index, double effort) { joints_[index].effort = effort; }

void PhysicsWorld::set_joint_position(int index, double position) {
  joints_[index].joint->setPosition(0, position);
  joints_[index].joint->setVelocity(0, 0);
}

void PhysicsWorld::set_joint_velocity(int index, double velocity) {
  joints_[index].joint->setVelocity(0, velocity);
}

bool PhysicsWorld::set_model_velocity(const std::string& model, const Eigen::Vector3d& velocity) {
  auto it = skeleton_by_model_.find(model);
  if (it == skeleton_by_model_.end() || !it->second->isMobile()) return false;
  dd::Skeleton& skel = *it->second;
  skel.resetVelocities();
  bool moved = false;
  for (size_t t = 0; t < skel.getNumTrees(); ++t) {
    if (auto* free = dynamic_cast<dd::FreeJoint*>(skel.getRootJoint(t))) {
      free->setLinearVelocity(velocity);  // of the root body's origin, in the world frame
      moved = true;
    }
  }
  return moved;
}

int PhysicsWorld::link_index(const std::string& name) const {
  auto it = link_by_name_.find(name);
  return it == link_by_name_.end() ? -1 : it->second;
}

Eigen::Isometry3d PhysicsWorld::link_pose(int index) const {
  const LinkRef& l = links_[index];
  if (l.at_origin) return l.body->getWorldTransform();
  return l.body->getWorldTransform() * l.offset;
}

LinkState PhysicsWorld::link_state(int index) const {
  const LinkRef& l = links_[index];
  LinkState s;
  const Eigen::Isometry3d t = link_pose(index);
  s.position = t.translation();
  s.rotation = Eigen::Quaterniond(t.linear());
  s.linear_velocity = l.body->getLinearVelocity(l.offset.translation());
  s.angular_velocity = l.body->getAngularVelocity();
  return s;
}

}  // namespace convoy::world
