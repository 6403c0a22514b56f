#include "app/event_loop_run.h"

#include <atomic>
#include <chrono>
#include <exception>
#include <fstream>
#include <optional>
#include <string>
#include <thread>

#include "app/external_processes.h"
#include "app/session.h"
#include "app/simulation.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "python/interpreter.h"

namespace convoy::app {

namespace fs = std::filesystem;
namespace py = pybind11;

namespace {

// What EventLoopRun takes: the keys of the config it uses, with Convoy's parsed values.
py::dict run_config(const config::SimulationConfig& cfg) {
  py::dict loop;
  loop["Timeout"] = cfg.event_loop.timeout_s;
  loop["Timestep"] = cfg.event_loop.timestep_s;
  loop["TimestepWarnThreshold"] = cfg.event_loop.timestep_warn_threshold_s;
  loop["ExecutionMode"] = cfg.event_loop.execution_mode;
  py::dict out;
  out["EventLoop"] = loop;
  if (cfg.mqtt_node) {
    py::dict mqtt;
    mqtt["MQTTBroker"] = cfg.mqtt_node->broker;
    mqtt["ClientName"] = cfg.mqtt_node->client_name;
    out["MQTTNode"] = mqtt;
  }
  if (cfg.ros_node) {
    py::dict ros;
    ros["NodeName"] = cfg.ros_node->node_name;
    out["ROSNode"] = ros;
  }
  return out;
}

// A ComputationalGraphError's own text (it names the key, file or node), else the traceback.
std::string message_of(py::error_already_set& e) {
  try {
    py::object cge = py::module_::import("nrp_core.event_loop").attr("ComputationalGraphError");
    if (e.matches(cge)) return py::str(e.value()).cast<std::string>();
  } catch (...) {
  }
  return python::format_exception(e);
}

std::string graph_label(const config::SimulationConfig& cfg) {
  std::string names;
  for (const auto& f : cfg.computational_graph)
    names += (names.empty() ? "" : ", ") + f.filename().string();
  return "computational graph (" + names + ")";
}

// After a GraphClients connected: exports the broker to the run's processes
// ($CONVOY_MQTT_BROKER) and says what was started for the run.
void announce(const py::object& clients, const config::SimulationConfig& cfg, RunLog& log) {
  if (cfg.mqtt_node) {
    python::set_environment("CONVOY_MQTT_BROKER", cfg.mqtt_node->broker, true);
    if (!clients.attr("broker").is_none())
      log.info("MQTT: started mosquitto on " + cfg.mqtt_node->broker +
               " for the run (logs/mosquitto.log)");
  }
  py::object ros = clients.attr("ros");
  if (!ros.is_none() && !ros.attr("master").is_none())
    log.info("ROS: started rosmaster on " + ros.attr("master_uri").cast<std::string>() +
             " for the run (logs/rosmaster.log)");
}

// Connects, loads the graph, starts the external processes (their errors are UserErrors).
void set_up(py::object& run, const config::SimulationConfig& cfg, ExternalProcesses& external,
            RunLog& log) {
  try {
    run.attr("connect")();
  } catch (py::error_already_set& e) {
    throw UserError(message_of(e));
  }
  announce(run.attr("clients"), cfg, log);
  py::list files;
  for (const auto& f : cfg.computational_graph) files.append(f.string());
  try {
    run.attr("load")(files, cfg.dir.string());
  } catch (py::error_already_set& e) {
    throw UserError(graph_label(cfg) + ": " + message_of(e));
  }
  external.start(log);
}

// The last line of `log` that says something, for a failed process's message.
std::string last_line(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

// A failed external process (an asynchronous engine with a bad config...) ends the run: exit 2
// when it exited with status 2 (Convoy's and NRP-Core's "bad input"), else 3.
Outcome failure_outcome(const ExternalProcesses::Failure& f, const fs::path& run_dir) {
  const std::string log = fs::relative(f.log, run_dir).string();
  const std::string last = last_line(f.log);
  const bool user = f.what.size() > 2 && f.what.compare(f.what.size() - 2, 2, " 2") == 0;
  return {user ? kExitUserError : kExitEngineError,
          "external process " + f.what + (last.empty() ? "" : ": " + last) + " (" + log + ")"};
}

// The engines' FTILoop on its own thread (NRP-Core's FTILoopSimManager::runSimulation(0) in a
// std::async): it steps the engines as fast as they go until stop(), its DataPackProcessor the
// EventLoop's graph in slave mode (python/graph_runtime.h). The thread holds no GIL: the graph
// runtime takes it for each cycle's datapacks.
class EngineThread {
 public:
  explicit EngineThread(Session& session) : session_(session) {
    thread_ = std::thread([this] {
      try {
        session_.run_steps(0, stop_);
      } catch (...) {
        error_ = std::current_exception();
      }
      ended_.store(true);
    });
  }
  ~EngineThread() { stop(); }
  // The loop ended (an error, an interrupt).
  bool ended() const { return ended_.load(); }
  // Stops the loop between cycles and waits for it (the GIL released meanwhile).
  void stop() {
    if (!thread_.joinable()) return;
    stop_.store(true);
    py::gil_scoped_release release;
    thread_.join();
  }
  std::exception_ptr error() const { return error_; }

 private:
  Session& session_;
  std::atomic<bool> stop_{false}, ended_{false};
  std::exception_ptr error_;
  std::thread thread_;
};

// Runs the EventLoop, and the engines' FTILoop beside it when there is a `session`, until the
// Timeout, an interrupt or a failure. Throws FunctionError for a node that raises, the engine
// thread's exception for an engine that fails.
Outcome run_cycles(py::object& run, const config::SimulationConfig& cfg, Session* session,
                   ExternalProcesses& external, const fs::path& run_dir, RunLog& log,
                   LoopFigures* figures) {
  log.info("EventLoop: a cycle every " + std::to_string(cfg.event_loop.timestep_s) +
           " s, timeout " + std::to_string(cfg.event_loop.timeout_s) + " s" +
           (session ? ", the engines' FTILoop beside it" : ""));
  figures->ran = true;
  const auto t0 = SteadyClock::now();
  std::optional<EngineThread> engines;
  if (session) engines.emplace(*session);
  std::optional<ExternalProcesses::Failure> failed;
  auto should_stop = [&] {
    if (!failed) failed = external.first_failure();
    return interrupted() || failed.has_value() || (engines && engines->ended());
  };
  try {
    figures->cycles = run.attr("run")(py::cpp_function(should_stop)).cast<uint64_t>();
  } catch (py::error_already_set& e) {
    throw FunctionError(graph_label(cfg) + ": " + message_of(e));
  }
  figures->wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
  figures->sim_time_ns = static_cast<int64_t>(figures->wall_s * 1e9);
  if (engines) {
    engines->stop();
    if (engines->error()) std::rethrow_exception(engines->error());
    log.info("FTILoop: " + std::to_string(session->figures().cycles) + " cycles, simulated " +
             std::to_string(session->figures().sim_time_ns * 1e-9) + " s");
  }
  if (!failed) failed = external.first_failure();
  if (interrupted()) return {kExitInterrupted, interrupted_text()};
  if (failed) return failure_outcome(*failed, run_dir);
  return {};
}

}  // namespace

Outcome run_event_loop(const config::SimulationConfig& cfg, const fs::path& run_dir, RunLog& log,
                       LoopFigures* figures, bool quiet) {
  ExternalProcesses external(cfg, run_dir / "logs");
  // With engines, the FTILoop's DataPackProcessor is the graph, whatever the config says (as in
  // NRP-Core: slave mode implies cg).
  config::SimulationConfig fti_cfg = cfg;
  fti_cfg.datapack_processor = "cg";
  std::optional<Session> session;
  Outcome outcome;
  py::object run;
  try {
    run = py::module_::import("nrp_core.event_loop._loop")
              .attr("EventLoopRun")(run_config(cfg), (run_dir / "logs").string());
    set_up(run, cfg, external, log);
    if (!cfg.engines.empty()) {
      session.emplace(fti_cfg, run_dir, log, quiet);
      session->initialize(/*keep_observations=*/false);
      // No steps.csv rows: unpaced, the FTILoop would write tens of thousands a second.
      session->loop().set_step_log(nullptr);
    }
    outcome = run_cycles(run, cfg, session ? &*session : nullptr, external, run_dir, log, figures);
  } catch (py::error_already_set& e) {
    outcome = {kExitInternal, message_of(e)};
  } catch (...) {
    outcome = outcome_of(std::current_exception());
  }
  if (outcome.code == kExitInterrupted) {
    log.info(outcome.error + ": stopping");
    interrupt_signal().store(0);
  } else if (outcome.code != kExitOk) {
    log.error(outcome.error);
  }
  if (session) {
    const std::string error = session->shut_down(outcome.code == kExitOk);
    if (!error.empty() && outcome.code == kExitOk) {
      outcome = {kExitEngineError, error};
      log.error(error);
    }
    session.reset();
  }
  external.stop(&log);  // before the broker: the engines' connections end with them
  if (run) {
    try {
      run.attr("close")();
    } catch (py::error_already_set& e) {
      log.info("warning: closing the event loop: " + message_of(e));
    }
  }
  return outcome;
}

GraphClients::GraphClients(const config::SimulationConfig& cfg, const fs::path& log_dir,
                           RunLog& log) {
  try {
    clients_ = py::module_::import("nrp_core.event_loop._clients")
                   .attr("GraphClients")(run_config(cfg), log_dir.string());
    clients_.attr("connect")();
  } catch (py::error_already_set& e) {
    clients_ = py::object();
    throw UserError(message_of(e));
  }
  clients_.attr("activate")();
  announce(clients_, cfg, log);
}

GraphClients::~GraphClients() {
  if (!clients_) return;
  try {
    clients_.attr("close")();
  } catch (py::error_already_set&) {
  }
}

}  // namespace convoy::app
