// The ego's state: each ego model published as a road user, so that agents and functions
// see the simulated vehicle as they see any other.
//
// Config key: EgoModels, the models' names (default: every moving model with a joint
// controller plugin). A name that is no model with a link is an error.
// Datapacks (one per ego):
//   <model>::road_user  RoadUserDataPack, read: id and model = the model's name, category =
//       its class, the pose and velocities of its first link (the reference point), speed
//       along that link's x, acceleration from the previous read, and the box of its
//       collision shapes in that link's frame (length, width, height, length_offset).
#pragma once

#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "world_system.h"

namespace convoy::world {

struct ModelDesc;

class EgoState final : public WorldSystem {
 public:
  const char* name() const override { return "ego_state"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override;
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  void reset() override;

  // The state of ego `model` now (as get_datapack writes it: a read sets the acceleration's
  // reference). Throws std::out_of_range for a model that is no ego.
  data::RoadUser state(const std::string& model);

 private:
  struct Ego {
    std::string name, cls, datapack;
    int link = -1;  // the model's first link: the reference point
    double length = 0, width = 0, height = 0, length_offset = 0;
    double speed = 0;  // at the last report, for the acceleration
    int64_t speed_ns = -1;
  };
  Ego make_ego(const ModelDesc& m) const;
  data::RoadUser state(Ego& e);  // (notes the speed for the next acceleration)

  const WorldContext* ctx_ = nullptr;
  std::vector<Ego> egos_;
};

}  // namespace convoy::world
