// Starting engine processes (BasicFork) and making sure none outlives the coordinator.
//
// Each child runs in its own process group (a terminal's Ctrl-C reaches only the
// coordinator, which then shuts the engines down in order), gets SIGKILL if the coordinator
// dies for any reason (PR_SET_PDEATHSIG), and writes stdout and stderr to its own log file.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace convoy::launch {

struct LaunchSpec {
  std::string program;            // a path, or a name looked up in search_dirs then PATH
  std::vector<std::string> args;  // without argv[0]
  std::vector<std::string> env;   // extra "KEY=VALUE" entries
  std::filesystem::path log_file;
  std::filesystem::path working_dir;
  std::vector<int> pass_fds;  // become fds 3, 4, ... in the child
  std::vector<std::filesystem::path> search_dirs;
};

class ChildProcess {
 public:
  ChildProcess() = default;
  explicit ChildProcess(pid_t pid) : pid_(pid) {}
  pid_t pid() const { return pid_; }
  bool running() const { return pid_ > 0 && !exited_; }
  // Non-blocking check; true once the child has exited (status then available).
  bool poll();
  // Waits up to `seconds`; true if the child exited.
  bool wait_for(double seconds);
  // Sends a signal to the child's process group.
  void signal_group(int sig);
  // Terminates politely (SIGTERM), then SIGKILL after `grace` seconds; reaps.
  void terminate(double grace);
  // "exited with status 1", "killed by signal 9 (Killed)", or "still running".
  std::string describe() const;

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
  int status_ = 0;
};

// Starts the process. Throws std::runtime_error if it cannot be executed.
ChildProcess launch(const LaunchSpec& spec);

}  // namespace convoy::launch
