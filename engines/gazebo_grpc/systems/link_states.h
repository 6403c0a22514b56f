// Link states: NRP's Gazebo link plugin (NRPGazeboGrpcLinkControllerPlugin) exposes every
// link of its model.
//
// Datapacks (each link under two names):
//   <link plugin>::<link>, <model>::<link>  GazeboLinkDataPack, read: the link's position,
//       rotation (x y z w), linear and angular velocity in the world frame.
#pragma once

#include <string>
#include <unordered_map>
#include <vector>

#include "world_system.h"

namespace convoy::world {

class LinkStates final : public WorldSystem {
 public:
  const char* name() const override { return "link_states"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override { return provided_; }
  void get_datapack(const std::string& name, datapack::Builder& out) override;

 private:
  const WorldContext* ctx_ = nullptr;
  std::unordered_map<std::string, int> by_datapack_;  // -> physics link index
  std::vector<ProvidedDataPack> provided_;
};

}  // namespace convoy::world
