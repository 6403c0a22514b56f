// One simulation from loading its functions to its engines' shutdown: the functions, the
// engines and the loop. The standalone run (simulation.cpp) runs it to its end; the NRP-Core
// server (nrp_server.h) steps it for a client. Every call needs the Python GIL.
#pragma once

#include <atomic>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/engine_set.h"
#include "app/run_log.h"
#include "config/simulation_config.h"
#include "loop/fti_loop.h"
#include "loop/tap_fanout.h"
#include "python/function_runtime.h"
#include "python/graph_runtime.h"
#include "record/recorder.h"

namespace convoy::app {

// What the loop did, kept after it is gone.
struct LoopFigures {
  bool ran = false;  // the loop was set up
  uint64_t cycles = 0;
  int64_t sim_time_ns = 0;
  double wall_s = 0;  // time spent running the loop: start-up and shutdown not counted
  bool done = false;  // the status function ended the run
};

// From the command's start to the first loop step (summary.json's "startup_s" and "startup").
// Negative: not reached.
struct StartupFigures {
  double total_s = -1;       // the process's start -> the first loop step
  double process_s = -1;     // the process's start -> the session: exec, config, run folder,
                             // the embedded interpreter
  double functions_s = -1;   // loading the TF/PF files (their imports)
  double launch_s = -1;      // forking the engines (or connecting to remote ones)
  double initialize_s = -1;  // Initialize of every engine (concurrently), until the last reply
  double prime_s = -1;       // the functions' first datapacks
  std::vector<EngineStartup> engines;
};

// How a run ended: its exit code (simulation.h's ExitCode) and, unless it went well, why.
struct Outcome {
  int code = 0;
  std::string error;
};
// The outcome of a run that ended by throwing `thrown` (UserError 2, EngineError 3, or 130
// after an interrupt, FunctionError 4, anything else 1).
Outcome outcome_of(std::exception_ptr thrown);
// "interrupted by signal N".
std::string interrupted_text();

class Session {
 public:
  // Nothing starts yet. `quiet`: no progress lines.
  Session(const config::SimulationConfig& cfg, std::filesystem::path run_dir, RunLog& log,
          bool quiet);
  ~Session();

  // Record the datapacks into `file` (record/recorder.h); `metadata` is the recording's
  // `convoy` metadata. Before initialize(). Throws std::runtime_error when the file cannot be
  // created.
  void record_to(const std::filesystem::path& file, bool blobs, const record::StringMap& metadata);
  // Finishes the recording with how the run ended (its `convoy_end` metadata). Logs a write
  // error. Without a recording, does nothing.
  void finish_recording(const Outcome& outcome);
  // A replay: each engine is `channel(engine)` (no process, no Initialize), and `tap` sees the
  // datapacks. Before initialize().
  using ChannelFactory =
      std::function<std::unique_ptr<transport::EngineChannel>(const config::EngineConfig&)>;
  void replay_with(ChannelFactory channel, loop::DataPackTap* tap);
  // Another tap on the loop (the live server's), after the recorder. Before initialize();
  // it must outlive the session's loop.
  void add_tap(loop::DataPackTap* tap) { extra_taps_.push_back(tap); }
  // A viewer shows the scene (a live run; a recording, by record_to()): the loop also asks the
  // engines for the road users the functions do not read (scene_setup.h's scene_datapacks).
  // Before initialize(); nothing the run computes changes.
  void show_scene() { show_scene_ = true; }
  // A gate the loop waits at between cycles (a live run's pause; loop/pause_gate.h). Before
  // initialize(); it must outlive the session's loop. The time it holds the loop is not in
  // LoopFigures::wall_s.
  void pause_with(loop::PauseGate* gate) { gate_ = gate; }

  // Loads the functions (a broken file costs no start-up), launches and initializes the
  // engines, and fetches the functions' first inputs. `keep_observations`: collect what the
  // status function returns, for a client. Throws UserError, EngineError, FunctionError.
  void initialize(bool keep_observations);
  bool initialized() const { return loop_ != nullptr; }

  // Standalone: runs until SimulationTimeout, the status function's done or an interrupt.
  void run_to_end();
  // NRP-Core's runLoop(n): n steps of the smallest EngineTimestep (0: until `stop`).
  void run_steps(uint32_t steps, const std::atomic<bool>& stop);
  // NRP-Core's runUntilTimeout: steps until done or SimulationTimeout (or `stop`). A done
  // flag still set from the last call returns at once, as in NRP-Core.
  void run_until_done_or_timeout(const std::atomic<bool>& stop);
  bool timed_out() const;
  void reset(std::vector<engine::DataPack> inputs);

  loop::FtiLoop& loop() { return *loop_; }
  const LoopFigures& figures() const { return figures_; }
  const StartupFigures& startup() const { return startup_; }

  // Shuts the engines down (see EngineSet::shut_down); returns the first error, or "".
  std::string shut_down(bool clean);
  // After shut_down: "" or what the run could not write of its own files (steps.csv).
  const std::string& output_error() const { return output_error_; }

 private:
  template <typename F>
  void timed(F&& run);
  // The TF, PF and status function files, or the computational graph (DataPackProcessor cg).
  void load_functions();
  // With a graph: the loop runs it, and takes the datapacks it reads.
  void attach_graph();

  const config::SimulationConfig& cfg_;
  std::filesystem::path run_dir_;
  RunLog& log_;
  bool quiet_;
  python::FunctionRuntime runtime_;
  std::unique_ptr<python::GraphRuntime> graph_;  // DataPackProcessor cg
  loop::LoadedFunction graph_label_;             // names the graph in errors and to taps
  EngineSet engines_;
  std::vector<loop::LoadedFunction> functions_;
  std::optional<loop::LoadedFunction> status_;
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> csv_{nullptr, &std::fclose};
  std::unique_ptr<loop::FtiLoop> loop_;
  int64_t step_ns_ = 0;  // the smallest EngineTimestep: NRP-Core's simulation timestep
  LoopFigures figures_;
  StartupFigures startup_;
  bool shut_down_ = false;
  std::string output_error_;
  std::unique_ptr<record::Recorder> recorder_;
  ChannelFactory replay_channel_;
  loop::DataPackTap* replay_tap_ = nullptr;
  std::vector<loop::DataPackTap*> extra_taps_;
  loop::PauseGate* gate_ = nullptr;
  bool show_scene_ = false;
  loop::TapFanout taps_;
};

}  // namespace convoy::app
