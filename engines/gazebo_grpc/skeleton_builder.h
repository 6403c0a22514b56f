// DART skeletons from SDF model descriptions, for PhysicsWorld (physics_world.h): each SDF
// model is a skeleton; each link a body node, except that links joined by a fixed joint (or
// one whose limits are equal) share one; root links hang from the world on a free joint (a
// weld for static models).
#pragma once

#include <dart/dart.hpp>
#include <string>
#include <utility>
#include <vector>

#include "world_description.h"

namespace convoy::world {

// A model's skeleton, and where its links and movable joints ended up.
struct BuiltModel {
  struct Link {
    std::string name;
    dart::dynamics::BodyNode* body;
    Eigen::Isometry3d offset;  // the link's frame in the body's frame
  };
  struct Joint {
    std::string name;
    dart::dynamics::Joint* joint;
  };
  dart::dynamics::SkeletonPtr skeleton;
  std::vector<Link> links;    // in the order built
  std::vector<Joint> joints;  // those with a degree of freedom, in the order built
  // The collision shapes whose SDF sets <max_contacts>, with its value.
  std::vector<std::pair<const dart::dynamics::ShapeNode*, int>> contact_limits;
};

// Builds a model's skeleton, walking from each root link down the joints.
BuiltModel build_skeleton(const ModelDesc& model);

// DART's shape for an SDF geometry; `offset` (the shape's frame in the link's) moves with it
// where the shape's own origin differs (a mesh collides as its bounding box, off-centre).
dart::dynamics::ShapePtr make_shape(const Shape& s, Eigen::Isometry3d* offset);

// Static scenery that nothing can touch (no collision) and that carries no sensor is for the
// cameras only: DART's per-skeleton cost would buy nothing.
bool needs_physics(const ModelDesc& model);
// Static scenery: a static model with collisions and no infinite plane.
bool is_scenery(const ModelDesc& model);

// The axis-aligned box holding `box` moved by `t`.
Eigen::AlignedBox3d transformed(const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& t);
// The box holding the collision shapes of body `bn`, in the body's frame.
Eigen::AlignedBox3d collision_box(dart::dynamics::BodyNode* bn);
// The distance from the origin to the farthest corner of `box`.
double farthest_corner(const Eigen::AlignedBox3d& box);

}  // namespace convoy::world
