// The moving part of the scene, kept from the datapacks that cross the coordinator: the road
// users (by RoadUser.id), the ego's trail and route, the signals' states. Fed by the live
// server's tap and the recorder (one state each); turned into messages by scene_json.h. The
// state is a function of the datapacks given (no clock), so a run gives the same scene.
//
// The ego: a RoadUser from one of `world_engines` (the world engine publishes each ego model
// as `<model>::road_user`), or from any datapack named `*::road_user`.
// Road users leave the scene when they say they are absent, or when the set that listed them
// (a RoadUsers datapack, a JSON list) no longer does; they are then among `deleted()` until
// clear_deleted().
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "convoy/road_users.pb.h"
#include "datapack/datapack.h"
#include "scene/scene_content.h"
#include "scene/scene_map.h"

namespace convoy::scene {

struct SceneOptions {
  std::set<std::string> world_engines;
  double trail_seconds = 60;  // how much of the ego's past the trail keeps
  double trail_step_m = 0.5;  // least distance between the trail's points
  std::vector<Point3> route;  // the ego's route when the config gives one
};

struct SceneUser {
  data::RoadUser state;
  bool ego = false;
  std::string source;  // "<engine>/<datapack>"
};

struct TrailPoint {
  Point3 p;
  int64_t time_ns = 0;
};

class SceneState {
 public:
  explicit SceneState(SceneOptions options = {});

  // Takes what a datapack from `engine` says (scene_content.h). Returns whether the scene
  // changed.
  bool ingest(const std::string& engine, const datapack::View& dp, int64_t time_ns);
  void apply(const std::string& source, bool from_world, const SceneContent& content,
             int64_t time_ns);

  const std::map<std::string, SceneUser>& users() const { return users_; }
  const std::set<std::string>& deleted() const { return deleted_; }
  void clear_deleted() { deleted_.clear(); }
  const std::map<std::string, std::string>& signals() const { return signals_; }
  const std::deque<TrailPoint>& trail() const { return trail_; }
  const std::vector<Point3>& route() const { return route_; }
  // The ego (the first by id), or nullptr.
  const SceneUser* ego() const;
  // Nothing taken in yet that the scene would show.
  bool empty() const { return users_.empty() && deleted_.empty() && signals_.empty(); }

 private:
  void upsert(const std::string& source, bool ego, const data::RoadUser& u, int64_t time_ns);
  void remove(const std::string& id);
  void extend_trail(const data::RoadUser& u, int64_t time_ns);

  SceneOptions options_;
  std::map<std::string, SceneUser> users_;
  std::set<std::string> deleted_;
  std::map<std::string, std::string> signals_;
  std::deque<TrailPoint> trail_;
  std::vector<Point3> route_;
};

// When a scene update is due: at most `hz` per simulated second, each for a loop cycle that is
// complete (the previous simulated time, once a datapack of a later time arrives).
class ScenePacer {
 public:
  explicit ScenePacer(double hz) : hz_(hz) {}
  // Call before taking in a datapack of `time_ns`; returns the time of an update to send now.
  std::optional<int64_t> due(int64_t time_ns, bool have_scene);

 private:
  double hz_;
  int64_t current_ns_ = -1, last_ns_ = -1;
};

}  // namespace convoy::scene
