#include "scene/scene_state.h"

#include <cmath>

namespace convoy::scene {

namespace {

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

SceneState::SceneState(SceneOptions options)
    : options_(std::move(options)), route_(options_.route) {}

bool SceneState::ingest(const std::string& engine, const datapack::View& dp, int64_t time_ns) {
  const SceneContent content = read_scene_content(dp);
  if (content.empty()) return false;
  const std::string& name = dp.id().name();
  const bool from_world =
      options_.world_engines.count(engine) > 0 || ends_with(name, "::road_user");
  apply(engine + "/" + name, from_world, content, time_ns);
  return true;
}

void SceneState::apply(const std::string& source, bool from_world, const SceneContent& content,
                       int64_t time_ns) {
  std::set<std::string> listed;
  for (const data::RoadUser& u : content.users) {
    const std::string id = u.id().empty() ? source : u.id();
    if (u.absent()) {
      remove(id);
      continue;
    }
    listed.insert(id);
    upsert(source, from_world, u, time_ns);
  }
  if (content.user_set) {
    for (auto it = users_.begin(); it != users_.end();) {
      if (it->second.source == source && !listed.count(it->first)) {
        deleted_.insert(it->first);
        it = users_.erase(it);
      } else {
        ++it;
      }
    }
  }
  if (content.has_signals)
    for (const auto& [id, state] : content.signals) signals_[id] = state;
  if (!content.route.empty()) route_ = content.route;
}

void SceneState::upsert(const std::string& source, bool ego, const data::RoadUser& u,
                        int64_t time_ns) {
  const std::string id = u.id().empty() ? source : u.id();
  SceneUser& su = users_[id];
  su.state = u;
  if (u.id().empty()) su.state.set_id(id);
  su.ego = ego;
  su.source = source;
  deleted_.erase(id);
  if (ego) {
    const SceneUser* first = this->ego();
    if (first && first->state.id() == id) extend_trail(u, time_ns);
  }
}

void SceneState::remove(const std::string& id) {
  if (users_.erase(id)) deleted_.insert(id);
}

void SceneState::extend_trail(const data::RoadUser& u, int64_t time_ns) {
  const Point3 p{u.x(), u.y(), u.z()};
  if (trail_.empty() ||
      std::hypot(p.x - trail_.back().p.x, p.y - trail_.back().p.y) >= options_.trail_step_m)
    trail_.push_back({p, time_ns});
  const auto keep_ns = static_cast<int64_t>(options_.trail_seconds * 1e9);
  while (trail_.size() > 1 && time_ns - trail_.front().time_ns > keep_ns) trail_.pop_front();
}

const SceneUser* SceneState::ego() const {
  for (const auto& [id, u] : users_)
    if (u.ego) return &u;
  return nullptr;
}

std::optional<int64_t> ScenePacer::due(int64_t time_ns, bool have_scene) {
  if (hz_ <= 0 || time_ns <= current_ns_) return std::nullopt;
  const int64_t prev = current_ns_;
  current_ns_ = time_ns;
  if (prev < 0 || !have_scene) return std::nullopt;
  const auto period = static_cast<int64_t>(std::llround(1e9 / hz_));
  if (last_ns_ >= 0 && prev - last_ns_ < period) return std::nullopt;
  last_ns_ = prev;
  return prev;
}

}  // namespace convoy::scene
