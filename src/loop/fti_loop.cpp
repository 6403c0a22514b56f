#include "loop/fti_loop.h"

#include <algorithm>

#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"

namespace convoy::loop {

namespace {
std::string key(const std::string& engine, const std::string& name) {
  std::string k;
  k.reserve(engine.size() + name.size() + 1);
  k += engine;
  k += '\0';
  k += name;
  return k;
}
}  // namespace

FtiLoop::FtiLoop(std::vector<EngineHandle*> engines, python::FunctionRuntime& runtime,
                 const std::vector<python::LoadedFunction>& functions)
    : engines_(std::move(engines)), runtime_(runtime), functions_(functions) {
  for (size_t i = 0; i < engines_.size(); ++i) {
    by_name_[engines_[i]->name()] = engines_[i];
    index_[engines_[i]->name()] = i;
  }
  // Which datapacks each engine must hand over after its steps.
  for (const auto& fn : functions_) {
    for (const auto& in : fn.inputs) {
      if (in.preprocessed) continue;
      auto* e = by_name_.at(in.engine);
      bool known = std::any_of(e->wanted.begin(), e->wanted.end(),
                               [&](const engine::DataPackId& id) { return id.name() == in.datapack; });
      if (!known) {
        engine::DataPackId id;
        id.set_name(in.datapack);
        id.set_engine_name(in.engine);
        e->wanted.push_back(id);
      }
    }
  }
  source_.engine_datapack = [this](const std::string& engine, const std::string& name)
      -> const engine::DataPack* {
    auto it = pool_.find(key(engine, name));
    return it == pool_.end() ? nullptr : &it->second;
  };
}

void FtiLoop::set_step_log(std::FILE* csv) {
  csv_ = csv;
  if (!csv_) return;
  std::fprintf(csv_, "cycle,sim_time_s,cycle_wall_us");
  for (auto* e : engines_) {
    std::fprintf(csv_, ",%s_step_us,%s_roundtrip_us", e->name().c_str(), e->name().c_str());
  }
  std::fprintf(csv_, "\n");
}

void FtiLoop::prime() {
  for (auto* e : engines_) {
    if (e->wanted.empty()) continue;
    engine::Request request;
    for (const auto& id : e->wanted) *request.mutable_get_datapacks()->add_ids() = id;
    e->start(request, "GetDataPacks");
  }
  for (auto* e : engines_) {
    if (!e->busy()) continue;
    engine::Reply reply;
    e->finish(&reply);
    for (auto& dp : *reply.mutable_get_datapacks()->mutable_datapacks()) {
      std::string k = key(e->name(), dp.id().name());
      pool_[k] = std::move(dp);
    }
  }
  for (size_t i = 0; i < engines_.size(); ++i) queue_.emplace(engines_[i]->time_ns, i);
}

void FtiLoop::take_outputs(EngineHandle& e, engine::StepReply* reply) {
  e.time_ns = reply->time_ns();
  e.last_compute_ns = reply->compute_ns();
  for (auto& dp : *reply->mutable_outputs()) {
    auto& slot = pool_[key(e.name(), dp.id().name())];
    slot.Swap(&dp);
  }
}

void FtiLoop::route(std::vector<engine::DataPack>& outputs, const python::LoadedFunction& fn) {
  for (auto& dp : outputs) {
    auto it = by_name_.find(dp.id().engine_name());
    if (it == by_name_.end()) {
      throw FunctionError(fn.label() + " returned datapack '" + dp.id().name() +
                          "' for unknown engine '" + dp.id().engine_name() + "'");
    }
    it->second->pending_inputs.push_back(std::move(dp));
  }
  outputs.clear();
}

void FtiLoop::run_functions(const std::vector<EngineHandle*>& due) {
  runtime_.begin_cycle();
  auto is_due = [&](const std::string& engine) {
    return std::any_of(due.begin(), due.end(), [&](EngineHandle* e) { return e->name() == engine; });
  };
  for (const auto& fn : functions_) {
    if (fn.preprocessing && is_due(fn.engine)) runtime_.run_preprocessing(fn, source_);
  }
  for (const auto& fn : functions_) {
    if (fn.preprocessing || !is_due(fn.engine)) continue;
    runtime_.run_transceiver(fn, source_, &outputs_);
    route(outputs_, fn);
  }
}

void FtiLoop::write_row(const std::vector<EngineHandle*>& due, int64_t cycle_wall_ns) {
  if (!csv_) return;
  std::fprintf(csv_, "%llu,%.9g,%.3f", static_cast<unsigned long long>(cycles_),
               static_cast<double>(sim_time_ns_) * 1e-9, static_cast<double>(cycle_wall_ns) * 1e-3);
  for (auto* e : engines_) {
    bool stepped = std::find(due.begin(), due.end(), e) != due.end() && e->last_compute_ns >= 0;
    if (stepped) {
      std::fprintf(csv_, ",%.3f,%.3f", static_cast<double>(e->last_compute_ns) * 1e-3,
                   static_cast<double>(e->last_roundtrip_ns) * 1e-3);
    } else {
      std::fprintf(csv_, ",,");
    }
  }
  std::fputc('\n', csv_);
}

void FtiLoop::run(int64_t until_ns) {
  std::vector<EngineHandle*> due;
  engine::Reply reply;
  engine::Request request;
  int64_t last_cycle_ns = now_ns();
  while (!queue_.empty()) {
    const int64_t next = queue_.begin()->first;
    if (until_ns > 0 && next > until_ns) break;
    due.clear();
    while (!queue_.empty() && queue_.begin()->first == next) {
      due.push_back(engines_[queue_.begin()->second]);
      queue_.erase(queue_.begin());
    }
    std::sort(due.begin(), due.end(), [&](EngineHandle* a, EngineHandle* b) {
      return index_[a->name()] < index_[b->name()];
    });
    for (auto* e : due) {
      e->last_compute_ns = -1;
      if (!e->busy()) continue;
      reply.Clear();
      e->finish(&reply);
      take_outputs(*e, reply.mutable_step());
      e->time_ns = next;  // the schedule, not the engine's clock, drives the loop
    }
    sim_time_ns_ = next;
    run_functions(due);
    if (interrupted()) break;
    for (auto* e : due) {
      const int64_t ts = e->config().timestep_ns;
      if (until_ns > 0 && next + ts > until_ns) continue;
      request.Clear();
      auto* step = request.mutable_step();
      step->set_duration_ns(ts);
      for (auto& dp : e->pending_inputs) step->add_inputs()->Swap(&dp);
      e->pending_inputs.clear();
      for (const auto& id : e->wanted) *step->add_wanted() = id;
      e->start(request, "Step");
      queue_.emplace(next + ts, index_[e->name()]);
    }
    int64_t t = now_ns();
    write_row(due, t - last_cycle_ns);
    last_cycle_ns = t;
    ++cycles_;
  }
}

}  // namespace convoy::loop
