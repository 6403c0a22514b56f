#include "world_systems.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace convoy::world {

WorldSystems::WorldSystems(WorldDesc desc, uint64_t seed, const std::string& engine)
    : desc_(std::move(desc)), seed_(seed) {
  ctx_.engine = engine;
  ctx_.desc = &desc_;
  ctx_.systems = &systems_;
  make_world();
}

void WorldSystems::make_world() {
  KeptCameras kept = cameras_ ? cameras_->release_kept() : KeptCameras{};
  cameras_.reset();
  const auto t0 = std::chrono::steady_clock::now();
  physics_ = std::make_unique<PhysicsWorld>(desc_);
  const auto t1 = std::chrono::steady_clock::now();
  cameras_ =
      std::make_unique<CameraSensors>(desc_, *physics_, seed_, &mesh_files_, std::move(kept));
  physics_s_ = std::chrono::duration<double>(t1 - t0).count();
  cameras_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  ctx_.physics = physics_.get();
  ctx_.cameras = cameras_.get();
}

std::vector<ProvidedDataPack> WorldSystems::configure(const nlohmann::json& config) {
  std::vector<ProvidedDataPack> all;
  std::vector<WorldSystem*> by;
  for (auto& s : systems_) s->configure(ctx_, config);
  for (auto& s : systems_)
    for (auto& p : s->provides()) {
      all.push_back(std::move(p));
      by.push_back(s.get());
    }
  std::vector<size_t> order(all.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  auto rank = [&](size_t i) {
    return all[i].model < 0 ? desc_.models.size() : static_cast<size_t>(all[i].model);
  };
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return rank(a) < rank(b); });
  std::vector<ProvidedDataPack> sorted;
  for (size_t i : order) {
    provider_.try_emplace(all[i].name, by[i]);
    sorted.push_back(std::move(all[i]));
  }
  return sorted;
}

int64_t WorldSystems::step(int64_t duration_ns) {
  const double dt = physics_->step_size();
  // As many physics steps as keep the physics clock within half a step of the engine's,
  // so that a timestep that is not a multiple of max_step_size (1/30 s, say) does not drift.
  ctx_.time_ns += duration_ns;
  const int64_t dt_ns = std::max<int64_t>(1, std::llround(dt * 1e9));
  const int64_t n = (ctx_.time_ns + dt_ns / 2) / dt_ns - physics_steps_;
  physics_steps_ += n;
  for (auto& s : systems_) s->before_step();
  for (int64_t k = 0; k < n; ++k) {
    for (auto& s : systems_) s->pre_update(dt);
    for (auto& s : systems_) s->update(dt);
    physics_->step();
    for (auto& s : systems_) s->post_update(dt);
  }
  for (auto& s : systems_) s->after_step();
  return ctx_.time_ns;
}

void WorldSystems::set_datapack(const datapack::View& dp) {
  for (auto& s : systems_)
    if (s->set_datapack(dp)) return;
  throw std::runtime_error("engine '" + ctx_.engine + "' has no writable datapack '" +
                           dp.id().name() + "' (joint datapacks are <joint plugin>::<joint>)");
}

void WorldSystems::get_datapack(const std::string& name, datapack::Builder& out) {
  if (auto it = provider_.find(name); it != provider_.end()) it->second->get_datapack(name, out);
}

bool WorldSystems::unchanged(const std::string& name) {
  auto it = provider_.find(name);
  return it != provider_.end() && it->second->unchanged(name);
}

void WorldSystems::reset() {
  make_world();
  ctx_.time_ns = 0;
  physics_steps_ = 0;
  for (auto& s : systems_) s->reset();
}

}  // namespace convoy::world
