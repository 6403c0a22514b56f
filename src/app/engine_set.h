// The engines of one run, from start to end: launch (fork or connect), Initialize, and the
// shutdown that every engine gets whatever happened in between.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/run_log.h"
#include "config/simulation_config.h"
#include "loop/engine_handle.h"

namespace convoy::app {

// One engine's start-up, as it reports it in its Initialize reply (summary.json's "startup").
struct EngineStartup {
  std::string name;
  double process_s = -1;     // its process's start -> the Initialize request (forked engines)
  double initialize_s = -1;  // inside Initialize
};

class EngineSet {
 public:
  // One handle per engine of `cfg`, in config order, logging to `log_dir`/<name>.log. Nothing
  // is started yet.
  EngineSet(const config::SimulationConfig& cfg, const std::filesystem::path& log_dir);

  // Forks each BasicFork engine (socket, shared-memory arenas) or connects to an
  // EmptyLaunchCommand engine's ServerAddress. Throws UserError or EngineError.
  void launch();
  // A replay: attaches `channel(engine)` to each handle instead of starting anything.
  void attach(
      const std::function<std::unique_ptr<transport::EngineChannel>(const config::EngineConfig&)>&
          channel);
  // Sends Initialize to every engine, then collects the replies, logging the warnings they
  // carry, and each engine's start-up figures into `startup` (if given). Throws EngineError.
  void initialize(RunLog& log, std::vector<EngineStartup>* startup = nullptr);
  // Shuts every engine down (see EngineHandle::shutdown), the longer timeout after a clean
  // run. Logs each failure with the engine's last log lines; returns the first one, or "".
  std::string shut_down(bool clean, RunLog& log);

  size_t size() const { return engines_.size(); }
  std::vector<loop::EngineHandle*> handles() const;

 private:
  void launch(loop::EngineHandle& handle);

  const config::SimulationConfig& cfg_;
  std::vector<std::unique_ptr<loop::EngineHandle>> engines_;
};

}  // namespace convoy::app
