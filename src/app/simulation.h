// One simulation run: config -> engines -> FTILoop -> artefacts in a run folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace convoy::app {

struct RunOptions {
  std::filesystem::path config_file;
  std::vector<std::string> overrides;  // "-o Key=Value"
  std::filesystem::path run_dir;       // empty: runs/<name>-<time> under $CONVOY_RUNS_DIR or cwd
  bool quiet = false;
  // NRP-Core's server mode (-m server): serve the simulation to a client (app/nrp_server.h).
  bool server = false;
  std::string server_address;  // --server_address HOST:PORT
  bool slave = false;          // --slave: started by a client; ignore Ctrl-C, end with it
  bool insecure = false;       // --insecure: listen beyond the loopback too
};

// Exit codes of `convoy run`.
enum ExitCode {
  kExitOk = 0,
  kExitInternal = 1,
  kExitUserError = 2,
  kExitEngineError = 3,
  kExitFunctionError = 4,
  kExitInterrupted = 130,
};

int run_simulation(const RunOptions& options);
// The server mode: serves until a client's shutdown, an interrupt or (slave) the client's exit.
int serve_simulation(const RunOptions& options);

// Directory of the running executable, and the share directory next to it.
std::filesystem::path bin_dir();
std::filesystem::path share_dir();

}  // namespace convoy::app
