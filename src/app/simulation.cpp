#include "app/simulation.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <ctime>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "app/engine_set.h"
#include "app/event_loop_run.h"
#include "app/external_processes.h"
#include "app/live_run.h"
#include "app/nrp_server.h"
#include "app/run_log.h"
#include "app/session.h"
#include "config/simulation_config.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "datapack/blobs.h"
#include "loop/fti_loop.h"
#include "python/function_runtime.h"
#include "python/interpreter.h"
#include "record/recorder.h"

namespace convoy::app {

namespace fs = std::filesystem;

fs::path bin_dir() {
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : exe.parent_path();
}

fs::path share_dir() {
  if (const char* s = std::getenv("CONVOY_SHARE_DIR"); s && *s) return s;
  return bin_dir().parent_path() / "share" / "convoy";
}

namespace {

void on_signal(int sig) {
  if (interrupted()) _exit(kExitInterrupted);  // second Ctrl-C: give up at once
  interrupt_signal().store(sig);
}

// Each forked engine holds three of the coordinator's file descriptors (its socket and two
// arenas): with the usual soft limit of 1024, some 300 engines would exhaust them, well below
// config::kMaxEngines.
void raise_file_limit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0 ||
      limit.rlim_cur >= std::min<rlim_t>(limit.rlim_max, 65536))
    return;
  limit.rlim_cur = std::min<rlim_t>(limit.rlim_max, 65536);
  setrlimit(RLIMIT_NOFILE, &limit);
}

}  // namespace

void install_signal_handlers(bool ignore_sigint) {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: blocking waits return and see the flag
  sigaction(SIGTERM, &sa, nullptr);
  if (ignore_sigint)
    signal(SIGINT, SIG_IGN);  // a client's process: Ctrl-C in its terminal is the client's
  else
    sigaction(SIGINT, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
}

namespace {

fs::path make_run_dir(const RunOptions& options, const std::string& sim_name) {
  fs::path dir = options.run_dir;
  if (dir.empty()) {
    fs::path base = fs::current_path() / "runs";
    if (const char* b = std::getenv("CONVOY_RUNS_DIR"); b && *b) base = b;
    char stamp[32];
    std::time_t t = std::time(nullptr);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&t));
    dir = base / (sim_name + "-" + stamp + "-" + std::to_string(getpid()));
  }
  fs::create_directories(dir / "logs");
  return fs::absolute(dir);
}

// Copies of frame-sized payloads (datapack::large_copies()) made by each process of the run:
// the coordinator's own, and each engine's, which it prints last in its log on exit.
nlohmann::json frame_copies(const config::SimulationConfig& cfg, const fs::path& run_dir) {
  nlohmann::json out = {{"coordinator", datapack::large_copies().copies.load()}};
  static const std::string kTag = "frame-sized copies: ";
  for (const auto& e : cfg.engines) {
    std::ifstream log(run_dir / "logs" / (e.name + ".log"));
    std::string line, last;
    while (std::getline(log, line))
      if (line.rfind(kTag, 0) == 0) last = line;
    if (!last.empty()) out[e.name] = std::strtoull(last.c_str() + kTag.size(), nullptr, 10);
  }
  return out;
}

// The start-up figures as summary.json's "startup".
nlohmann::json startup_json(const StartupFigures& s) {
  auto r = [](double v) {
    return v < 0 ? nlohmann::json() : nlohmann::json(std::round(v * 1e4) / 1e4);
  };
  nlohmann::json engines = nlohmann::json::object();
  for (const auto& e : s.engines)
    engines[e.name] = {{"process_s", r(e.process_s)}, {"initialize_s", r(e.initialize_s)}};
  return {{"process_s", r(s.process_s)}, {"functions_s", r(s.functions_s)},
          {"launch_s", r(s.launch_s)},   {"initialize_s", r(s.initialize_s)},
          {"prime_s", r(s.prime_s)},     {"engines", engines}};
}

// What a failed write of `file` says: a full disk by name, else the system's reason.
std::string write_error(const fs::path& file, int err) {
  if (err == ENOSPC || err == EDQUOT) return "no space left writing " + file.string();
  return "cannot write " + file.string() + ": " + std::strerror(err);
}

// A temporary file beside it, synced, then renamed over it: a reader, or a run killed at any
// point, sees the old file or the new one, never half of one. Returns "" or what failed (the
// old file, if any, stays).
std::string write_file_atomically(const fs::path& file, const std::string& text) {
  const fs::path tmp = file.string() + ".tmp-" + std::to_string(getpid());
  const int fd = open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return write_error(file, errno);
  size_t done = 0;
  int err = 0;
  while (done < text.size() && err == 0) {
    const ssize_t n = write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      err = n < 0 ? errno : ENOSPC;
    else
      done += static_cast<size_t>(n);
  }
  if (err == 0 && fsync(fd) != 0) err = errno;
  close(fd);
  std::error_code ec;
  if (err == 0) {
    fs::rename(tmp, file, ec);
    if (ec) err = ec.value();
  }
  if (err != 0) fs::remove(tmp, ec);
  return err == 0 ? "" : write_error(file, err);
}

}  // namespace

// summary.json: what an engine or function of the run wrote there (a JSON object, e.g. an
// experiment's own figures), with the coordinator's fields on top.
std::string write_summary(const fs::path& file, const config::SimulationConfig& cfg,
                          const LoopFigures& loop, double wall_s, const Outcome& outcome,
                          const StartupFigures* startup, const nlohmann::json* extra) {
  nlohmann::json j = nlohmann::json::object();
  if (std::ifstream in(file); in) {
    j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) j = nlohmann::json::object();
  }
  j["simulation"] = cfg.name;
  j["config"] = cfg.file.string();
  j["state"] = "ended";
  j["exit_code"] = outcome.code;
  j["error"] = outcome.error;
  j["wall_s"] = wall_s;
  j["cycles"] = loop.cycles;
  const double sim_s = static_cast<double>(loop.sim_time_ns) * 1e-9;
  j["sim_time_s"] = sim_s;
  // The loop alone, without start-up and shutdown: simulated over wall-clock time.
  j["loop_wall_s"] = loop.wall_s;
  j["real_time_factor"] = loop.wall_s > 0 ? sim_s / loop.wall_s : 0.0;
  if (cfg.status_function && cfg.status_function->active) j["status_function_done"] = loop.done;
  // From the command's start to the first loop step, and its parts (standalone runs).
  if (startup && startup->total_s >= 0) {
    j["startup_s"] = startup->total_s;
    j["startup"] = startup_json(*startup);
  }
  j["frame_copies"] = frame_copies(cfg, file.parent_path());
  if (extra)
    for (const auto& [key, value] : extra->items()) j[key] = value;
  return write_file_atomically(file, j.dump(2) + "\n");
}

namespace {

// The effective config as the run folder keeps it: tokens are written as "***".
nlohmann::json redacted(nlohmann::json config) {
  if (config.contains("EngineConfigs") && config["EngineConfigs"].is_array()) {
    for (auto& e : config["EngineConfigs"])
      if (e.is_object() && e.contains("AuthToken")) e["AuthToken"] = "***";
  }
  return config;
}

}  // namespace

record::StringMap recording_metadata(const config::SimulationConfig& cfg) {
  return {{"format", record::kRecordingFormat},
          {"convoy_version", CONVOY_VERSION},
          {"simulation", cfg.name},
          {"config_file", cfg.file.string()},
          {"config", redacted(cfg.json).dump(2)},
          {"record_blobs", cfg.record_blobs ? "true" : "false"}};
}

namespace {

// The config and the run folder. Returns kExitOk, or the exit code once it has
// logged why the run cannot start.
int load(const RunOptions& options, RunLog& log, config::SimulationConfig* cfg, fs::path* run_dir) {
  try {
    *cfg = config::load_simulation_config(fs::absolute(options.config_file), options.overrides,
                                          share_dir());
  } catch (const config::ConfigError& e) {
    log.error(e.what());
    return kExitUserError;
  }
  try {
    *run_dir = make_run_dir(options, cfg->name);
  } catch (const std::exception& e) {
    log.error(std::string("cannot create the run folder: ") + e.what());
    return kExitUserError;
  }
  log.open(*run_dir / "logs" / "coordinator.log");
  log.info("run folder: " + run_dir->string());
  for (const auto& w : cfg->warnings) log.info("warning: " + w);
  if (std::string e =
          write_file_atomically(*run_dir / "config.json", redacted(cfg->json).dump(2) + "\n");
      !e.empty()) {
    log.error(e);
    return kExitUserError;
  }
  // From the start, so that a run killed on the way still says what it was: replaced (a reused
  // folder's too) at the end.
  const nlohmann::json running = {{"simulation", cfg->name},
                                  {"config", cfg->file.string()},
                                  {"state", "running"},
                                  {"pid", getpid()}};
  if (std::string e = write_file_atomically(*run_dir / "summary.json", running.dump(2) + "\n");
      !e.empty()) {
    log.error(e);
    return kExitUserError;
  }
  const bool event_loop = cfg->loop == "EventLoop";
  if (event_loop && cfg->record)
    log.info("warning: Record is not available with SimulationLoop EventLoop; nothing is recorded");
  if (cfg->process_launcher_type != "Basic")
    log.info("warning: ProcessLauncherType " + cfg->process_launcher_type +
             " is not available; using Basic");
  // ComputationalGraph, EventLoop and ExternalProcesses are the config's (its warnings say
  // when they are ignored); MQTTNode and ROSNode are the graph's (EventLoop or cg).
  const bool graph_clients = event_loop || cfg->datapack_processor == "cg";
  for (const char* key : {"ConnectROS", "ConnectMQTT", "EventLoopTimeout", "EventLoopTimestep",
                          "ROSNode", "MQTTNode"}) {
    if (graph_clients && (std::string(key) == "ROSNode" || std::string(key) == "MQTTNode"))
      continue;
    // An object counts when present ("ROSNode": {} starts a node with the defaults in NRP-Core);
    // an empty list asks for nothing.
    if (cfg->json.contains(key) && (!cfg->json[key].empty() || cfg->json[key].is_object())) {
      log.info(std::string("warning: ") + key + " is not supported yet; ignored");
    }
  }
  return kExitOk;
}

}  // namespace

void export_run_environment(const fs::path& run_dir) {
  python::set_environment("CONVOY_RUN_DIR", run_dir.string(), true);
  python::set_environment("CONVOY_SHARE_DIR", share_dir().string(), false);
}

namespace {

// The run proper, with the interpreter up: load the functions, launch and initialize the
// engines, run the loop; then shut the engines down, whatever happened before.
Outcome run_engines(const config::SimulationConfig& cfg, const fs::path& run_dir, bool quiet,
                    RunLog& log, LoopFigures* figures, StartupFigures* startup,
                    loop::DataPackTap* live_tap, loop::PauseGate* gate) {
  export_run_environment(run_dir);
  python::Interpreter interpreter;
  std::optional<GraphClients> graph_clients;  // closed after the session's graph is gone
  ExternalProcesses external(cfg, run_dir / "logs");
  Session session(cfg, run_dir, log, quiet);
  Outcome outcome;
  if (live_tap) {
    session.add_tap(live_tap);
    session.show_scene();
  }
  session.pause_with(gate);
  try {
    if (cfg.record) {
      try {
        session.record_to(run_dir / record::kRecordingFile, cfg.record_blobs,
                          recording_metadata(cfg));
      } catch (const std::runtime_error& e) {
        throw UserError(std::string("Record: ") + e.what());
      }
    }
    if (cfg.datapack_processor == "cg" && (cfg.mqtt_node || cfg.ros_node))
      graph_clients.emplace(cfg, run_dir / "logs", log);  // the graph's MQTT and ROS nodes
    external.start(log);
    session.initialize(/*keep_observations=*/false);
    session.run_to_end();
    if (interrupted()) outcome = {kExitInterrupted, interrupted_text()};
  } catch (...) {
    outcome = outcome_of(std::current_exception());
  }
  *figures = session.figures();
  session.finish_recording(outcome);
  *startup = session.startup();
  if (outcome.code == kExitInterrupted) {
    log.info(outcome.error + ": shutting the engines down (Ctrl-C again to kill them)");
    interrupt_signal().store(0);
  } else if (outcome.code != kExitOk) {
    log.error(outcome.error);
  }
  std::string shutdown_error = session.shut_down(outcome.code == kExitOk);
  external.stop(&log);
  if (!shutdown_error.empty()) {
    if (outcome.code == kExitOk) outcome.code = kExitEngineError;
    if (outcome.error.empty()) outcome.error = shutdown_error;
  }
  if (outcome.code == kExitOk && !session.output_error().empty()) {
    outcome = {kExitUserError, session.output_error()};
    log.error(outcome.error);
  }
  return outcome;
}

// summary.json and the last lines of the log; returns the exit code: the outcome's, or 2 when a
// run that went well cannot write its summary (a full disk).
int report(const config::SimulationConfig& cfg, const fs::path& run_dir, RunLog& log,
           const LoopFigures& figures, double wall_s, const Outcome& outcome,
           const StartupFigures* startup = nullptr, const nlohmann::json* extra = nullptr) {
  const std::string failed =
      write_summary(run_dir / "summary.json", cfg, figures, wall_s, outcome, startup, extra);
  if (!failed.empty()) log.error(failed);
  if (startup && startup->total_s >= 0) {
    std::ostringstream s;
    s.precision(3);
    s << std::fixed << "start-up " << startup->total_s << " s (to the first loop step)";
    log.info(s.str());
  }
  if (figures.ran) {
    std::ostringstream s;
    s << "simulated " << static_cast<double>(figures.sim_time_ns) * 1e-9 << " s in " << wall_s
      << " s wall, " << figures.cycles << " loop cycles";
    log.info(s.str());
  }
  std::string listing;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(run_dir, ec)) {
    if (entry.is_regular_file()) listing += "\n  " + entry.path().filename().string();
  }
  log.info("run folder: " + run_dir.string() + listing);
  return failed.empty() || outcome.code != kExitOk ? outcome.code : kExitUserError;
}

}  // namespace

int run_simulation(const RunOptions& options) {
  install_signal_handlers();
  raise_file_limit();
  RunLog log;
  log.quiet = options.quiet;
  config::SimulationConfig cfg;
  fs::path run_dir;
  if (int code = load(options, log, &cfg, &run_dir); code != kExitOk) return code;

  const auto t0 = SteadyClock::now();
  LoopFigures figures;
  StartupFigures startup;
  // The live server first: a port in use or a refused address ends the run before any engine.
  std::unique_ptr<LiveRun> live;
  if (!options.live.empty()) {
    try {
      live = std::make_unique<LiveRun>(options, cfg, log);
    } catch (const UserError& e) {
      const Outcome refused{kExitUserError, e.what()};
      log.error(refused.error);
      return report(cfg, run_dir, log, figures, 0, refused);
    }
  }
  Outcome outcome;
  if (cfg.loop == "EventLoop") {
    export_run_environment(run_dir);
    python::Interpreter interpreter;
    outcome = run_event_loop(cfg, run_dir, log, &figures, options.quiet);
  } else {
    outcome = run_engines(cfg, run_dir, options.quiet, log, &figures, &startup,
                          live ? live->tap() : nullptr, live ? live->gate() : nullptr);
  }
  const double wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  nlohmann::json live_fields;
  if (live) live_fields = {{"live", live->finish()}};
  return report(cfg, run_dir, log, figures, wall_s, outcome, &startup,
                live ? &live_fields : nullptr);
}

int serve_simulation(const RunOptions& options) {
  install_signal_handlers(options.slave);
  raise_file_limit();
  const pid_t parent = options.slave ? getppid() : 0;
  RunLog log;
  log.quiet = options.quiet;
  config::SimulationConfig cfg;
  fs::path run_dir;
  if (int code = load(options, log, &cfg, &run_dir); code != kExitOk) return code;
  if (cfg.record) log.info("warning: Record is not available in server mode; nothing is recorded");

  const auto t0 = SteadyClock::now();
  Outcome outcome;
  LoopFigures figures;
  {
    export_run_environment(run_dir);
    python::Interpreter interpreter;
    ExternalProcesses external(cfg, run_dir / "logs");
    NrpServer server(cfg, run_dir, log);
    try {
      external.start(log);
      server.listen(options.server_address, options.insecure);
      if (!options.local_socket.empty()) server.listen_local(options.local_socket);
      {
        pybind11::gil_scoped_release release;  // each call takes the GIL in its gRPC thread
        server.wait(parent);
        server.stop_serving();
      }
      server.finish();
      outcome = {server.exit_code(), server.error()};
      figures = server.figures();
    } catch (...) {
      outcome = outcome_of(std::current_exception());
      log.error(outcome.error);
    }
    external.stop(&log);
    if (outcome.code == kExitOk && interrupted()) outcome = {kExitInterrupted, interrupted_text()};
  }
  const double wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  return report(cfg, run_dir, log, figures, wall_s, outcome);
}

}  // namespace convoy::app
