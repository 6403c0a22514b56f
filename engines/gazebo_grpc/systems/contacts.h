// Contacts: the `collisions` datapack, every contact so far between two of the world's
// models (not the ground) and the actors.
//
// Datapacks:
//   collisions  JSON list of {"t", "a", "b", "class_a", "class_b", "relative_speed_mps"},
//               read: names in sorted order, t the engine's time of the step.
// After every physics step (post_update) it reads the physics' contact pairs; the actors
// system adds its actors as entities and reports their overlaps (note_contact). A pair is
// recorded when it starts touching, once: again only after kContactGap seconds apart. The
// relative speed is the difference of the two velocities at the start of the contact (a
// model's: its root body's; an actor's: from its messages).
#pragma once

#include <Eigen/Core>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "world_system.h"

namespace dart::dynamics {
class Skeleton;
}

namespace convoy::world {

class Contacts final : public WorldSystem {
 public:
  // A contact between two entities counts as new when they have not touched for this long
  // (s): bodies resting against each other make and break contact from step to step.
  static constexpr double kContactGap = 0.5;

  // What takes part: a world model (velocity from its skeleton's root body, null for a
  // static one) or an actor (velocity from its messages: a pointer that stays valid).
  struct Entity {
    std::string name, cls;
    const dart::dynamics::Skeleton* skeleton = nullptr;
    const Eigen::Vector3d* velocity = nullptr;
  };

  const char* name() const override { return "contacts"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  std::vector<ProvidedDataPack> provides() const override;
  void get_datapack(const std::string& name, datapack::Builder& out) override;
  void post_update(double dt) override;
  void reset() override;

  // Entities are keyed by their physics skeleton.
  void add_entity(const void* key, Entity entity);
  // Two entities touch now (keys as given to add_entity; the pair is remembered in this
  // order); records the contact if it is new.
  void note_contact(const void* a, const void* b);
  const nlohmann::json& records() const { return records_; }

 private:
  void add_world_models();
  Eigen::Vector3d velocity_of(const Entity& e) const;

  const WorldContext* ctx_ = nullptr;
  std::unordered_map<const void*, Entity> entity_;
  std::map<std::pair<const void*, const void*>, double> last_touched_;  // physics time (s)
  nlohmann::json records_ = nlohmann::json::array();
  // post_update's, reused
  std::vector<std::pair<const dart::dynamics::Skeleton*, const dart::dynamics::Skeleton*>> pairs_;
  struct Found {
    const void *ka, *kb;
    const Entity *a, *b;
  };
  std::vector<Found> found_;
};

}  // namespace convoy::world
