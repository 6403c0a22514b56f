// Initial speeds: a model of GazeboSDFModels with an InitSpeed (model_inserts.h) starts
// rolling: at configure and after each reset, every body of the model (and of its nested
// models) translates at InitSpeed along the x axis of its InitPose, and its wheels spin at
// InitSpeed / radius, so that it rolls on without a jolt. The wheels' velocity controllers
// (JointControllers, if registered before) hold that spin until a datapack sets another
// target.
//
// A wheel (find_wheels): a revolute or continuous joint of the model (not locked by equal
// limits) whose child link has a collision sphere, or a collision cylinder whose axis is
// within ~8 degrees of the joint's axis; its radius is the largest such shape's. It spins at
// ((up x heading) . axis) InitSpeed / radius, up and heading being the z and x axes of
// InitPose: rolling forward on the ground.
//
// Config key: GazeboSDFModels (its InitSpeed; the adapter loads the models). No datapacks.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

struct WheelDesc {
  std::string joint;     // scoped joint name
  Eigen::Vector3d axis;  // the joint's axis in the world, at load (unit)
  double radius;         // m
};

// The wheels of `model`, by the rule above, in the order of its joints.
std::vector<WheelDesc> find_wheels(const ModelDesc& model);

class InitialSpeeds final : public WorldSystem {
 public:
  const char* name() const override { return "initial_speeds"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  void reset() override { apply(); }

 private:
  struct Moving {
    std::string model;
    Eigen::Vector3d velocity;  // m/s, world frame
  };
  struct Spin {
    int joint;     // physics joint index
    double omega;  // rad/s
  };
  void apply() const;

  const WorldContext* ctx_ = nullptr;
  std::vector<Moving> models_;
  std::vector<Spin> spins_;
};

}  // namespace convoy::world
