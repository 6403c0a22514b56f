#include "physics_world.h"

#include <algorithm>
#include <dart/collision/bullet/BulletCollisionDetector.hpp>
#include <functional>
#include <set>
#include <stdexcept>
#include <type_traits>

namespace convoy::world {

namespace dd = dart::dynamics;

namespace {

dd::ShapePtr make_shape(const Shape& s, Eigen::Isometry3d* offset) {
  switch (s.kind) {
    case Shape::kBox:
      return std::make_shared<dd::BoxShape>(s.size);
    case Shape::kCylinder:
      return std::make_shared<dd::CylinderShape>(s.size.x(), s.size.z());
    case Shape::kSphere:
      return std::make_shared<dd::SphereShape>(s.size.x());
    case Shape::kPlane:
      // Collision planes are infinite, as in Gazebo (Bullet's static plane).
      return std::make_shared<dd::PlaneShape>(s.normal, 0.0);
    case Shape::kMesh: {
      // Bullet, as DART drives it, does not collide moving triangle meshes with primitives;
      // a mesh collides as its bounding box (documented limitation).
      const aiScene* scene = dd::MeshShape::loadMesh(s.mesh.string());
      if (!scene) throw std::runtime_error(s.mesh.string() + ": cannot load mesh");
      auto mesh = std::make_shared<dd::MeshShape>(s.scale, scene);
      const auto& box = mesh->getBoundingBox();
      Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
      t.translation() = box.computeCenter();
      *offset = *offset * t;
      return std::make_shared<dd::BoxShape>(box.computeFullExtents().cwiseMax(1e-3));
    }
  }
  return nullptr;
}

// Properties shared by every joint type: name and the frames on both sides.
template <typename Props>
void set_frames(Props& p, const std::string& name, const Eigen::Isometry3d& parent_world,
                const Eigen::Isometry3d& child_world, const Eigen::Isometry3d& joint_world) {
  p.mName = name;
  p.mT_ParentBodyToJoint = parent_world.inverse() * joint_world;
  p.mT_ChildBodyToJoint = child_world.inverse() * joint_world;
}

// The axis-aligned box holding `box` moved by `t`.
Eigen::AlignedBox3d transformed(const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& t) {
  Eigen::AlignedBox3d out;
  for (int c = 0; c < 8; ++c)
    out.extend(t * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)));
  return out;
}

}  // namespace

PhysicsWorld::PhysicsWorld(const WorldDesc& desc) {
  world_ = dart::simulation::World::create(desc.name);
  world_->setGravity(desc.gravity);
  world_->setTimeStep(desc.max_step_size > 0 ? desc.max_step_size : 0.001);
  world_->getConstraintSolver()->setCollisionDetector(
      dart::collision::BulletCollisionDetector::create());
  for (const auto& model : desc.models) build_model(model);
  gate_every_ = std::max<int64_t>(1, std::llround(0.02 / world_->getTimeStep()));
}

void PhysicsWorld::build_model(const ModelDesc& model) {
  if (model.links.empty()) return;
  // Static scenery that nothing can touch (no collision) and that carries no sensor is for
  // the cameras only: DART's per-skeleton cost would buy nothing.
  if (model.is_static) {
    bool needed = false;
    for (const auto& l : model.links) needed |= !l.collisions.empty() || !l.cameras.empty();
    if (!needed) return;
  }
  auto skel = dd::Skeleton::create(model.name);
  std::unordered_map<std::string, const LinkDesc*> links;
  for (const auto& l : model.links) links[l.name] = &l;
  std::unordered_map<std::string, std::vector<const JointDesc*>> children;  // by parent
  std::set<std::string> has_parent;
  std::unordered_map<std::string, const JointDesc*> to_world;  // child link -> joint to world
  for (const auto& j : model.joints) {
    if (!links.count(j.child)) {
      throw std::runtime_error("joint '" + j.name + "': unknown child link '" + j.child + "'");
    }
    if (j.parent == "world") {
      to_world[j.child] = &j;
    } else {
      if (!links.count(j.parent)) {
        throw std::runtime_error("joint '" + j.name + "': unknown parent link '" + j.parent + "'");
      }
      children[j.parent].push_back(&j);
    }
    has_parent.insert(j.child);
  }

  auto body_props = [](const LinkDesc& l) {
    dd::BodyNode::Properties bp;
    bp.mName = l.name;
    bp.mInertia = dd::Inertia(l.mass, l.com, l.inertia);
    bp.mGravityMode = l.gravity;
    return bp;
  };
  // Gives body `bn` the collision shapes of link `l`, whose frame is `link_offset` in the
  // body's frame, and registers the link as that body and offset.
  auto add_shapes = [&](dd::BodyNode* bn, const LinkDesc& l, const Eigen::Isometry3d& link_offset) {
    for (const auto& c : l.collisions) {
      Eigen::Isometry3d offset = c.pose;
      auto shape = make_shape(c.shape, &offset);
      auto* node = bn->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(
          shape, l.name + "::" + c.name);
      node->setRelativeTransform(link_offset * offset);
      node->getDynamicsAspect()->setFrictionCoeff(c.mu);
    }
    links_.push_back({bn, link_offset, link_offset.isApprox(Eigen::Isometry3d::Identity(), 0)});
    link_names_.push_back(l.name);
    link_by_name_[l.name] = static_cast<int>(links_.size() - 1);
  };
  // Adds the mass of link `l`, whose frame is `offset` in the body's frame, to body `bn`.
  auto add_inertia = [](dd::BodyNode* bn, const LinkDesc& l, const Eigen::Isometry3d& offset) {
    const dd::Inertia& host = bn->getInertia();
    const double m1 = host.getMass(), m2 = l.mass, m = m1 + m2;
    const Eigen::Vector3d c1 = host.getLocalCOM(), c2 = offset * l.com;
    const Eigen::Vector3d c = m > 0 ? Eigen::Vector3d((m1 * c1 + m2 * c2) / m) : c1;
    auto about_c = [&](double mass, const Eigen::Vector3d& at) -> Eigen::Matrix3d {
      const Eigen::Vector3d d = at - c;  // parallel axis theorem
      return mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
    };
    const Eigen::Matrix3d moment = host.getMoment() + about_c(m1, c1) +
                                   offset.linear() * l.inertia * offset.linear().transpose() +
                                   about_c(m2, c2);
    bn->setInertia(dd::Inertia(m, c, moment));
  };

  // Builds the subtree hanging from `parent_bn` through joint `j` (nullptr: a root link).
  // `parent_world` is where the parent body's frame is in the world as the SDF places the
  // links (the identity for the world).
  std::function<void(dd::BodyNode*, const Eigen::Isometry3d&, const LinkDesc&, const JointDesc*)>
      attach;
  attach = [&](dd::BodyNode* parent_bn, const Eigen::Isometry3d& parent_world, const LinkDesc& l,
               const JointDesc* j) {
    auto attach_children = [&](dd::BodyNode* bn, const Eigen::Isometry3d& bn_world) {
      auto it = children.find(l.name);
      if (it == children.end()) return;
      for (const JointDesc* cj : it->second) attach(bn, bn_world, *links.at(cj->child), cj);
    };
    // A revolute or prismatic joint whose limits are equal cannot move (Gazebo holds it at
    // the limit). Such a joint, or a fixed one, between two links makes them one rigid body:
    // the child's mass and shapes join the parent's body, which DART steps faster than two
    // bodies welded together.
    const AxisDesc axis = (!j || j->axes.empty()) ? AxisDesc{} : j->axes[0];
    const bool locked = j &&
                        (j->type == JointDesc::kRevolute || j->type == JointDesc::kPrismatic) &&
                        !j->axes.empty() && axis.lower == axis.upper;
    Eigen::Isometry3d joint_at = j ? j->pose : Eigen::Isometry3d::Identity();  // held there
    if (locked && j->type == JointDesc::kRevolute)
      joint_at.rotate(Eigen::AngleAxisd(axis.lower, axis.xyz.normalized()));
    else if (locked)
      joint_at.translate(axis.lower * axis.xyz.normalized());
    if (j && parent_bn && (locked || j->type == JointDesc::kFixed)) {
      const Eigen::Isometry3d offset =
          parent_world.inverse() * joint_at * j->pose.inverse() * l.pose;
      add_inertia(parent_bn, l, offset);
      add_shapes(parent_bn, l, offset);
      attach_children(parent_bn, l.pose * offset.inverse());
      return;
    }
    std::pair<dd::Joint*, dd::BodyNode*> made;
    auto bp = body_props(l);
    if (!j) {
      if (model.is_static) {
        dd::WeldJoint::Properties p;
        set_frames(p, model.name + "::__root__" + l.short_name, Eigen::Isometry3d::Identity(),
                   l.pose, l.pose);
        made = skel->createJointAndBodyNodePair<dd::WeldJoint>(nullptr, p, bp);
      } else {
        dd::FreeJoint::Properties p;
        p.mName = model.name + "::__root__" + l.short_name;
        made = skel->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, p, bp);
        made.first->setPositions(dd::FreeJoint::convertToPositions(l.pose));
      }
    } else {
      // Joint J between the parent body and this link, its properties finished by `finish`.
      auto joint_of = [&](auto type, auto finish) {
        using J = typename decltype(type)::type;
        typename J::Properties p;
        set_frames(p, j->name, parent_world, l.pose, j->pose);
        finish(p);
        return skel->createJointAndBodyNodePair<J>(parent_bn, p, bp);
      };
      auto as_is = [](auto&) {};
      auto one_axis = [&](auto& p) { p.mAxis = axis.xyz; };
      if (locked) {  // to the world: welded where it is held
        made = joint_of(std::type_identity<dd::WeldJoint>{}, [&](auto& p) {
          p.mT_ParentBodyToJoint = parent_world.inverse() * joint_at;
        });
      } else {
        switch (j->type) {
          case JointDesc::kRevolute:
          case JointDesc::kContinuous:
            made = joint_of(std::type_identity<dd::RevoluteJoint>{}, one_axis);
            break;
          case JointDesc::kPrismatic:
            made = joint_of(std::type_identity<dd::PrismaticJoint>{}, one_axis);
            break;
          case JointDesc::kFixed:
            made = joint_of(std::type_identity<dd::WeldJoint>{}, as_is);
            break;
          case JointDesc::kBall:
            made = joint_of(std::type_identity<dd::BallJoint>{}, as_is);
            break;
          case JointDesc::kUniversal:
            made = joint_of(std::type_identity<dd::UniversalJoint>{}, [&](auto& p) {
              p.mAxis[0] = axis.xyz;
              p.mAxis[1] = j->axes.size() > 1 ? j->axes[1].xyz : Eigen::Vector3d::UnitY();
            });
            break;
        }
      }
      dd::Joint* joint = made.first;
      for (size_t a = 0; a < joint->getNumDofs() && a < j->axes.size(); ++a) {
        const auto& ax = j->axes[a];
        bool limited = j->type != JointDesc::kContinuous && ax.lower < ax.upper &&
                       ax.lower > -1e15 && ax.upper < 1e15;
        if (limited) {
          joint->setPositionLowerLimit(a, ax.lower);
          joint->setPositionUpperLimit(a, ax.upper);
          joint->setLimitEnforcement(true);
        }
        joint->setDampingCoefficient(a, ax.damping);
        joint->setCoulombFriction(a, ax.friction);
        if (ax.effort > 0) {
          joint->setForceLowerLimit(a, -ax.effort);
          joint->setForceUpperLimit(a, ax.effort);
        }
      }
      if (joint->getNumDofs() > 0) {
        joints_.push_back({j->name, joint, 0});
        joint_by_name_[j->name] = static_cast<int>(joints_.size() - 1);
      }
    }
    add_shapes(made.second, l, Eigen::Isometry3d::Identity());
    attach_children(made.second, l.pose);
  };

  for (const auto& l : model.links) {
    auto tw = to_world.find(l.name);
    if (tw != to_world.end()) {
      attach(nullptr, Eigen::Isometry3d::Identity(), l, tw->second);  // jointed to the world
    } else if (!has_parent.count(l.name)) {
      attach(nullptr, Eigen::Isometry3d::Identity(), l, nullptr);  // a free or welded root
    }
  }
  if (model.is_static) skel->setMobile(false);  // DART then skips its dynamics

  // Static scenery (static, with collisions, no infinite plane) stays out of the DART world:
  // it has no dynamics, and DART would still visit it every step. gate_scenery() enters it
  // into collision detection while a moving body is near.
  bool has_plane = false, has_collision = false;
  for (const auto& l : model.links) {
    for (const auto& c : l.collisions) has_plane |= c.shape.kind == Shape::kPlane;
    has_collision |= !l.collisions.empty();
  }
  const bool scenery = model.is_static && has_collision && !has_plane;
  if (scenery)
    scenery_.push_back({skel, {}, false});
  else
    world_->addSkeleton(skel);
  for (size_t b = 0; b < skel->getNumBodyNodes(); ++b) {
    dd::BodyNode* bn = skel->getBodyNode(b);
    Eigen::AlignedBox3d box;  // in the body frame
    for (const dd::ShapeNode* node : bn->getShapeNodesWith<dd::CollisionAspect>()) {
      const auto& bb = node->getShape()->getBoundingBox();
      box.extend(
          transformed(Eigen::AlignedBox3d(bb.getMin(), bb.getMax()), node->getRelativeTransform()));
    }
    if (box.isEmpty()) continue;
    if (scenery) {
      scenery_.back().box.extend(transformed(box, bn->getWorldTransform()));
    } else if (!model.is_static) {
      double radius = 0;  // the farthest corner from the body's origin
      for (int c = 0; c < 8; ++c)
        radius =
            std::max(radius, box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)).norm());
      moving_.push_back({bn, radius});
    }
  }
}

void PhysicsWorld::gate_scenery() {
  // A moving body travels at most about |v| * window before the next decision; twice that
  // plus half a metre keeps every contact that can happen before then.
  const double window = static_cast<double>(gate_every_) * world_->getTimeStep();
  auto group = world_->getConstraintSolver()->getCollisionGroup();
  reach_.clear();
  for (const auto& m : moving_) {
    reach_.emplace_back(m.body->getWorldTransform().translation(),
                        m.radius + 2.0 * m.body->getLinearVelocity().norm() * window + 0.5);
  }
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
  if (steps_++ % gate_every_ == 0) gate_scenery();
  world_->step();
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
