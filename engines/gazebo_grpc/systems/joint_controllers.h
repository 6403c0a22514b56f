// Joint controllers: NRP's Gazebo joint controller plugin (NRPGazeboGrpcJointControllerPlugin,
// world_description.h's PidDesc). Each joint of the plugin gets a PID with Gazebo's semantics
// (joint_pid.h) holding its SDF Target until a datapack sets another.
//
// Datapacks (each joint under two names):
//   <joint plugin>::<joint>, <model>::<joint>  GazeboJointDataPack, written and read. Written:
//       the target (the position for a position controller, the velocity for a velocity
//       controller); a non-zero effort is added as a feed-forward effort. Read: the joint's
//       position, velocity and effort.
// Each physics step (update, after the brakes' pre_update) it sets each joint's effort; a
// joint whose wheel brakes (Brakes::braking) gets none and its PID starts afresh.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "joint_pid.h"
#include "world_system.h"

namespace convoy::world {

class Brakes;

class JointControllers final : public WorldSystem {
 public:
  const char* name() const override { return "joint_controllers"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  bool set_datapack(const datapack::View& dp) override;
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  void update(double dt) override;
  void reset() override;

  // The target of the controller of datapack `name` (NaN: no such controller).
  double target(const std::string& name) const;
  // The velocity controllers of physics joint `joint` hold `velocity` from now on and after a
  // reset, in place of the SDF's Target (a wheel spinning from the start, initial_speeds.h).
  void hold_velocity(int joint, double velocity);

 private:
  struct Controller {
    int joint;
    bool velocity;
    double target;
    JointPid pid;
    double feed_forward;
    double initial_target;  // the SDF's Target, or hold_velocity()'s
  };
  const WorldContext* ctx_ = nullptr;
  const Brakes* brakes_ = nullptr;  // null: no brakes system
  std::vector<Controller> controllers_;
  std::unordered_map<std::string, size_t> by_datapack_;
  std::vector<ProvidedDataPack> provided_;
};

}  // namespace convoy::world
