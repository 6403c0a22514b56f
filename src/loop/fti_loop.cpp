#include "loop/fti_loop.h"

#include <algorithm>
#include <charconv>
#include <stdexcept>

#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "datapack/datapack.h"

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

// Adds `name` to the datapacks `e` hands over; false when it is there already.
bool add_wanted(EngineHandle& e, const std::string& name) {
  if (std::any_of(e.wanted.begin(), e.wanted.end(),
                  [&](const engine::DataPackId& id) { return id.name() == name; }))
    return false;
  engine::DataPackId& id = e.wanted.emplace_back();
  id.set_name(name);
  id.set_engine_name(e.name());
  return true;
}
}  // namespace

FtiLoop::FtiLoop(std::vector<EngineHandle*> engines, FunctionRunner& runner,
                 const std::vector<LoadedFunction>& functions, const LoadedFunction* status)
    : engines_(std::move(engines)), runner_(runner), functions_(functions), status_(status) {
  for (size_t i = 0; i < engines_.size(); ++i) {
    by_name_[engines_[i]->name()] = engines_[i];
    engines_[i]->index = i;
  }
  due_mask_.assign(engines_.size(), 0);
  for (const auto& fn : functions_) function_engine_.push_back(by_name_.at(fn.engine)->index);
  // Which datapacks each engine must hand over after its steps.
  std::vector<const LoadedFunction*> readers;
  for (const auto& fn : functions_) readers.push_back(&fn);
  if (status_) readers.push_back(status_);
  for (const LoadedFunction* fn : readers) {
    for (const auto& in : fn->inputs) {
      if (in.preprocessed || in.kind != InputKind::kDataPack) continue;
      add_wanted(*by_name_.at(in.engine), in.datapack);
    }
  }
  source_.engine_datapack = [this](const std::string& engine,
                                   const std::string& name) -> const engine::DataPack* {
    auto it = pool_.find(key(engine, name));
    return it == pool_.end() ? nullptr : &it->second.datapack;
  };
  source_.updated = [this](const std::string& engine, const std::string& name) {
    auto it = pool_.find(key(engine, name));
    return it != pool_.end() && it->second.cycle == cycles_;
  };
  source_.reader_for = [this](const std::string& engine) -> const datapack::BlobReader* {
    auto it = by_name_.find(engine);
    return it == by_name_.end() ? nullptr : it->second->blob_reader();
  };
  source_.writer_for = [this](const std::string& engine) -> datapack::BlobWriter* {
    auto it = by_name_.find(engine);
    return it == by_name_.end() ? nullptr : it->second->blob_writer();
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
  std::fflush(csv_);
}

void FtiLoop::keep_observation(const engine::DataPack& dp, const std::string& engine) {
  if (dp.payload_case() == engine::DataPack::PAYLOAD_NOT_SET) return;
  observations_.push_back(dp);
  if (dp.blobs_size() == 0) return;
  // The blobs may sit in the engine's arena, which it reuses: the copy carries them inline.
  const datapack::BlobReader* reader = source_.reader_for(engine);
  datapack::View view(dp, reader ? *reader : datapack::inline_blob_reader());
  auto& kept = observations_.back();
  for (int i = 0; i < dp.blobs_size(); ++i) {
    auto* blob = kept.mutable_blobs(i);
    std::string_view bytes = view.blob(static_cast<uint32_t>(i));
    blob->set_inline_(bytes.data(), bytes.size());
    blob->set_in_shm(false);
    blob->set_shm_offset(0);
    blob->set_size(bytes.size());
  }
}

std::vector<engine::DataPack> FtiLoop::take_observations() {
  std::vector<engine::DataPack> out;
  out.swap(observations_);
  return out;
}

void FtiLoop::add_input(engine::DataPack datapack) {
  auto it = by_name_.find(datapack.id().engine_name());
  if (it == by_name_.end()) {
    std::string list;
    for (auto* e : engines_) list += (list.empty() ? "" : ", ") + e->name();
    throw std::invalid_argument("datapack '" + datapack.id().name() + "' is for unknown engine '" +
                                datapack.id().engine_name() + "' (engines: " + list + ")");
  }
  auto& pending = it->second->pending_inputs;
  pending.insert(pending.begin(), std::move(datapack));
}

bool FtiLoop::also_want(const std::string& engine, const std::string& datapack) {
  auto it = by_name_.find(engine);
  if (it == by_name_.end())
    throw std::invalid_argument("datapack '" + datapack + "' wanted of unknown engine '" + engine +
                                "'");
  if (!add_wanted(*it->second, datapack)) return false;
  extra_.insert(key(engine, datapack));
  return true;
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
      if (keep_observations_ && !extra_.count(k)) keep_observation(dp, e->name());
      if (tap_) tap_->from_engine(e->name(), dp, *e->blob_reader(), cycles_, sim_time_ns_);
      auto& slot = pool_[k];
      slot.datapack.Swap(&dp);
      slot.cycle = 0;
    }
  }
  for (size_t i = 0; i < engines_.size(); ++i) queue_.emplace(engines_[i]->time_ns, i);
}

void FtiLoop::take_outputs(EngineHandle& e, engine::StepReply* reply, int64_t time_ns) {
  e.time_ns = reply->time_ns();
  e.last_compute_ns = reply->compute_ns();
  for (auto& dp : *reply->mutable_outputs()) {
    if (tap_) tap_->from_engine(e.name(), dp, *e.blob_reader(), cycles_, time_ns);
    auto& slot = pool_[key(e.name(), dp.id().name())];
    slot.datapack.Swap(&dp);
    slot.cycle = cycles_;
  }
}

void FtiLoop::route(std::vector<engine::DataPack>& outputs, const LoadedFunction& fn) {
  for (auto& dp : outputs) {
    auto it = by_name_.find(dp.id().engine_name());
    if (it == by_name_.end()) {
      throw FunctionError(fn.label() + " returned datapack '" + dp.id().name() +
                          "' for unknown engine '" + dp.id().engine_name() + "'");
    }
    if (tap_)
      tap_->to_engine(it->first, dp, *it->second->sent_blob_reader(), fn, cycles_, sim_time_ns_);
    it->second->pending_inputs.push_back(std::move(dp));
  }
  outputs.clear();
}

void FtiLoop::run_functions() {
  source_.iteration = cycles_;
  source_.time_ns = sim_time_ns_;
  runner_.begin_cycle();
  for (size_t i = 0; i < functions_.size(); ++i) {
    if (functions_[i].preprocessing && due_mask_[function_engine_[i]])
      runner_.run_preprocessing(functions_[i], source_);
  }
  for (size_t i = 0; i < functions_.size(); ++i) {
    const auto& fn = functions_[i];
    if (fn.preprocessing || !due_mask_[function_engine_[i]]) continue;
    runner_.run_transceiver(fn, source_, &outputs_);
    route(outputs_, fn);
  }
  if (graph_) {
    due_names_.clear();
    for (auto* e : due_) due_names_.push_back(e->name());
    runner_.run_graph(due_names_, source_, &outputs_);
    route(outputs_, *graph_);
  }
  if (status_) {
    const size_t before = observations_.size();
    done_ = runner_.run_status(*status_, source_, &observations_);
    if (!keep_observations_) observations_.resize(before);
  }
}

namespace {
// Appends ns as microseconds with three decimals ("12.345"), without printf's float path.
void append_us(std::string* row, int64_t ns) {
  char buf[32];
  auto [p, ec] = std::to_chars(buf, buf + sizeof buf, ns / 1000);
  *p++ = '.';
  int64_t frac = ns % 1000;
  *p++ = static_cast<char>('0' + frac / 100);
  *p++ = static_cast<char>('0' + frac / 10 % 10);
  *p++ = static_cast<char>('0' + frac % 10);
  row->append(buf, p);
}
}  // namespace

FtiLoop::~FtiLoop() { flush_rows(); }

void FtiLoop::flush_rows() {
  if (!csv_ || row_.empty()) return;
  std::fwrite(row_.data(), 1, row_.size(), csv_);
  std::fflush(csv_);
  row_.clear();
}

void FtiLoop::write_row(int64_t cycle_wall_ns) {
  if (!csv_) return;
  char buf[32];
  row_.append(buf, std::to_chars(buf, buf + sizeof buf, cycles_).ptr);
  row_ += ',';
  row_.append(buf, std::to_chars(buf, buf + sizeof buf, sim_time_ns_ / 1'000'000'000).ptr);
  row_ += '.';
  std::snprintf(buf, sizeof buf, "%09lld", static_cast<long long>(sim_time_ns_ % 1'000'000'000));
  row_ += buf;
  row_ += ',';
  append_us(&row_, cycle_wall_ns);
  for (size_t i = 0; i < engines_.size(); ++i) {
    const auto* e = engines_[i];
    row_ += ',';
    if (due_mask_[i] && e->last_compute_ns >= 0) {
      append_us(&row_, e->last_compute_ns);
      row_ += ',';
      append_us(&row_, e->last_roundtrip_ns);
    } else {
      row_ += ',';
    }
  }
  row_ += '\n';
  const int64_t now = now_ns();
  if (now - rows_flushed_ns_ >= 50'000'000 || row_.size() >= (1 << 16)) {
    flush_rows();
    rows_flushed_ns_ = now;
  }
}

bool FtiLoop::cycle(int64_t next, int64_t bound_ns, bool stop_on_done) {
  due_.clear();
  while (!queue_.empty() && queue_.begin()->first == next) {
    due_.push_back(engines_[queue_.begin()->second]);
    queue_.erase(queue_.begin());
  }
  std::sort(due_.begin(), due_.end(),
            [&](EngineHandle* a, EngineHandle* b) { return a->index < b->index; });
  std::fill(due_mask_.begin(), due_mask_.end(), 0);
  for (auto* e : due_) due_mask_[e->index] = 1;
  for (auto* e : due_) {
    e->last_compute_ns = -1;
    if (!e->busy()) continue;
    reply_.Clear();
    e->finish(&reply_);
    take_outputs(*e, reply_.mutable_step(), next);
    e->time_ns = next;  // the schedule, not the engine's clock, drives the loop
  }
  sim_time_ns_ = next;
  run_functions();
  if (interrupted()) return false;
  const bool finished = stop_on_done && done_;
  for (auto* e : due_) {
    const int64_t ts = e->config().timestep_ns;
    if (finished || (bound_ns > 0 && next + ts > bound_ns)) continue;
    request_.Clear();
    auto* step = request_.mutable_step();
    step->set_duration_ns(ts);
    for (auto& dp : e->pending_inputs) step->add_inputs()->Swap(&dp);
    e->pending_inputs.clear();
    for (const auto& id : e->wanted) *step->add_wanted() = id;
    e->start(request_, "Step");
    queue_.emplace(next + ts, e->index);
  }
  int64_t t = now_ns();
  write_row(t - last_cycle_ns_);
  last_cycle_ns_ = t;
  ++cycles_;
  if (progress_ && t - last_progress_ns_ >= progress_period_ns_) {
    last_progress_ns_ = t;
    progress_(sim_time_ns_);
  }
  return !finished;
}

bool FtiLoop::pass_gate() {
  const int64_t held = gate_->wait(sim_time_ns_);
  if (held > 0) {
    // The engines were idle meanwhile: neither their deadlines nor the cycle's wall time
    // count the pause.
    for (auto* e : engines_)
      if (e->busy()) e->postpone(held);
    last_cycle_ns_ += held;
    last_progress_ns_ += held;
  }
  return !interrupted();
}

void FtiLoop::run(int64_t until_ns) {
  last_cycle_ns_ = last_progress_ns_ = now_ns();
  while (!queue_.empty()) {
    const int64_t next = queue_.begin()->first;
    if (until_ns > 0 && next > until_ns) break;
    if (gate_ && !pass_gate()) break;
    if (!cycle(next, until_ns, /*stop_on_done=*/true)) break;
  }
}

void FtiLoop::advance(int64_t stop_ns, const std::atomic<bool>* stop) {
  if (last_cycle_ns_ == 0) last_cycle_ns_ = last_progress_ns_ = now_ns();
  while (!queue_.empty() && queue_.begin()->first < stop_ns) {
    if ((stop && stop->load(std::memory_order_relaxed)) || interrupted()) return;
    if (gate_ && !pass_gate()) return;
    if (!cycle(queue_.begin()->first, 0, /*stop_on_done=*/false)) return;
  }
  sim_time_ns_ = std::max(sim_time_ns_, stop_ns);
}

void FtiLoop::reset(std::vector<engine::DataPack> inputs) {
  engine::Reply reply;
  for (auto* e : engines_)
    if (e->busy()) e->finish(&reply);  // the steps in flight; their datapacks are dropped
  for (auto* e : engines_) {
    engine::Request request;
    auto* set = request.mutable_set_datapacks();
    for (auto& dp : inputs)
      if (dp.id().engine_name() == e->name()) *set->add_datapacks() = std::move(dp);
    if (set->datapacks_size() > 0) e->call(request, "SetDataPacks", &reply);
  }
  engine::Request request;
  request.mutable_reset();
  for (auto* e : engines_) e->start(request, "Reset");
  for (auto* e : engines_) e->finish(&reply);
  for (auto* e : engines_) {
    e->pending_inputs.clear();
    e->time_ns = 0;
  }
  pool_.clear();
  queue_.clear();
  observations_.clear();
  done_ = false;
  cycles_ = 0;
  sim_time_ns_ = 0;
  runner_.reset();
  prime();
}

}  // namespace convoy::loop
