#include "app/event_loop_run.h"

#include <chrono>
#include <fstream>
#include <optional>
#include <string>

#include "app/external_processes.h"
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

// Connects, loads the graph, starts the external processes (their errors are UserErrors).
void set_up(py::object& run, const config::SimulationConfig& cfg, ExternalProcesses& external,
            RunLog& log) {
  try {
    run.attr("connect")();
  } catch (py::error_already_set& e) {
    throw UserError(message_of(e));
  }
  if (cfg.mqtt_node) {
    python::set_environment("CONVOY_MQTT_BROKER", cfg.mqtt_node->broker, true);
    if (!run.attr("broker").is_none())
      log.info("MQTT: started mosquitto on " + cfg.mqtt_node->broker +
               " for the run (logs/mosquitto.log)");
  }
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

}  // namespace

Outcome run_event_loop(const config::SimulationConfig& cfg, const fs::path& run_dir, RunLog& log,
                       LoopFigures* figures) {
  ExternalProcesses external(cfg, run_dir / "logs");
  Outcome outcome;
  py::object run;
  try {
    run = py::module_::import("nrp_core.event_loop._loop")
              .attr("EventLoopRun")(run_config(cfg), (run_dir / "logs").string());
    set_up(run, cfg, external, log);
    log.info("EventLoop: a cycle every " + std::to_string(cfg.event_loop.timestep_s) +
             " s, timeout " + std::to_string(cfg.event_loop.timeout_s) + " s");
    figures->ran = true;
    const auto t0 = SteadyClock::now();
    std::optional<ExternalProcesses::Failure> failed;
    auto should_stop = [&] {
      if (!failed) failed = external.first_failure();
      return interrupted() || failed.has_value();
    };
    try {
      figures->cycles = run.attr("run")(py::cpp_function(should_stop)).cast<uint64_t>();
    } catch (py::error_already_set& e) {
      throw FunctionError(graph_label(cfg) + ": " + message_of(e));
    }
    figures->wall_s = std::chrono::duration<double>(SteadyClock::now() - t0).count();
    figures->sim_time_ns = static_cast<int64_t>(figures->wall_s * 1e9);
    if (!failed) failed = external.first_failure();
    if (interrupted())
      outcome = {kExitInterrupted, interrupted_text()};
    else if (failed)
      outcome = failure_outcome(*failed, run_dir);
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

}  // namespace convoy::app
