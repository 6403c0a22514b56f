// FTILoop: NRP-Core's fixed-time-increment loop.
//
// Engines step concurrently, each with its own timestep. Each cycle the loop waits for the
// engines whose next completion time comes first ("due" engines), takes the datapacks the
// functions read from them, runs the preprocessing functions then the transceiver
// functions linked to them (config order), and restarts them with the functions' outputs.
// Everything the loop decides depends on simulated time only, so runs are deterministic.
#pragma once

#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "loop/engine_handle.h"
#include "loop/function_runner.h"

namespace convoy::loop {

class FtiLoop {
 public:
  // `engines` in config order; `functions` in config order, run by `runner`. All three must
  // outlive the loop.
  FtiLoop(std::vector<EngineHandle*> engines, FunctionRunner& runner,
          const std::vector<LoadedFunction>& functions);

  // Writes one CSV row per cycle (wall times per engine) to `csv` (may be null).
  void set_step_log(std::FILE* csv);
  // Calls `report(sim_time_ns)` about every `period_s` of wall time while running.
  void set_progress(double period_s, std::function<void(int64_t)> report) {
    progress_period_ns_ = static_cast<int64_t>(period_s * 1e9);
    progress_ = std::move(report);
  }

  // Fetches the functions' inputs from every engine (after Initialize).
  void prime();
  // Runs until every engine has reached `until_ns` (0: until interrupted).
  void run(int64_t until_ns);

  int64_t sim_time_ns() const { return sim_time_ns_; }
  uint64_t cycles() const { return cycles_; }

 private:
  void take_outputs(EngineHandle& e, engine::StepReply* reply);
  void run_functions();
  void route(std::vector<engine::DataPack>& outputs, const LoadedFunction& fn);
  void write_row(int64_t cycle_wall_ns);

  std::vector<EngineHandle*> engines_;
  std::unordered_map<std::string, EngineHandle*> by_name_;
  std::vector<char> due_mask_;           // by engine index: due this cycle
  std::vector<size_t> function_engine_;  // by function: index of its engine
  std::string row_;
  FunctionRunner& runner_;
  const std::vector<LoadedFunction>& functions_;
  InputSource source_;
  struct Pooled {
    engine::DataPack datapack;
    uint64_t cycle = 0;  // the loop cycle it came in (prime(): 0)
  };
  std::unordered_map<std::string, Pooled> pool_;  // "engine\0name" -> latest
  std::multimap<int64_t, size_t> queue_;          // completion time -> engine
  std::vector<engine::DataPack> outputs_;
  std::FILE* csv_ = nullptr;
  int64_t sim_time_ns_ = 0;
  uint64_t cycles_ = 0;
  int64_t progress_period_ns_ = 0;
  std::function<void(int64_t)> progress_;
};

}  // namespace convoy::loop
