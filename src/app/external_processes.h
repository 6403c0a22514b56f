// The config's ExternalProcesses (NRP-Core's process launcher keys ProcCmd, ProcStartParams,
// ProcEnvParams, LaunchCommand): started in config order before the engines, stopped after
// them.
//
// Each runs with the config's folder as its working folder, the coordinator's environment plus
// ProcEnvParams, stdout and stderr to logs/<ProcCmd's basename>_<index>.log in the run folder,
// in its own process group, and gets SIGKILL when the coordinator dies (launch/BasicFork). Stopping
// sends SIGTERM, then SIGKILL after the grace period, one process after the other.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/run_log.h"
#include "config/simulation_config.h"
#include "launch/process_launcher.h"

namespace convoy::app {

// ProcCmd and ProcStartParams as an argv: each split at spaces, tabs and newlines (NRP-Core
// hands them to bash's unquoted `exec`; no quotes or globs are interpreted here).
std::vector<std::string> command_words(const config::ExternalProcessConfig& proc);
// `text` with $NAME and ${NAME} replaced by lookup(NAME) ("" when unset); "$" before anything
// else stays.
std::string expand_variables(const std::string& text,
                             const std::function<std::string(const std::string&)>& lookup);
// "logs/<basename>_<index>.log"'s file name for the process's program ("proc_<index>.log"
// when the name is unusable as a file name).
std::string external_log_name(const std::string& program, size_t index);

class ExternalProcesses {
 public:
  // Nothing starts yet. `grace_s`: how long stop() waits after SIGTERM.
  // `cfg` must outlive it.
  ExternalProcesses(const config::SimulationConfig& cfg, std::filesystem::path log_dir,
                    double grace_s = 5.0);
  // Stops those still running.
  ~ExternalProcesses();

  // Starts them in order. Throws UserError naming the ProcCmd that cannot be executed, after
  // stopping those already started.
  void start(RunLog& log);
  // SIGTERM, then SIGKILL after the grace period, in config order; reaps them. Logs each one
  // that had already ended on its own.
  void stop(RunLog* log);
  size_t running() const;
  // The first one that has ended with a failure (a non-zero status or a signal): what it was
  // and how it ended ("\"cmd\" exited with status 2"), and its log; nullopt if none.
  struct Failure {
    std::string what;
    std::filesystem::path log;
  };
  std::optional<Failure> first_failure();

 private:
  struct Started {
    std::string cmd;
    launch::ChildProcess child;
    std::filesystem::path log;
  };
  const std::vector<config::ExternalProcessConfig>& procs_;
  std::filesystem::path config_file_, config_dir_, log_dir_;
  double grace_s_;
  std::vector<Started> started_;
};

}  // namespace convoy::app
