// FTILoop: NRP-Core's fixed-time-increment loop.
//
// Engines step concurrently, each with its own timestep. Each cycle the loop waits for the
// engines whose next completion time comes first ("due" engines), takes the datapacks the
// functions read from them, runs the preprocessing functions then the transceiver
// functions linked to them (config order), and restarts them with the functions' outputs.
// Everything the loop decides depends on simulated time only, so runs are deterministic.
//
// After the transceiver functions of every cycle, the status function (if any) runs on the
// datapacks it asks for; its done flag ends run(), and the data it returns collects as the
// observations that a client of the NRP-Core server (app/nrp_server.h) receives. A client
// steps the loop with advance() and resets it with reset().
#pragma once

#include <atomic>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "loop/datapack_tap.h"
#include "loop/engine_handle.h"
#include "loop/function_runner.h"
#include "loop/pause_gate.h"

namespace convoy::loop {

class FtiLoop {
 public:
  // `engines` in config order; `functions` in config order, run by `runner`; `status`, the
  // status function, or null. All must outlive the loop.
  FtiLoop(std::vector<EngineHandle*> engines, FunctionRunner& runner,
          const std::vector<LoadedFunction>& functions, const LoadedFunction* status = nullptr);
  // Writes the steps.csv rows not written yet.
  ~FtiLoop();

  // Writes one CSV row per cycle (wall times per engine) to `csv` (may be null).
  void set_step_log(std::FILE* csv);
  // Shows every datapack taken from an engine and every one the functions send to `tap`
  // (null: none). The tap must outlive the loop.
  void set_tap(DataPackTap* tap) { tap_ = tap; }
  // Waits at `gate` before each cycle (null: never). The time it holds the loop counts neither
  // against the engines' EngineCommandTimeout nor in the cycles' wall times. The gate must
  // outlive the loop.
  void set_gate(PauseGate* gate) { gate_ = gate; }
  // Calls `report(sim_time_ns)` about every `period_s` of wall time while running.
  void set_progress(double period_s, std::function<void(int64_t)> report) {
    progress_period_ns_ = static_cast<int64_t>(period_s * 1e9);
    progress_ = std::move(report);
  }

  // Also asks engine `engine` for datapack `datapack` after Initialize and with each of its
  // steps, though no function reads it: for the viewers (the live scene, a recording), which
  // see it through the tap. The functions' inputs are unchanged; it is no observation. A
  // datapack already wanted is asked for once; an engine that has no such datapack answers
  // it empty (as engines answer an unknown id), which the loop keeps like any other. Before
  // prime(). Returns whether it was not wanted yet. Throws std::invalid_argument naming an
  // unknown engine.
  bool also_want(const std::string& engine, const std::string& datapack);

  // Runs the runner's computational graph (FunctionRunner::run_graph) each cycle, after the
  // functions; `label` names it in errors and to the tap (its name and first file). The
  // datapacks it reads are asked for with also_want(). Before prime(); `label` must outlive
  // the loop.
  void set_graph(const LoadedFunction* label) { graph_ = label; }

  // Fetches the functions' inputs from every engine (after Initialize). With
  // keep_observations(), the non-empty ones are the first observations (what NRP-Core's
  // initialize() returns to its client).
  void prime();
  // Runs until every engine has reached `until_ns` (0: until interrupted) or the status
  // function returns done. Engines are not restarted past `until_ns`, nor after done.
  void run(int64_t until_ns);
  // NRP-Core's stepping (its FTILoop::runLoop): runs the cycles due before `stop_ns`,
  // restarting every due engine; the loop's time is then `stop_ns`. Returns early, between
  // cycles, when `stop` is set or on an interrupt.
  void advance(int64_t stop_ns, const std::atomic<bool>* stop = nullptr);
  // NRP-Core's reset: waits for the steps in flight, sends each engine the datapacks of
  // `inputs` named for it, resets the engines, forgets the pool, the pending datapacks, the
  // observations and the done flag, and starts again at time 0 and cycle 0 with prime().
  void reset(std::vector<engine::DataPack> inputs);

  // A datapack from outside the loop (a client) for its engine's next step, before the
  // transceiver functions' ones. Throws std::invalid_argument naming an unknown engine.
  void add_input(engine::DataPack datapack);
  bool has_engine(const std::string& name) const { return by_name_.count(name) > 0; }

  // Collect what the status function returns (off: it is dropped each cycle).
  void keep_observations(bool keep) { keep_observations_ = keep; }
  // The observations collected since the last call, in order; each carries its blobs inline.
  std::vector<engine::DataPack> take_observations();
  // The status function's done flag from the last cycle (false without one).
  bool done() const { return done_; }
  bool has_status_function() const { return status_ != nullptr; }

  int64_t sim_time_ns() const { return sim_time_ns_; }
  uint64_t cycles() const { return cycles_; }

 private:
  // One cycle at `next`: collect the due engines, run the functions, restart the engines
  // (none past `bound_ns` when > 0, none when `stop_on_done` and the status function says
  // done). Returns false when the loop must stop (interrupt, done).
  bool cycle(int64_t next, int64_t bound_ns, bool stop_on_done);
  void take_outputs(EngineHandle& e, engine::StepReply* reply, int64_t time_ns);
  void run_functions();
  void keep_observation(const engine::DataPack& dp, const std::string& engine);
  void route(std::vector<engine::DataPack>& outputs, const LoadedFunction& fn);
  void write_row(int64_t cycle_wall_ns);
  // steps.csv: the rows of the last 50 ms (or 64 KiB) go out in one write, whole rows only,
  // so that a run killed at any point keeps every row but those of its last 50 ms.
  void flush_rows();
  // Waits at the gate; false on an interrupt.
  bool pass_gate();

  std::vector<EngineHandle*> engines_;
  std::unordered_map<std::string, EngineHandle*> by_name_;
  std::vector<char> due_mask_;           // by engine index: due this cycle
  std::vector<size_t> function_engine_;  // by function: index of its engine
  std::string row_;                      // the rows not written yet
  int64_t rows_flushed_ns_ = 0;
  FunctionRunner& runner_;
  const std::vector<LoadedFunction>& functions_;
  const LoadedFunction* status_;
  const LoadedFunction* graph_ = nullptr;  // set_graph()'s: runs the graph
  std::vector<std::string> due_names_;     // the due engines' names, for the graph
  InputSource source_;
  struct Pooled {
    engine::DataPack datapack;
    uint64_t cycle = 0;  // the loop cycle it came in (prime(): 0)
  };
  std::unordered_map<std::string, Pooled> pool_;  // "engine\0name" -> latest
  std::unordered_set<std::string> extra_;         // also_want()'s, "engine\0name"
  std::multimap<int64_t, size_t> queue_;          // completion time -> engine
  std::vector<engine::DataPack> outputs_;
  std::vector<engine::DataPack> observations_;
  bool keep_observations_ = false;
  bool done_ = false;
  std::vector<EngineHandle*> due_;
  engine::Reply reply_;
  engine::Request request_;
  int64_t last_cycle_ns_ = 0;
  int64_t last_progress_ns_ = 0;
  std::FILE* csv_ = nullptr;
  DataPackTap* tap_ = nullptr;
  PauseGate* gate_ = nullptr;
  int64_t sim_time_ns_ = 0;
  uint64_t cycles_ = 0;
  int64_t progress_period_ns_ = 0;
  std::function<void(int64_t)> progress_;
};

}  // namespace convoy::loop
