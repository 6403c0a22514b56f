#include "systems/contacts.h"

#include <algorithm>

#include "datapack/json.h"
#include "physics_world.h"
#include "world_description.h"

namespace convoy::world {

void Contacts::configure(const WorldContext& ctx, const nlohmann::json& config) {
  ctx_ = &ctx;
  add_world_models();
}

std::vector<ProvidedDataPack> Contacts::provides() const { return {{"collisions", "json"}}; }

void Contacts::get_datapack(const std::string& name, datapack::Builder& out) {
  if (name == "collisions") datapack::write_json(out, records_);
}

void Contacts::reset() {
  entity_.clear();
  last_touched_.clear();
  records_ = nlohmann::json::array();
  add_world_models();
}

void Contacts::add_world_models() {
  for (const auto& m : ctx_->desc->models) {
    if (is_ground(m)) continue;
    if (const auto* skel = ctx_->physics->model_skeleton(m.name))
      entity_[skel] = {m.name, class_of(m), m.is_static ? nullptr : skel, nullptr};
  }
}

void Contacts::add_entity(const void* key, Entity entity) {
  entity_[key] = std::move(entity);
  // A key given again is a new entity (an actor taken over): it has touched nothing yet.
  std::erase_if(last_touched_,
                [key](const auto& kv) { return kv.first.first == key || kv.first.second == key; });
}

Eigen::Vector3d Contacts::velocity_of(const Entity& e) const {
  if (e.velocity) return *e.velocity;
  if (e.skeleton && e.skeleton->getNumBodyNodes() > 0)
    return e.skeleton->getRootBodyNode()->getLinearVelocity();
  return Eigen::Vector3d::Zero();
}

void Contacts::note_contact(const void* a_key, const void* b_key) {
  const Entity& a = entity_.at(a_key);
  const Entity& b = entity_.at(b_key);
  const double t = ctx_->physics->time();
  auto key = std::make_pair(a_key, b_key);
  auto it = last_touched_.find(key);
  const bool fresh = it == last_touched_.end() || t - it->second > kContactGap;
  last_touched_[key] = t;
  if (!fresh) return;
  const Entity& first = a.name <= b.name ? a : b;
  const Entity& second = a.name <= b.name ? b : a;
  records_.push_back({{"t", ctx_->time_s()},
                      {"a", first.name},
                      {"b", second.name},
                      {"class_a", first.cls},
                      {"class_b", second.cls},
                      {"relative_speed_mps", (velocity_of(a) - velocity_of(b)).norm()}});
}

void Contacts::post_update(double dt) {
  ctx_->physics->contact_pairs(&pairs_);
  // By name, not by address: records of one step come in the same order in every run.
  found_.clear();
  for (const auto& [sa, sb] : pairs_) {
    auto ea = entity_.find(sa), eb = entity_.find(sb);
    if (ea == entity_.end() || eb == entity_.end()) continue;  // the ground
    found_.push_back({sa, sb, &ea->second, &eb->second});
  }
  std::sort(found_.begin(), found_.end(), [](const Found& x, const Found& y) {
    return std::minmax(x.a->name, x.b->name) < std::minmax(y.a->name, y.b->name);
  });
  for (const auto& f : found_) note_contact(f.ka, f.kb);
}

}  // namespace convoy::world
