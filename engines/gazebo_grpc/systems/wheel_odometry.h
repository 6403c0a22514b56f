// Wheel odometry datapacks: the world's wheel odometers (<sensor type="custom"> with a
// convoy_wheel_odometry plugin, radar_desc.h, or a config "Sensors" entry of Type
// wheel_odometry), src/wheel_odometry fed with the model's rear wheel joints' speeds (and its
// steering joint's angle) every physics step.
//
// Config keys: GazeboRNGSeed (odometer k of the world draws its scale error and slip from
// streams of (GazeboRNGSeed, k)), EngineTimestep (an update rate above its rate is refused).
// A joint the model does not have is refused: "model 'M' link 'L' sensor 'S': <left_joint>:
// no joint 'J' ...".
// Datapacks (NRP-Core's scoped name, and the plugin's name if it has one):
//   <model>::<link>::<sensor>, <plugin>::<sensor>   OdometryDataPack (convoy.data.Odometry)
// The state is integrated every physics step from the start and read out after every engine
// step at which the odometer is due (update_rate; 0: every step); unchanged() until then.
#pragma once

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "wheel_odometry/odometry_model.h"
#include "world_description.h"
#include "world_system.h"

namespace convoy::world {

class WheelOdometry final : public WorldSystem {
 public:
  const char* name() const override { return "wheel_odometry"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  bool unchanged(const std::string& name) override;
  void post_update(double dt) override;
  void after_step() override;
  void reset() override;

  size_t count() const { return sensors_.size(); }
  const wheel_odometry::OdometryState& reading(size_t i) const { return sensors_[i].reading; }

 private:
  struct Sensor {
    const OdometryDesc* desc = nullptr;
    int left = -1, right = -1, steering = -1;  // physics joint indices (steering -1: none)
    std::optional<wheel_odometry::OdometryModel> model;
    wheel_odometry::OdometryState reading;
    double time = 0, next_update = 0;
    uint64_t readings = 0;
  };
  void read(Sensor& s);

  const WorldContext* ctx_ = nullptr;
  std::vector<Sensor> sensors_;
  std::unordered_map<std::string, size_t> by_datapack_;
  std::vector<ProvidedDataPack> provided_;
  std::unordered_map<std::string, uint64_t> sent_;
};

}  // namespace convoy::world
