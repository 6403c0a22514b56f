#include "app/session.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "app/scene_setup.h"
#include "app/simulation.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "python/live_module.h"

namespace convoy::app {

namespace fs = std::filesystem;

namespace {

// Checks that every function names engines that exist, and PF inputs are their own engine's.
void check_functions(const std::vector<const loop::LoadedFunction*>& functions,
                     const config::SimulationConfig& cfg) {
  std::set<std::string> engines;
  std::string list;
  for (const auto& e : cfg.engines) {
    engines.insert(e.name);
    list += (list.empty() ? "" : ", ") + e.name;
  }
  for (const auto* fn : functions) {
    const char* deco = fn->status          ? "@StatusFunction"
                       : fn->preprocessing ? "@PreprocessingFunction"
                                           : "@TransceiverFunction";
    if (!fn->status && !engines.count(fn->engine)) {
      throw UserError(fn->file.string() + ": " + deco + "(\"" + fn->engine + "\") in function '" +
                      fn->name + "' names an unknown engine (engines: " + list + ")");
    }
    for (const auto& in : fn->inputs) {
      if (in.kind != loop::InputKind::kDataPack) continue;
      if (!engines.count(in.engine)) {
        throw UserError(fn->file.string() + ": input '" + in.keyword + "' of function '" +
                        fn->name + "' reads datapack '" + in.datapack + "' from unknown engine '" +
                        in.engine + "' (engines: " + list + ")");
      }
      if (fn->preprocessing && !in.preprocessed && in.engine != fn->engine) {
        throw UserError(fn->file.string() + ": preprocessing function '" + fn->name +
                        "' may only read datapacks of its engine '" + fn->engine + "', not '" +
                        in.engine + "'");
      }
    }
  }
}

}  // namespace

std::string interrupted_text() {
  return "interrupted by signal " + std::to_string(interrupt_signal().load());
}

Outcome outcome_of(std::exception_ptr thrown) {
  try {
    std::rethrow_exception(thrown);
  } catch (const UserError& e) {
    return {kExitUserError, e.what()};
  } catch (const EngineError& e) {
    // Ctrl-C while waiting for an engine: the engine did nothing wrong.
    if (interrupted()) return {kExitInterrupted, interrupted_text()};
    return {kExitEngineError, e.what()};
  } catch (const FunctionError& e) {
    return {kExitFunctionError, e.what()};
  } catch (const std::exception& e) {
    return {kExitInternal, e.what()};
  }
}

Session::Session(const config::SimulationConfig& cfg, fs::path run_dir, RunLog& log, bool quiet)
    : cfg_(cfg),
      run_dir_(std::move(run_dir)),
      log_(log),
      quiet_(quiet),
      runtime_(cfg.argument_passing == "reference"),
      engines_(cfg, run_dir_ / "logs") {
  step_ns_ = std::numeric_limits<int64_t>::max();
  for (const auto& e : cfg.engines) step_ns_ = std::min(step_ns_, e.timestep_ns);
  if (cfg.engines.empty()) step_ns_ = cfg.timestep_ns;
}

Session::~Session() {
  if (!shut_down_) shut_down(false);
}

void Session::initialize(bool keep_observations) {
  if (loop_) throw std::logic_error("the simulation is already initialized");
  const auto t0 = SteadyClock::now();
  auto since = [](SteadyClock::time_point from) {
    return std::chrono::duration<double>(SteadyClock::now() - from).count();
  };
  if (const int64_t start = process_start_ns(); start > 0)
    startup_.process_s = (now_ns() - start) * 1e-9;
  load_functions();
  startup_.functions_s = since(t0);

  if (replay_channel_) {
    engines_.attach(replay_channel_);
  } else {
    auto t1 = SteadyClock::now();
    engines_.launch();
    startup_.launch_s = since(t1);
    log_.info("started " + std::to_string(engines_.size()) + " engines");
    t1 = SteadyClock::now();
    engines_.initialize(log_, &startup_.engines);
    startup_.initialize_s = since(t1);
    log_.info("engines initialized in " +
              std::to_string(std::chrono::duration<double>(SteadyClock::now() - t0).count()) +
              " s");
  }

  loop::FunctionRunner& runner = graph_ ? static_cast<loop::FunctionRunner&>(*graph_) : runtime_;
  loop_ = std::make_unique<loop::FtiLoop>(engines_.handles(), runner, functions_,
                                          status_ ? &*status_ : nullptr);
  loop_->keep_observations(keep_observations);
  attach_graph();
  if (show_scene_) {
    std::string extra;
    for (const auto& id : scene_datapacks(engines_.handles()))
      if (loop_->also_want(id.engine_name(), id.name()))
        extra += (extra.empty() ? "" : ", ") + id.engine_name() + "/" + id.name();
    if (!extra.empty()) log_.info("scene: also taking " + extra + " (no function reads them)");
  }
  taps_.add(recorder_.get());
  taps_.add(replay_tap_);
  for (auto* tap : extra_taps_) taps_.add(tap);
  if (!taps_.empty()) loop_->set_tap(taps_.single_or_this());
  loop_->set_gate(gate_);
  csv_.reset(std::fopen((run_dir_ / "steps.csv").c_str(), "w"));
  // Unbuffered: the loop writes whole rows, 50 ms of them at a time (FtiLoop::flush_rows), so
  // that a run killed at any point keeps every whole row written.
  if (csv_) std::setvbuf(csv_.get(), nullptr, _IONBF, 0);
  loop_->set_step_log(csv_.get());
  if (!quiet_) {
    auto start = SteadyClock::now();
    loop_->set_progress(5.0, [this, start](int64_t sim_ns) {
      double wall = std::chrono::duration<double>(SteadyClock::now() - start).count();
      std::ostringstream s;
      s.precision(1);
      s << std::fixed << "progress: simulated " << sim_ns * 1e-9 << " s";
      if (cfg_.timeout_ns > 0) s << " of " << cfg_.timeout_ns * 1e-9 << " s";
      s << " (" << sim_ns * 1e-9 / wall << "x real time)";
      log_.info(s.str());
    });
  }
  figures_.ran = true;
  const auto t_prime = SteadyClock::now();
  timed([&] { loop_->prime(); });
  startup_.prime_s = since(t_prime);
  if (const int64_t start = process_start_ns(); start > 0)
    startup_.total_s = (now_ns() - start) * 1e-9;
}

void Session::load_functions() {
  if (cfg_.datapack_processor == "cg") {
    // As in NRP-Core, the graph replaces the functions (the config warns about them).
    python::add_python_path(cfg_.dir);
    std::vector<std::string> engines;
    for (const auto& e : cfg_.engines) engines.push_back(e.name);
    graph_ = std::make_unique<python::GraphRuntime>();
    graph_->load(cfg_.computational_graph, cfg_.dir, engines);
    graph_label_.name = graph_->label();
    graph_label_.file = cfg_.computational_graph.empty() ? cfg_.file : cfg_.computational_graph[0];
    log_.info("loaded the " + graph_->label());
    return;
  }
  for (const auto& f : cfg_.functions) {
    if (!f.active) continue;
    python::add_python_path(f.file.parent_path());
    for (auto& fn : runtime_.load(f.name, f.file)) functions_.push_back(std::move(fn));
  }
  if (cfg_.status_function && cfg_.status_function->active) {
    const auto& f = *cfg_.status_function;
    python::add_python_path(f.file.parent_path());
    status_ = runtime_.load_status(f.name, f.file);
  }
  std::vector<const loop::LoadedFunction*> all;
  for (const auto& fn : functions_) all.push_back(&fn);
  if (status_) all.push_back(&*status_);
  check_functions(all, cfg_);
}

void Session::attach_graph() {
  if (!graph_) return;
  for (const auto& [engine, name] : graph_->requested()) loop_->also_want(engine, name);
  loop_->set_graph(&graph_label_);
}

void Session::record_to(const fs::path& file, bool blobs, const record::StringMap& metadata) {
  record::RecorderOptions options;
  const SceneSetup scene = scene_setup(cfg_, log_);
  options.map = scene.map;
  options.scene = scene.options;
  recorder_ = std::make_unique<record::Recorder>(file, blobs, metadata, options);
  python::set_live_publisher(
      [recorder = recorder_.get()](const std::string& topic, const std::string& json,
                                   int64_t time_ns) {
        return recorder->viewer_json(topic, json, time_ns);
      },
      python::PublisherSlot::kRecording);
  show_scene();
  log_.info("recording the datapacks into " + file.string() +
            (blobs ? " (with blobs)" : " (blobs as stubs; --record-blobs records them)"));
}

void Session::finish_recording(const Outcome& outcome) {
  if (!recorder_) return;
  python::set_live_publisher(nullptr, python::PublisherSlot::kRecording);
  const std::string error =
      recorder_->finish({{"exit_code", std::to_string(outcome.code)},
                         {"error", outcome.error},
                         {"cycles", std::to_string(figures_.cycles)},
                         {"sim_time_ns", std::to_string(figures_.sim_time_ns)}});
  if (!error.empty()) {
    log_.error("recording: " + error);
  } else {
    log_.info("recording: " + std::to_string(recorder_->messages()) + " messages, " +
              std::to_string(recorder_->bytes()) + " bytes in " + recorder_->path().string());
  }
  if (recorder_->skipped() > 0)
    log_.info("warning: recording: " + std::to_string(recorder_->skipped()) +
              " datapacks could not be recorded; the first: " + recorder_->first_skip());
}

void Session::replay_with(ChannelFactory channel, loop::DataPackTap* tap) {
  replay_channel_ = std::move(channel);
  replay_tap_ = tap;
}

template <typename F>
void Session::timed(F&& run) {
  const auto start = SteadyClock::now();
  const int64_t held = gate_ ? gate_->held_ns() : 0;
  auto record = [&] {
    figures_.cycles = loop_->cycles();
    figures_.sim_time_ns = loop_->sim_time_ns();
    figures_.wall_s += std::chrono::duration<double>(SteadyClock::now() - start).count();
    if (gate_) figures_.wall_s -= (gate_->held_ns() - held) * 1e-9;  // paused by a viewer
    figures_.done = loop_->done();
  };
  try {
    run();
  } catch (...) {
    record();
    throw;
  }
  record();
}

void Session::run_to_end() {
  timed([&] { loop_->run(cfg_.timeout_ns); });
  if (loop_->done()) {
    std::ostringstream s;
    s << "the status function returned done at cycle " << loop_->cycles() - 1 << " (simulated "
      << loop_->sim_time_ns() * 1e-9 << " s): run ended";
    log_.info(s.str());
  }
}

void Session::run_steps(uint32_t steps, const std::atomic<bool>& stop) {
  timed([&] {
    for (uint32_t i = 0; steps == 0 || i < steps; ++i) {
      if (stop.load(std::memory_order_relaxed) || interrupted()) return;
      loop_->advance(loop_->sim_time_ns() + step_ns_, &stop);
    }
  });
}

bool Session::timed_out() const {
  return cfg_.timeout_ns > 0 && loop_ && loop_->sim_time_ns() >= cfg_.timeout_ns;
}

void Session::run_until_done_or_timeout(const std::atomic<bool>& stop) {
  timed([&] {
    while (!loop_->done() && !timed_out()) {
      if (stop.load(std::memory_order_relaxed) || interrupted()) return;
      loop_->advance(loop_->sim_time_ns() + step_ns_, &stop);
    }
  });
}

void Session::reset(std::vector<engine::DataPack> inputs) {
  timed([&] { loop_->reset(std::move(inputs)); });
}

std::string Session::shut_down(bool clean) {
  shut_down_ = true;
  loop_.reset();
  if (recorder_) python::set_live_publisher(nullptr, python::PublisherSlot::kRecording);
  recorder_.reset();  // finished already, unless the run ended by an exception of its own
  std::string error = engines_.shut_down(clean, log_);
  if (csv_ && (std::fflush(csv_.get()) != 0 || std::ferror(csv_.get()))) {
    const int err = errno;
    const std::string file = (run_dir_ / "steps.csv").string();
    output_error_ = err == ENOSPC || err == EDQUOT
                        ? "no space left writing " + file
                        : "cannot write " + file + " (a row could not be written)";
  }
  return error;
}

}  // namespace convoy::app
