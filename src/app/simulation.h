// One simulation run: config -> engines -> FTILoop -> artefacts in a run folder.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "app/session.h"
#include "config/simulation_config.h"
#include "record/mcap_writer.h"

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
  std::string local_socket;    // --local_socket PATH: the same calls at a Unix socket too
  // --live [HOST:]PORT: serve the run to Foxglove WebSocket clients (app/live_run.h).
  std::string live;
  double live_camera_hz = 10;  // --live-camera-hz: JPEG frames per simulated second
  double live_scene_hz = 10;   // --live-scene-hz: /convoy/scene updates per simulated second
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

// `convoy replay RUN_DIR` and `convoy score RUN_DIR` (app/replay.h).
struct ReplayOptions {
  std::filesystem::path run_dir;       // the recorded run
  std::filesystem::path out_dir;       // default: RUN_DIR/replay (score: RUN_DIR/rescore)
  std::filesystem::path config_file;   // instead of the recorded config (other functions)
  std::vector<std::string> overrides;  // -o Key=Value on that config
  bool quiet = false;
};
// Exit code of a replay whose functions sent other datapacks than the recorded ones, and of a
// score whose fields differ from the live ones.
constexpr int kExitReplayDiffers = 5;
int replay_run(const ReplayOptions& options);
int score_run(const ReplayOptions& options);

// Shared by the commands (simulation.cpp).
void install_signal_handlers(bool ignore_sigint = false);
// $CONVOY_RUN_DIR and $CONVOY_SHARE_DIR for the functions, before the interpreter starts.
void export_run_environment(const std::filesystem::path& run_dir);
// summary.json: what the run's engines and functions wrote there, with the coordinator's
// fields on top (and the start-up figures, when given: a live run's; and `extra`'s fields,
// e.g. the live server's "live"). Returns "" or what failed ("no space left writing ...").
std::string write_summary(const std::filesystem::path& file, const config::SimulationConfig& cfg,
                          const LoopFigures& loop, double wall_s, const Outcome& outcome,
                          const StartupFigures* startup = nullptr,
                          const nlohmann::json* extra = nullptr);
// The `convoy` metadata of a recording: the effective config (tokens redacted), version.
record::StringMap recording_metadata(const config::SimulationConfig& cfg);

// Directory of the running executable, and the share directory next to it.
std::filesystem::path bin_dir();
std::filesystem::path share_dir();

}  // namespace convoy::app
