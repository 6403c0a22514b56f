#include "app/simulation.h"

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <ctime>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "app/run_log.h"
#include "config/simulation_config.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "loop/fti_loop.h"
#include "python/function_runtime.h"
#include "transport/frame_socket.h"

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

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: blocking waits return and see the flag
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  signal(SIGPIPE, SIG_IGN);
}

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

// Checks that every function names engines that exist, and PF inputs are their own engine's.
void check_functions(const std::vector<python::LoadedFunction>& functions,
                     const config::SimulationConfig& cfg) {
  std::set<std::string> engines;
  std::string list;
  for (const auto& e : cfg.engines) {
    engines.insert(e.name);
    list += (list.empty() ? "" : ", ") + e.name;
  }
  for (const auto& fn : functions) {
    const char* deco = fn.preprocessing ? "@PreprocessingFunction" : "@TransceiverFunction";
    if (!engines.count(fn.engine)) {
      throw UserError(fn.file.string() + ": " + deco + "(\"" + fn.engine + "\") in function '" +
                      fn.name + "' names an unknown engine (engines: " + list + ")");
    }
    for (const auto& in : fn.inputs) {
      if (!engines.count(in.engine)) {
        throw UserError(fn.file.string() + ": input '" + in.keyword + "' of function '" + fn.name +
                        "' reads datapack '" + in.datapack + "' from unknown engine '" + in.engine +
                        "' (engines: " + list + ")");
      }
      if (fn.preprocessing && !in.preprocessed && in.engine != fn.engine) {
        throw UserError(fn.file.string() + ": preprocessing function '" + fn.name +
                        "' may only read datapacks of its engine '" + fn.engine + "', not '" +
                        in.engine + "'");
      }
    }
  }
}

// Engines whose next request usually comes within this time wait for it by yielding the CPU
// rather than sleeping (EngineServer::set_spin_us): the slowest engine of a lock-step loop
// then starts its next step without a wake-up; the others, which wait longer, sleep.
int engine_spin_us() {
  if (const char* s = std::getenv("CONVOY_ENGINE_SPIN_US")) return std::atoi(s);
  return 300;
}

// Each local engine gets two arenas of this size (virtual: pages are used once written).
size_t shm_arena_bytes() {
  if (const char* s = std::getenv("CONVOY_SHM_MB")) return std::strtoull(s, nullptr, 10) << 20;
  return size_t{512} << 20;
}

void launch_engine(loop::EngineHandle& handle, const config::SimulationConfig& cfg) {
  const auto& ec = handle.config();
  if (ec.launch_type == "EmptyLaunchCommand") {
    if (ec.server_address.empty()) {
      throw UserError(cfg.file.string() + ": " + ec.pointer +
                      "/ServerAddress: EmptyLaunchCommand needs the address of the running "
                      "engine");
    }
    auto channel = transport::make_grpc_channel(ec.server_address, deadline_after(10.0));
    if (!channel) {
      throw EngineError(ec.name, "engine '" + ec.name + "': nothing answers at ServerAddress " +
                                     ec.server_address + " (EmptyLaunchCommand)");
    }
    handle.attach(std::move(channel), launch::ChildProcess());
    return;
  }
  int fds[2];
  transport::make_socket_pair(fds);
  launch::LaunchSpec spec;
  spec.program = ec.proc_cmd.empty() ? "convoy-engine-" + ec.type : ec.proc_cmd;
  spec.args = ec.proc_start_params;
  spec.args.insert(spec.args.end(),
                   {"--convoy-fd", "3", "--convoy-spin-us", std::to_string(engine_spin_us())});
  spec.pass_fds = {fds[1]};
  if (size_t bytes = shm_arena_bytes(); bytes > 0) {  // CONVOY_SHM_MB=0: blobs inline
    handle.create_arenas(bytes);
    spec.args.insert(spec.args.end(), {"--convoy-shm-out", "4", "--convoy-shm-in", "5"});
    spec.pass_fds.push_back(handle.out_arena_fd());
    spec.pass_fds.push_back(handle.in_arena_fd());
  }
  spec.env = ec.env_params;
  spec.env.push_back("CONVOY_RUN_DIR=" + handle.log_file().parent_path().parent_path().string());
  spec.env.push_back("CONVOY_BIN_DIR=" + bin_dir().string());
  spec.env.push_back("CONVOY_SHARE_DIR=" + share_dir().string());
  spec.log_file = handle.log_file();
  spec.working_dir = cfg.dir;
  spec.search_dirs = {bin_dir()};

  launch::ChildProcess child;
  try {
    child = launch::launch(spec);
  } catch (const std::exception& e) {
    close(fds[0]);
    close(fds[1]);
    throw UserError(cfg.file.string() + ": " + ec.pointer + ": engine '" + ec.name +
                    "': " + e.what());
  }
  close(fds[1]);
  handle.attach(transport::make_socket_channel(fds[0]), child);
}

// summary.json: what an engine or function of the run wrote there (a JSON object, e.g. an
// experiment's own figures), with the coordinator's fields on top.
void write_summary(const fs::path& file, const config::SimulationConfig& cfg,
                   const loop::FtiLoop* loop, double wall_s, double loop_wall_s, int exit_code,
                   const std::string& error) {
  nlohmann::json j = nlohmann::json::object();
  if (std::ifstream in(file); in) {
    j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) j = nlohmann::json::object();
  }
  j["simulation"] = cfg.name;
  j["config"] = cfg.file.string();
  j["exit_code"] = exit_code;
  j["error"] = error;
  j["wall_s"] = wall_s;
  j["cycles"] = loop ? loop->cycles() : 0;
  const double sim_s = loop ? static_cast<double>(loop->sim_time_ns()) * 1e-9 : 0.0;
  j["sim_time_s"] = sim_s;
  // The loop alone, without start-up and shutdown: simulated over wall-clock time.
  j["loop_wall_s"] = loop_wall_s;
  j["real_time_factor"] = loop_wall_s > 0 ? sim_s / loop_wall_s : 0.0;
  std::ofstream(file) << j.dump(2) << "\n";
}

}  // namespace

int run_simulation(const RunOptions& options) {
  install_signal_handlers();
  RunLog log;
  log.quiet = options.quiet;

  config::SimulationConfig cfg;
  try {
    cfg = config::load_simulation_config(fs::absolute(options.config_file), options.overrides,
                                         share_dir());
  } catch (const config::ConfigError& e) {
    log.error(e.what());
    return kExitUserError;
  }
  fs::path run_dir;
  try {
    run_dir = make_run_dir(options, cfg.name);
  } catch (const std::exception& e) {
    log.error(std::string("cannot create the run folder: ") + e.what());
    return kExitUserError;
  }
  log.open(run_dir / "logs" / "coordinator.log");
  log.info("run folder: " + run_dir.string());
  for (const auto& w : cfg.warnings) log.info("warning: " + w);
  std::ofstream(run_dir / "config.json") << cfg.json.dump(2) << "\n";
  std::error_code stale;
  fs::remove(run_dir / "summary.json", stale);  // a reused folder's; the run writes its own
  if (cfg.loop != "FTILoop")
    log.info("warning: SimulationLoop " + cfg.loop + " is not available yet; running FTILoop");
  if (cfg.datapack_processor != "tf")
    log.info("warning: DataPackProcessor " + cfg.datapack_processor +
             " is not available yet; running tf");
  for (const char* key :
       {"StatusFunction", "ExternalProcesses", "ConnectROS", "ConnectMQTT", "ComputationalGraph"}) {
    if (cfg.json.contains(key) && !cfg.json[key].empty()) {
      log.info(std::string("warning: ") + key + " is not supported yet; ignored");
    }
  }

  std::vector<std::unique_ptr<loop::EngineHandle>> engines;
  std::unique_ptr<loop::FtiLoop> fti;
  double loop_wall = 0;
  std::optional<SteadyClock::time_point> loop_start;
  std::FILE* csv = nullptr;
  auto t0 = SteadyClock::now();
  int code = kExitOk;
  std::string error;
  {
    python::Interpreter interpreter;
    python::FunctionRuntime runtime(cfg.argument_passing == "reference");
    std::vector<python::LoadedFunction> functions;
    try {
      for (const auto& f : cfg.functions) {
        if (!f.active) continue;
        interpreter.add_path(f.file.parent_path());
        for (auto& fn : runtime.load(f.name, f.file)) functions.push_back(std::move(fn));
      }
      check_functions(functions, cfg);

      for (const auto& ec : cfg.engines) {
        engines.push_back(
            std::make_unique<loop::EngineHandle>(ec, run_dir / "logs" / (ec.name + ".log")));
        engines.back()->index = engines.size() - 1;
      }
      for (auto& e : engines) launch_engine(*e, cfg);
      log.info("started " + std::to_string(engines.size()) + " engines");

      for (auto& e : engines) {
        engine::Request request;
        auto* init = request.mutable_initialize();
        init->set_engine_name(e->name());
        init->set_config_json(e->config().json.dump());
        init->set_timestep_ns(e->config().timestep_ns);
        double timeout =
            e->config().command_timeout_s > 0 ? std::max(e->config().command_timeout_s, 60.0) : 0;
        e->start(request, "Initialize", timeout);
      }
      for (auto& e : engines) {
        engine::Reply reply;
        e->finish(&reply);
      }
      log.info("engines initialized in " +
               std::to_string(std::chrono::duration<double>(SteadyClock::now() - t0).count()) +
               " s");

      std::vector<loop::EngineHandle*> handles;
      for (auto& e : engines) handles.push_back(e.get());
      fti = std::make_unique<loop::FtiLoop>(handles, runtime, functions);
      csv = std::fopen((run_dir / "steps.csv").c_str(), "w");
      if (csv) std::setvbuf(csv, nullptr, _IOFBF, 1 << 20);
      fti->set_step_log(csv);
      if (!options.quiet) {
        auto start = SteadyClock::now();
        fti->set_progress(5.0, [&log, start, timeout = cfg.timeout_ns](int64_t sim_ns) {
          double wall = std::chrono::duration<double>(SteadyClock::now() - start).count();
          std::ostringstream s;
          s.precision(1);
          s << std::fixed << "progress: simulated " << sim_ns * 1e-9 << " s";
          if (timeout > 0) s << " of " << timeout * 1e-9 << " s";
          s << " (" << sim_ns * 1e-9 / wall << "x real time)";
          log.info(s.str());
        });
      }
      loop_start = SteadyClock::now();
      fti->prime();
      fti->run(cfg.timeout_ns);
      if (interrupted()) {
        code = kExitInterrupted;
        error = "interrupted by signal " + std::to_string(interrupt_signal().load());
      }
    } catch (const UserError& e) {
      code = kExitUserError;
      error = e.what();
    } catch (const EngineError& e) {
      code = interrupted() ? kExitInterrupted : kExitEngineError;
      error = interrupted() ? "interrupted by signal " + std::to_string(interrupt_signal().load())
                            : e.what();
    } catch (const FunctionError& e) {
      code = kExitFunctionError;
      error = e.what();
    } catch (const std::exception& e) {
      code = kExitInternal;
      error = e.what();
    }
    if (loop_start)
      loop_wall = std::chrono::duration<double>(SteadyClock::now() - *loop_start).count();
    if (code == kExitInterrupted) {
      log.info(error + ": shutting the engines down (Ctrl-C again to kill them)");
      interrupt_signal().store(0);
    } else if (code != kExitOk) {
      log.error(error);
    }
    // Shut everything down, whatever happened.
    for (auto& e : engines) {
      std::string err = e->shutdown(code == kExitOk ? 10.0 : 3.0);
      if (!err.empty()) {
        log.error(err + "\n--- " + e->log_file().string() + " (last lines) ---\n" + e->log_tail());
        if (code == kExitOk) code = kExitEngineError;
        if (error.empty()) error = err;
      }
    }
    if (csv) std::fclose(csv);
  }
  double wall = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  write_summary(run_dir / "summary.json", cfg, fti.get(), wall, loop_wall, code, error);
  if (fti) {
    std::ostringstream s;
    s << "simulated " << static_cast<double>(fti->sim_time_ns()) * 1e-9 << " s in " << wall
      << " s wall, " << fti->cycles() << " loop cycles";
    log.info(s.str());
  }
  std::string listing;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(run_dir, ec)) {
    if (entry.is_regular_file()) listing += "\n  " + entry.path().filename().string();
  }
  log.info("run folder: " + run_dir.string() + listing);
  return code;
}

}  // namespace convoy::app
