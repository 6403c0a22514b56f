// The world's physics: DART with the Bullet collision detector, built from a WorldDesc.
// Each SDF model is a DART skeleton; each link a body node, except that links joined by a
// fixed joint (or one whose limits are equal) share one; root links hang from the world on a
// free joint (a weld for static models).
#pragma once

#include <dart/dart.hpp>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "world_description.h"

namespace convoy::world {

class CappedBulletDetector;

struct JointState {
  double position = 0, velocity = 0, effort = 0;
};

struct LinkState {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
};

class PhysicsWorld {
 public:
  explicit PhysicsWorld(const WorldDesc& desc);

  // One physics step of max_step_size.
  void step();
  double time() const { return world_->getTime(); }
  double step_size() const { return world_->getTimeStep(); }

  // Joints by scoped name (model::joint); -1 if unknown.
  int joint_index(const std::string& name) const;
  const std::string& joint_name(int index) const { return joints_[index].name; }
  JointState joint_state(int index) const;
  // Effort (torque or force) applied on the joint's first axis during the next steps.
  void set_joint_effort(int index, double effort);
  // Moves the joint (first axis) to `position`, at rest; for initial conditions.
  void set_joint_position(int index, double position);
  // Sets the joint's (first axis) velocity; for initial conditions.
  void set_joint_velocity(int index, double velocity);
  // Sets every body of a moving model translating at `velocity` (m/s, world frame), not
  // turning: the free joints of its roots move, its other joints rest. False if the model
  // has no moving skeleton. For initial conditions.
  bool set_model_velocity(const std::string& model, const Eigen::Vector3d& velocity);

  // Links by scoped name (model::link); -1 if unknown.
  int link_index(const std::string& name) const;
  LinkState link_state(int index) const;
  Eigen::Isometry3d link_pose(int index) const;
  const std::vector<std::string>& link_names() const { return link_names_; }

  dart::simulation::WorldPtr dart_world() const { return world_; }

  // --- Weather and brakes --------------------------------------------------------------------
  // Tyre-road friction: every collision shape of a wheel (a body with collision shapes on a
  // revolute joint of a moving model) gets friction coefficient mu times its SDF <mu> (1 for
  // the smart car). DART takes the lesser of two touching shapes' coefficients, so a road
  // with <mu> 1 leaves the tyre's. Before any call the SDF's values hold.
  void set_wheel_friction(double mu);
  int wheel_count() const { return static_cast<int>(wheels_.size()); }
  // Wind (m/s, world frame): each moving model with wheels is pushed at its root body's
  // centre of mass by 1/2 rho |w| (Cd_x A_x w_x, Cd_y A_y w_y) in the body's frame (areas from
  // its collision box; Cd 0.4 head-on, 1.0 sideways), every step. Not the drag of the
  // vehicle's own motion: still air pushes nothing.
  void set_wind(const Eigen::Vector3d& wind);
  Eigen::Vector3d wind_force(int vehicle) const;  // the push on vehicle i in the last step (N)
  // A brake: Coulomb friction torque (Nm) on the joint's first axis, on top of the SDF's
  // <friction>, until changed. It holds a stopped wheel, as a brake does.
  void set_joint_brake(int index, double torque);
  // The joint's child body (the wheel) and its axis in the world frame.
  dart::dynamics::BodyNode* joint_child(int index) const;
  Eigen::Vector3d joint_axis_world(int index) const;

  // Actors: road users posed from outside. Each is one immobile body on a free joint with
  // the collision shapes of `model` (link poses in the actor's frame): the physically
  // simulated models collide with it; it does not move in response. Returns its index.
  // Like static scenery, an actor is in the DART world (collision detection) only while a
  // moving body is near it (decided again before the step after actors were posed, and with
  // the scenery): thousands of actors far from the simulated vehicles cost its step nothing.
  int add_actor(const std::string& name, const ModelDesc& model);
  void set_actor_pose(int actor, const Eigen::Isometry3d& pose);
  // Its skeleton's name becomes "actor:NAME" (an actor taken over by another road user).
  void set_actor_name(int actor, const std::string& name);
  // In the world (colliding) or not.
  void set_actor_present(int actor, bool present);
  // In the DART world after the last step (present and near a moving body).
  bool actor_colliding(int actor) const { return actors_[actor].colliding; }

  // The skeleton of a world model (null if it has none) or of an actor.
  const dart::dynamics::Skeleton* model_skeleton(const std::string& model) const;
  const dart::dynamics::Skeleton* actor_skeleton(int actor) const {
    return actors_[actor].skeleton.get();
  }
  // The pairs of skeletons in contact after the last step, each pair once (in either order).
  void contact_pairs(
      std::vector<std::pair<const dart::dynamics::Skeleton*, const dart::dynamics::Skeleton*>>* out)
      const;

 private:
  struct JointRef {
    std::string name;
    dart::dynamics::Joint* joint = nullptr;
    double effort = 0;
    double base_friction = 0;  // the SDF's <friction> on the first axis
  };
  struct Wheel {
    dart::dynamics::ShapeNode* shape;
    double sdf_mu;
  };
  struct Vehicle {
    dart::dynamics::BodyNode* root;
    double area_x, area_y;  // m^2: frontal (facing +x) and side
    Eigen::Vector3d force = Eigen::Vector3d::Zero();
  };
  std::vector<Wheel> wheels_;
  std::vector<Vehicle> vehicles_;
  Eigen::Vector3d wind_ = Eigen::Vector3d::Zero();
  // Builds a model's skeleton (none for a static model with neither collisions nor cameras)
  // and registers its links and movable joints.
  void build_model(const ModelDesc& model);
  // Registers a link under its scoped name: part of `body`, its frame `offset` in the body's.
  void add_link(const std::string& name, dart::dynamics::BodyNode* body,
                const Eigen::Isometry3d& offset);
  // Registers a joint with a degree of freedom under its scoped name.
  void add_joint(const std::string& name, dart::dynamics::Joint* joint);
  // Puts a model's skeleton into the DART world, or among the static scenery, and notes its
  // moving bodies for gate_scenery().
  void add_skeleton(const dart::dynamics::SkeletonPtr& skel, const ModelDesc& model);
  // Static scenery far from every moving body is left out of collision detection (see
  // step()); this re-decides which scenery takes part, from the moving bodies' state.
  void gate_scenery();

  // A static model with collision shapes but no infinite plane: it takes part in collision
  // detection only while a moving body is near its bounding box.
  struct Scenery {
    dart::dynamics::SkeletonPtr skeleton;
    Eigen::AlignedBox3d box;
    bool active = true;
  };
  // A body of a mobile skeleton with collision shapes, and the radius of a sphere around its
  // origin that holds them.
  struct MovingBody {
    dart::dynamics::BodyNode* body;
    double radius;
  };
  std::vector<Scenery> scenery_;
  std::vector<MovingBody> moving_;
  std::vector<std::pair<Eigen::Vector3d, double>> reach_;  // gate_scenery's, reused
  int64_t steps_ = 0;
  int64_t gate_every_ = 1;

  dart::simulation::WorldPtr world_;
  std::shared_ptr<CappedBulletDetector> detector_;  // Bullet's, contacts capped (contact_cap.h)
  std::vector<JointRef> joints_;
  std::unordered_map<std::string, int> joint_by_name_;
  // A link: the body it is part of (links joined by a fixed joint share one) and its frame
  // in the body's frame.
  struct LinkRef {
    dart::dynamics::BodyNode* body;
    Eigen::Isometry3d offset;
    bool at_origin;  // offset is the identity
  };
  std::vector<LinkRef> links_;
  struct Actor {
    dart::dynamics::SkeletonPtr skeleton;
    bool present = false;
    bool colliding = false;  // in the DART world: present, and near a moving body
    double radius = 0;       // a sphere about its origin holding its collision shapes
    // Its last pose; given to its skeleton only while it is in the DART world (posing a
    // DART skeleton costs about 1 us, and most of a city's actors are far from any moving
    // body).
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    bool skeleton_stale = false;  // pose not yet given to the skeleton
  };
  std::vector<Actor> actors_;
  bool actors_posed_ = false;  // since the last gate_actors()
  // The moving bodies' reach (reach_) until the next decision, for the gates.
  void compute_reach();
  // Enters the present actors near a moving body into the DART world, the others out.
  void gate_actors();
  void pose_skeleton(Actor& a);
  std::unordered_map<std::string, dart::dynamics::SkeletonPtr> skeleton_by_model_;
  std::vector<std::string> link_names_;
  std::unordered_map<std::string, int> link_by_name_;
};

}  // namespace convoy::world
