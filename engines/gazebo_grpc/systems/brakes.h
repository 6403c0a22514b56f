// Brakes and ABS: Convoy's brake plugin (ConvoyBrakePlugin.so, see world_description.h's
// BrakePluginDesc) on the wheels' joints.
//
// Datapacks (one per braked joint):
//   <brake plugin>::<joint>  GazeboJointDataPack, written and read. The effort written is the
//                            brake torque (Nm, clamped to MaxTorque; < 0 is an error); the
//                            effort read is the torque the ABS applies.
// Each physics step (pre_update) it sets each brake's Coulomb friction torque on its joint.
// With ABS, a PI controller per wheel holds its longitudinal slip at the plugin's <slip>:
// the torque falls while the wheel slips more, rises (never above the command) while it
// slips less; below 2 m/s, or without ABS, the full command applies. While a wheel brakes,
// its joint controller is idle (JointControllers asks braking()).
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "world_system.h"

namespace convoy::world {

class Brakes final : public WorldSystem {
 public:
  const char* name() const override { return "brakes"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  bool set_datapack(const datapack::View& dp) override;
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  void pre_update(double dt) override;
  void reset() override;

  // True while the brake on physics joint `joint` is commanded (torque > 0).
  bool braking(int joint) const;
  // The torque (Nm) the brake of datapack `name` applies now (-1: no such brake).
  double applied(const std::string& name) const;

 private:
  struct Brake {
    int joint = -1;
    double max_torque = 0, slip = 0.15;
    bool abs = true;
    double command = 0, applied = 0;  // Nm
    double radius = -1;               // m; -1: not yet found
    double last_command = 0;          // in the previous physics step
    double last_omega = 0;            // the wheel's spin (rad/s, forward) in the previous step
    double integral = 0;              // ABS: the PI controller's integral torque
  };
  void update_brake(Brake& b, double dt);
  double wheel_radius(Brake& b);  // found once, kept across resets (the same wheels)

  const WorldContext* ctx_ = nullptr;
  std::vector<Brake> brakes_;
  std::unordered_map<std::string, size_t> by_datapack_;
  std::vector<ProvidedDataPack> provided_;
};

}  // namespace convoy::world
