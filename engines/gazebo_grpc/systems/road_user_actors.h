// Road users as actors of the world (docs/road_users.md; the model library: actors.h).
//
// Config keys: ActorTimeout (s, default 1; 0: never), ActorModels (the actor-model table;
// default share/convoy/actors/actor_models.json).
// Datapacks, written (any name): a RoadUserDataPack or RoadUsersDataPack, or a JSON datapack
// holding a RoadUser dict, a list of them or {"users": [...]} (a python_json road user's).
// This system takes every such datapack that no system registered before it takes, so it is
// registered after those that take JSON datapacks by name (weather, traffic lights).
//
// Each road-user id is one actor: added the first time it is seen, posed at the start of
// every engine step (before_step) from its latest state, removed (hidden, out of the physics)
// when a state says `absent` or none has come for ActorTimeout, back when its id is sent
// again. After every engine step (after_step) the actors' boxes are compared (they do not
// collide with each other in the physics) and overlaps reported to the Contacts system: a
// sweep along x finds the pairs whose bounding circles can meet, so thousands of actors cost
// about N log N, not N^2; the pairs are then taken in the order of their indices, as a loop
// over every pair would (docs/road_users.md, Pooled road users).
#pragma once

#include <Eigen/Geometry>
#include <deque>
#include <memory>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "actors.h"
#include "convoy/road_users.pb.h"
#include "world_system.h"

namespace convoy::world {

class Contacts;

class RoadUserActors final : public WorldSystem {
 public:
  // One actor as the world holds it.
  struct Actor {
    std::string id, category, cls;
    int physics = -1, camera = -1;
    bool present = false;
    int64_t last_seen_ns = 0;
    int64_t created_ns = -1;                                 // the step it first appeared in
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // the model's frame
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    Eigen::Vector3d half = Eigen::Vector3d::Zero();  // half the box, about the model's frame
    double length_offset = 0;  // its box centre ahead of the reference point (library's)
    int walk_poses = 0;        // an animated walker's walking cycle poses (then the camera's
    bool stand = false;        // pose walk_poses is its standing model, if it has one)
    std::string shape;         // its model and size: the key under which it can be reused
    bool free = false;         // removed, waiting in free_ for a new id of its shape
  };

  const char* name() const override { return "actors"; }
  void configure(const WorldContext& ctx, const nlohmann::json& config) override;
  bool set_datapack(const datapack::View& dp) override;
  void before_step() override;
  void after_step() override;
  void reset() override;

  // The actor of road-user `id`, or null if it never came.
  const Actor* actor(const std::string& id) const;
  // How many actors the world holds (present or kept for reuse).
  size_t actor_count() const { return actors_.size(); }

 private:
  Actor& actor_for(const std::string& dp_name, const data::RoadUser& u);
  void pose_actor(const std::string& dp_name, const data::RoadUser& u, int64_t now);
  Actor& add_actor(const std::string& dp_name, const data::RoadUser& u);
  Actor* reuse_actor(const std::string& shape, const data::RoadUser& u);
  void set_present(Actor& a, bool present);
  static bool boxes_overlap(const Actor& a, const Actor& b);
  void note_overlap(const Actor& a, const Actor& b, int64_t now);
  // The pairs of present actors (i < j, in order) whose bounding circles overlap in x and y.
  void candidate_pairs();

  // The road users received since the last step, by datapack in the order they came: a
  // RoadUsers message kept from step to step (its users' memory reused).
  struct Batch {
    std::string dp_name;
    data::RoadUsers users;
  };
  Batch& next_batch(const std::string& dp_name);
  // after_step's, reused: the actors' bounding circles along x, and the candidate pairs.
  struct Span {
    double lo, hi;  // along x
    double y, r;    // the centre's y, the circle's radius
    size_t index;
  };

  const WorldContext* ctx_ = nullptr;
  Contacts* contacts_ = nullptr;  // null: no contacts system
  double timeout_s_ = 1.0;
  std::string table_;
  std::unique_ptr<ActorLibrary> library_;  // loaded with the first actor
  std::vector<Batch> batches_;             // batches_[0, pending_) hold this step's road users
  size_t pending_ = 0;
  std::vector<Span> spans_;
  std::vector<std::pair<size_t, size_t>> pairs_;
  std::deque<Actor> actors_;  // a deque: the contacts system keeps pointers to velocities
  std::unordered_map<std::string, size_t> by_id_;
  std::unordered_map<std::string, std::deque<size_t>> free_;  // by shape, oldest removed first
  std::set<std::string> warned_models_;
};

}  // namespace convoy::world
