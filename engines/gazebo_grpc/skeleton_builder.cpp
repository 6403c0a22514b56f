// Builds DART skeletons from SDF model descriptions (physics_world.h's PhysicsWorld uses it).
#include "skeleton_builder.h"

#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "height_map.h"

namespace convoy::world {

namespace dd = dart::dynamics;

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

namespace {

// Properties shared by every joint type: name and the frames on both sides.
template <typename Props>
void set_frames(Props& p, const std::string& name, const Eigen::Isometry3d& parent_world,
                const Eigen::Isometry3d& child_world, const Eigen::Isometry3d& joint_world) {
  p.mName = name;
  p.mT_ParentBodyToJoint = parent_world.inverse() * joint_world;
  p.mT_ChildBodyToJoint = child_world.inverse() * joint_world;
}

}  // namespace

Eigen::AlignedBox3d transformed(const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& t) {
  Eigen::AlignedBox3d out;
  for (int c = 0; c < 8; ++c)
    out.extend(t * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)));
  return out;
}

bool needs_physics(const ModelDesc& model) {
  if (model.links.empty()) return false;
  if (!model.is_static) return true;
  bool needed = false;
  for (const auto& l : model.links) needed |= !l.collisions.empty() || !l.cameras.empty();
  return needed;
}

namespace {

// --- One model's skeleton ---------------------------------------------------------------

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
      if (c.max_contacts > 0) out_.contact_limits.emplace_back(node, c.max_contacts);
    }
    out_.links.push_back({l.name, bn, offset});
  }

  const ModelDesc& model_;
  const LinkTree tree_;
  BuiltModel out_;
};

}  // namespace

BuiltModel build_skeleton(const ModelDesc& model) { return SkeletonBuilder(model).build(); }

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

Eigen::AlignedBox3d collision_box(dd::BodyNode* bn) {
  Eigen::AlignedBox3d box;
  for (const dd::ShapeNode* node : bn->getShapeNodesWith<dd::CollisionAspect>()) {
    const auto& bb = node->getShape()->getBoundingBox();
    box.extend(
        transformed(Eigen::AlignedBox3d(bb.getMin(), bb.getMax()), node->getRelativeTransform()));
  }
  return box;
}

double farthest_corner(const Eigen::AlignedBox3d& box) {
  double radius = 0;
  for (int c = 0; c < 8; ++c)
    radius = std::max(radius, box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(c)).norm());
  return radius;
}

}  // namespace convoy::world
