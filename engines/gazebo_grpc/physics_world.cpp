#include "physics_world.h"

#include <algorithm>
#include <dart/collision/bullet/BulletCollisionDetector.hpp>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "height_map.h"

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
    case Shape::kHeightmap: {
      const HeightMapShape hm =
          make_height_map(read_height_map(s.mesh, s.size.z()), s.size, s.position);
      *offset = *offset * hm.offset;
      return hm.shape;
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

// --- One model's skeleton ---------------------------------------------------------------

// Static scenery that nothing can touch (no collision) and that carries no sensor is for the
// cameras only: DART's per-skeleton cost would buy nothing.
bool needs_physics(const ModelDesc& model) {
  if (model.links.empty()) return false;
  if (!model.is_static) return true;
  bool needed = false;
  for (const auto& l : model.links) needed |= !l.collisions.empty() || !l.cameras.empty();
  return needed;
}

// A model's links and joints, indexed for the walk from its root links down its joints.
struct LinkTree {
  std::unordered_map<std::string, const LinkDesc*> links;                   // by name
  std::unordered_map<std::string, std::vector<const JointDesc*>> children;  // by parent
  std::set<std::string> has_parent;
  std::unordered_map<std::string, const JointDesc*> to_world;  // child link -> joint to world
};

LinkTree index_links(const ModelDesc& model) {
  LinkTree tree;
  for (const auto& l : model.links) tree.links[l.name] = &l;
  for (const auto& j : model.joints) {
    if (!tree.links.count(j.child)) {
      throw std::runtime_error("joint '" + j.name + "': unknown child link '" + j.child + "'");
    }
    if (j.parent == "world") {
      tree.to_world[j.child] = &j;
    } else {
      if (!tree.links.count(j.parent)) {
        throw std::runtime_error("joint '" + j.name + "': unknown parent link '" + j.parent + "'");
      }
      tree.children[j.parent].push_back(&j);
    }
    tree.has_parent.insert(j.child);
  }
  return tree;
}

// A revolute or prismatic joint whose limits are equal cannot move: Gazebo holds it at the
// limit.
bool is_locked(const JointDesc& j) {
  return (j.type == JointDesc::kRevolute || j.type == JointDesc::kPrismatic) && !j.axes.empty() &&
         j.axes[0].lower == j.axes[0].upper;
}

// A fixed or locked joint holds its child rigidly to its parent.
bool is_rigid(const JointDesc& j) { return j.type == JointDesc::kFixed || is_locked(j); }

// Where joint `j` holds its child's side, in the world as the SDF places the links: the joint
// frame, turned or moved to the limit if the joint is locked.
Eigen::Isometry3d held_pose(const JointDesc& j) {
  Eigen::Isometry3d at = j.pose;
  if (!is_locked(j)) return at;
  const AxisDesc& axis = j.axes[0];
  if (j.type == JointDesc::kRevolute)
    at.rotate(Eigen::AngleAxisd(axis.lower, axis.xyz.normalized()));
  else
    at.translate(axis.lower * axis.xyz.normalized());
  return at;
}

dd::BodyNode::Properties body_props(const LinkDesc& l) {
  dd::BodyNode::Properties bp;
  bp.mName = l.name;
  bp.mInertia = dd::Inertia(l.mass, l.com, l.inertia);
  bp.mGravityMode = l.gravity;
  return bp;
}

// Adds the mass of link `l`, whose frame is `offset` in the body's frame, to body `bn`.
void add_inertia(dd::BodyNode* bn, const LinkDesc& l, const Eigen::Isometry3d& offset) {
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
}

// A joint of DART type J, named after SDF joint `j`, from body `parent` (nullptr: the world),
// whose frame is `parent_world` in the world, to a new body for link `l`; `finish` completes
// the joint's properties.
template <typename J, typename Finish>
std::pair<dd::Joint*, dd::BodyNode*> create_joint(dd::Skeleton& skel, dd::BodyNode* parent,
                                                  const Eigen::Isometry3d& parent_world,
                                                  const LinkDesc& l, const JointDesc& j,
                                                  Finish finish) {
  typename J::Properties p;
  set_frames(p, j.name, parent_world, l.pose, j.pose);
  finish(p);
  return skel.createJointAndBodyNodePair<J>(parent, p, body_props(l));
}

// Gives each axis of `joint` the SDF joint's limits, damping, friction and effort limit.
void set_axis_dynamics(dd::Joint* joint, const JointDesc& j) {
  for (size_t a = 0; a < joint->getNumDofs() && a < j.axes.size(); ++a) {
    const auto& ax = j.axes[a];
    bool limited = j.type != JointDesc::kContinuous && ax.lower < ax.upper && ax.lower > -1e15 &&
                   ax.upper < 1e15;
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
}

// A model's skeleton, and where its links and movable joints ended up.
struct BuiltModel {
  struct Link {
    std::string name;
    dd::BodyNode* body;
    Eigen::Isometry3d offset;  // the link's frame in the body's frame
  };
  struct Joint {
    std::string name;
    dd::Joint* joint;
  };
  dd::SkeletonPtr skeleton;
  std::vector<Link> links;    // in the order built
  std::vector<Joint> joints;  // those with a degree of freedom, in the order built
};

// Builds a model's skeleton, walking from each root link down the joints: a body per link,
// except that a link held rigidly to its parent joins the parent's body.
class SkeletonBuilder {
 public:
  explicit SkeletonBuilder(const ModelDesc& model) : model_(model), tree_(index_links(model)) {
    out_.skeleton = dd::Skeleton::create(model.name);
  }

  BuiltModel build() && {
    for (const auto& l : model_.links) {
      auto tw = tree_.to_world.find(l.name);
      if (tw != tree_.to_world.end()) {
        attach(nullptr, Eigen::Isometry3d::Identity(), l, tw->second);  // jointed to the world
      } else if (!tree_.has_parent.count(l.name)) {
        attach(nullptr, Eigen::Isometry3d::Identity(), l, nullptr);  // a free or welded root
      }
    }
    if (model_.is_static) out_.skeleton->setMobile(false);  // DART then skips its dynamics
    return std::move(out_);
  }

 private:
  // Builds link `l` and the links below it. `j` joins it to body `parent`, whose frame is
  // `parent_world` in the world as the SDF places the links (nullptr and the identity: the
  // world); no `j`: `l` is a root link.
  void attach(dd::BodyNode* parent, const Eigen::Isometry3d& parent_world, const LinkDesc& l,
              const JointDesc* j) {
    if (j && parent && is_rigid(*j)) {
      fuse(parent, parent_world, l, *j);
      return;
    }
    dd::BodyNode* body = j ? add_jointed_body(parent, parent_world, l, *j) : add_root_body(l);
    add_shapes(body, l, Eigen::Isometry3d::Identity());
    attach_children(l, body, l.pose);
  }

  // Builds the links below link `l`, which is part of `body`, whose frame is `body_world` in
  // the world as the SDF places the links.
  void attach_children(const LinkDesc& l, dd::BodyNode* body, const Eigen::Isometry3d& body_world) {
    auto it = tree_.children.find(l.name);
    if (it == tree_.children.end()) return;
    for (const JointDesc* j : it->second) attach(body, body_world, *tree_.links.at(j->child), j);
  }

  // Link `l`, held rigidly by joint `j`, becomes part of its parent's body: its mass and shapes
  // join that body, which DART steps faster than two bodies welded together.
  void fuse(dd::BodyNode* parent, const Eigen::Isometry3d& parent_world, const LinkDesc& l,
            const JointDesc& j) {
    const Eigen::Isometry3d offset =
        parent_world.inverse() * held_pose(j) * j.pose.inverse() * l.pose;
    add_inertia(parent, l, offset);
    add_shapes(parent, l, offset);
    attach_children(l, parent, l.pose * offset.inverse());
  }

  // The body of root link `l`: welded to the world in a static model, on a free joint
  // otherwise.
  dd::BodyNode* add_root_body(const LinkDesc& l) {
    const std::string name = model_.name + "::__root__" + l.short_name;
    if (model_.is_static) {
      dd::WeldJoint::Properties p;
      set_frames(p, name, Eigen::Isometry3d::Identity(), l.pose, l.pose);
      return out_.skeleton->createJointAndBodyNodePair<dd::WeldJoint>(nullptr, p, body_props(l))
          .second;
    }
    dd::FreeJoint::Properties p;
    p.mName = name;
    auto [joint, body] =
        out_.skeleton->createJointAndBodyNodePair<dd::FreeJoint>(nullptr, p, body_props(l));
    joint->setPositions(dd::FreeJoint::convertToPositions(l.pose));
    return body;
  }

  // The body of link `l`, hanging from `parent` by joint `j` with the SDF's axis dynamics.
  dd::BodyNode* add_jointed_body(dd::BodyNode* parent, const Eigen::Isometry3d& parent_world,
                                 const LinkDesc& l, const JointDesc& j) {
    auto [joint, body] = create_typed_joint(parent, parent_world, l, j);
    set_axis_dynamics(joint, j);
    if (joint->getNumDofs() > 0) out_.joints.push_back({j.name, joint});
    return body;
  }

  // The DART joint for SDF joint `j`, and the new body for link `l`.
  std::pair<dd::Joint*, dd::BodyNode*> create_typed_joint(dd::BodyNode* parent,
                                                          const Eigen::Isometry3d& parent_world,
                                                          const LinkDesc& l, const JointDesc& j) {
    dd::Skeleton& skel = *out_.skeleton;
    const AxisDesc axis = j.axes.empty() ? AxisDesc{} : j.axes[0];
    auto as_is = [](auto&) {};
    auto one_axis = [&](auto& p) { p.mAxis = axis.xyz; };
    if (is_locked(j)) {  // to the world (see attach): welded where it is held
      return create_joint<dd::WeldJoint>(skel, parent, parent_world, l, j, [&](auto& p) {
        p.mT_ParentBodyToJoint = parent_world.inverse() * held_pose(j);
      });
    }
    switch (j.type) {
      case JointDesc::kRevolute:
      case JointDesc::kContinuous:
        return create_joint<dd::RevoluteJoint>(skel, parent, parent_world, l, j, one_axis);
      case JointDesc::kPrismatic:
        return create_joint<dd::PrismaticJoint>(skel, parent, parent_world, l, j, one_axis);
      case JointDesc::kFixed:
        return create_joint<dd::WeldJoint>(skel, parent, parent_world, l, j, as_is);
      case JointDesc::kBall:
        return create_joint<dd::BallJoint>(skel, parent, parent_world, l, j, as_is);
      case JointDesc::kUniversal:
        return create_joint<dd::UniversalJoint>(skel, parent, parent_world, l, j, [&](auto& p) {
          p.mAxis[0] = axis.xyz;
          p.mAxis[1] = j.axes.size() > 1 ? j.axes[1].xyz : Eigen::Vector3d::UnitY();
        });
    }
    throw std::logic_error("joint '" + j.name + "': unknown joint type");
  }

  // Gives body `bn` the collision shapes of link `l`, whose frame is `offset` in the body's
  // frame, and records the link as that body and offset.
  void add_shapes(dd::BodyNode* bn, const LinkDesc& l, const Eigen::Isometry3d& offset) {
    for (const auto& c : l.collisions) {
      Eigen::Isometry3d shape_offset = c.pose;
      auto shape = make_shape(c.shape, &shape_offset);
      auto* node = bn->createShapeNodeWith<dd::CollisionAspect, dd::DynamicsAspect>(
          shape, l.name + "::" + c.name);
      node->setRelativeTransform(offset * shape_offset);
      node->getDynamicsAspect()->setFrictionCoeff(c.mu);
    }
    out_.links.push_back({l.name, bn, offset});
  }

  const ModelDesc& model_;
  const LinkTree tree_;
  BuiltModel out_;
};

// --- Static scenery and moving bodies ---------------------------------------------------

// Static scenery: a static model with collisions and no infinite plane.
bool is_scenery(const ModelDesc& model) {
  bool has_plane = false, has_collision = false;
  for (const auto& l : model.links) {
    for (const auto& c : l.collisions) {
      has_plane |= c.shape.kind == Shape::kPlane || c.shape.kind == Shape::kHeightmap;
    }
    has_collision |= !l.collisions.empty();
  }
  return model.is_static && has_collision && !has_plane;
}

// The box holding the collision shapes of body `bn`, in the body's frame.
Eigen::AlignedBox3d collision_box(dd::BodyNode* bn) {
  Eigen::AlignedBox3d box;
  for (const dd::ShapeNode* node : bn->getShapeNodesWith<dd::CollisionAspect>()) {
    const auto& bb = node->getShape()->getBoundingBox();
    box.extend(
        transformed(Eigen::AlignedBox3d(bb.getMin(), bb.getMax()), node->getRelativeTransform()));
  }
  return box;
}

// The distance from the origin to the farthest corner of `box`.
double farthest_corner(const Eigen::AlignedBox3d& box) {
  double radius = 0;
  for (int c = 0; c < 8; ++c)
    radius = std::max(radius, box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)).norm());
  return radius;
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
  if (!needs_physics(model)) return;
  BuiltModel built = SkeletonBuilder(model).build();
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
    }
  }
  skel->setMobile(false);
  actors_.push_back({skel, false});
  return static_cast<int>(actors_.size() - 1);
}

void PhysicsWorld::set_actor_pose(int actor, const Eigen::Isometry3d& pose) {
  auto& skel = actors_[actor].skeleton;
  skel->getRootJoint()->setPositions(dd::FreeJoint::convertToPositions(pose));
}

void PhysicsWorld::set_actor_name(int actor, const std::string& name) {
  auto& skel = actors_[actor].skeleton;
  skel->setName("actor:" + name);
  skel->getRootJoint()->setName("actor:" + name);
}

void PhysicsWorld::set_actor_present(int actor, bool present) {
  Actor& a = actors_[actor];
  if (a.present == present) return;
  if (present)
    world_->addSkeleton(a.skeleton);
  else
    world_->removeSkeleton(a.skeleton);
  a.present = present;
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
