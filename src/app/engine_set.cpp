#include "app/engine_set.h"

#include <unistd.h>

#include <algorithm>
#include <cstdlib>

#include "app/simulation.h"
#include "core/clock.h"
#include "core/error.h"
#include "transport/frame_socket.h"
#include "transport/grpc_security.h"

namespace convoy::app {
namespace {

// Shutdown deadlines (EngineSet::shut_down).
constexpr double kCleanShutdownS = 60.0, kFailedShutdownS = 3.0;

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

}  // namespace

EngineSet::EngineSet(const config::SimulationConfig& cfg, const std::filesystem::path& log_dir)
    : cfg_(cfg) {
  for (const auto& ec : cfg.engines) {
    engines_.push_back(std::make_unique<loop::EngineHandle>(ec, log_dir / (ec.name + ".log")));
    engines_.back()->index = engines_.size() - 1;
  }
}

std::vector<loop::EngineHandle*> EngineSet::handles() const {
  std::vector<loop::EngineHandle*> out;
  for (const auto& e : engines_) out.push_back(e.get());
  return out;
}

void EngineSet::launch() {
  for (auto& e : engines_) launch(*e);
}

void EngineSet::attach(
    const std::function<std::unique_ptr<transport::EngineChannel>(const config::EngineConfig&)>&
        channel) {
  for (auto& e : engines_) e->attach(channel(e->config()));
}

void EngineSet::launch(loop::EngineHandle& handle) {
  const auto& ec = handle.config();
  if (ec.launch_type == "EmptyLaunchCommand") {
    if (ec.server_address.empty()) {
      throw UserError(cfg_.file.string() + ": " + ec.pointer +
                      "/ServerAddress: EmptyLaunchCommand needs the address of the running "
                      "engine");
    }
    transport::ClientSecurity security;
    security.tls = ec.server_tls;
    security.ca_file = ec.tls_ca_file;
    security.cert_file = ec.tls_cert_file;
    security.key_file = ec.tls_key_file;
    security.server_name = ec.tls_server_name;
    security.token = ec.auth_token;
    if (security.token.empty()) {
      if (const char* env = std::getenv(transport::kTokenEnv)) security.token = env;
    }
    std::unique_ptr<transport::EngineChannel> channel;
    try {
      channel = transport::make_grpc_channel(ec.server_address, deadline_after(10.0), security);
    } catch (const std::invalid_argument& e) {
      throw UserError(cfg_.file.string() + ": " + ec.pointer + ": " + e.what());
    } catch (const std::runtime_error& e) {
      throw EngineError(ec.name, "engine '" + ec.name + "': " + e.what());
    }
    if (!channel) {
      throw EngineError(ec.name, "engine '" + ec.name + "': nothing answers at ServerAddress " +
                                     ec.server_address + " (EmptyLaunchCommand)");
    }
    handle.attach(std::move(channel));
    return;
  }
  int fds[2];
  try {
    transport::make_socket_pair(fds);
  } catch (const std::exception& e) {  // e.g. out of file descriptors
    throw EngineError(ec.name, "engine '" + ec.name + "': cannot start: " + e.what());
  }
  launch::LaunchSpec spec;
  spec.program = ec.proc_cmd.empty() ? "convoy-engine-" + ec.type : ec.proc_cmd;
  spec.args = ec.proc_start_params;
  spec.args.insert(spec.args.end(),
                   {"--convoy-fd", "3", "--convoy-spin-us", std::to_string(engine_spin_us())});
  spec.pass_fds = {fds[1]};
  if (size_t bytes = shm_arena_bytes(); bytes > 0) {  // CONVOY_SHM_MB=0: blobs inline
    try {
      handle.create_arenas(bytes);
    } catch (const std::exception& e) {
      close(fds[0]);
      close(fds[1]);
      throw EngineError(
          ec.name, "engine '" + ec.name + "': cannot create its shared-memory arenas: " + e.what());
    }
    spec.args.insert(spec.args.end(), {"--convoy-shm-out", "4", "--convoy-shm-in", "5"});
    spec.pass_fds.push_back(handle.out_arena_fd());
    spec.pass_fds.push_back(handle.in_arena_fd());
  }
  spec.env = ec.env_params;
  spec.env.push_back("CONVOY_RUN_DIR=" + handle.log_file().parent_path().parent_path().string());
  spec.env.push_back("CONVOY_BIN_DIR=" + bin_dir().string());
  spec.env.push_back("CONVOY_SHARE_DIR=" + share_dir().string());
  spec.log_file = handle.log_file();
  spec.working_dir = cfg_.dir;
  spec.search_dirs = {bin_dir()};

  launch::ChildProcess child;
  try {
    child = launch::launch(spec);
  } catch (const std::exception& e) {
    close(fds[0]);
    close(fds[1]);
    throw UserError(cfg_.file.string() + ": " + ec.pointer + ": engine '" + ec.name +
                    "': " + e.what());
  }
  close(fds[1]);
  handle.attach(transport::make_socket_channel(fds[0]), child);
}

void EngineSet::initialize(RunLog& log, std::vector<EngineStartup>* startup) {
  for (auto& e : engines_) {
    engine::Request request;
    auto* init = request.mutable_initialize();
    init->set_engine_name(e->name());
    init->set_config_json(e->config().json.dump());
    init->set_timestep_ns(e->config().timestep_ns);
    // Loading a world or a model may take longer than a step.
    double timeout =
        e->config().command_timeout_s > 0 ? std::max(e->config().command_timeout_s, 60.0) : 0;
    e->start(request, "Initialize", timeout);
  }
  for (auto& e : engines_) {
    engine::Reply reply;
    e->finish(&reply);
    const auto& init = reply.initialize();
    e->registered.assign(init.registered().begin(), init.registered().end());
    for (const auto& w : init.warnings()) log.info("warning: engine '" + e->name() + "': " + w);
    if (startup) {
      EngineStartup s{e->name()};
      if (init.compute_ns() > 0) s.initialize_s = init.compute_ns() * 1e-9;
      // A remote engine's process started whenever its owner started it.
      if (init.process_ns() > 0 && e->process().pid() > 0) s.process_s = init.process_ns() * 1e-9;
      startup->push_back(std::move(s));
    }
  }
}

std::string EngineSet::shut_down(bool clean, RunLog& log) {
  std::string first;
  for (auto& e : engines_) {
    // A clean shutdown is when engines write their outputs (a video's last frames, a score
    // over a whole lap: 10 s was too little for the autonomous-driving evaluator on 2 busy
    // cores), so it gets a minute, as Initialize does; after a failure, 3 s.
    std::string err = e->shutdown(clean ? kCleanShutdownS : kFailedShutdownS);
    if (err.empty()) continue;
    log.error(err + "\n--- " + e->log_file().string() + " (last lines) ---\n" + e->log_tail());
    if (first.empty()) first = err;
  }
  return first;
}

}  // namespace convoy::app
