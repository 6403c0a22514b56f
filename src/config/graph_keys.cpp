// The keys of NRP-Core 1.4's computational graph and event loop, and ExternalProcesses: read
// from the validated config (simulation_config.cpp calls read_graph_keys).
#include <string>

#include "config/simulation_config.h"

namespace convoy::config {

namespace {

using Issues = std::vector<std::pair<std::string, std::string>>;

void read_external_processes(const nlohmann::json& doc, SimulationConfig& config, Issues* errors) {
  if (!doc.contains("ExternalProcesses")) return;
  const nlohmann::json& list = doc["ExternalProcesses"];
  for (size_t i = 0; i < list.size(); ++i) {
    const nlohmann::json& p = list[i];
    ExternalProcessConfig proc;
    proc.pointer = "/ExternalProcesses/" + std::to_string(i);
    proc.cmd = p["ProcCmd"].get<std::string>();
    if (proc.cmd.find_first_not_of(" \t\n") == std::string::npos)
      errors->emplace_back(proc.pointer + "/ProcCmd", "is blank");
    proc.start_params = p.value("ProcStartParams", std::vector<std::string>{});
    proc.env_params = p.value("ProcEnvParams", std::vector<std::string>{});
    for (size_t k = 0; k < proc.env_params.size(); ++k) {
      const std::string& kv = proc.env_params[k];
      if (kv.find('=') == std::string::npos || kv[0] == '=') {
        errors->emplace_back(proc.pointer + "/ProcEnvParams/" + std::to_string(k),
                             "must be KEY=VALUE, got \"" + kv + "\"");
      }
    }
    if (p.contains("LaunchCommand"))
      proc.launch_type = p["LaunchCommand"].value("LaunchType", "BasicFork");
    config.external_processes.push_back(std::move(proc));
  }
}

void read_event_loop(const nlohmann::json& doc, SimulationConfig& config) {
  if (doc.contains("EventLoop")) {
    const nlohmann::json& e = doc["EventLoop"];
    config.event_loop.timeout_s = e.value("Timeout", 0.0);
    config.event_loop.timestep_s = e.value("Timestep", 0.01);
    config.event_loop.timestep_warn_threshold_s = e.value("TimestepWarnThreshold", 0.001);
    config.event_loop.execution_mode = e.value("ExecutionMode", "AllNodes");
  }
  if (doc.contains("MQTTNode")) {
    MqttNodeConfig mqtt;
    mqtt.broker = doc["MQTTNode"].value("MQTTBroker", mqtt.broker);
    mqtt.client_name = doc["MQTTNode"].value("ClientName", mqtt.client_name);
    config.mqtt_node = mqtt;
  }
  if (doc.contains("ROSNode")) {
    RosNodeConfig ros;
    ros.node_name = doc["ROSNode"].value("NodeName", ros.node_name);
    config.ros_node = ros;
  }
}

}  // namespace

void read_graph_keys(const nlohmann::json& doc, SimulationConfig& config, Issues* errors,
                     Issues* warnings) {
  if (doc.contains("ComputationalGraph")) {
    for (const auto& f : doc["ComputationalGraph"])
      config.computational_graph.emplace_back(f.get<std::string>());
  }
  read_event_loop(doc, config);
  read_external_processes(doc, config, errors);

  const bool cg = doc.value("DataPackProcessor", "tf") == "cg";
  const bool event_loop = doc.value("SimulationLoop", "FTILoop") == "EventLoop";
  if (cg) {
    if (config.computational_graph.empty())
      warnings->emplace_back("/ComputationalGraph",
                             "DataPackProcessor is cg but no graph file is given: nothing relays "
                             "datapacks between the engines");
  }
  if (cg || event_loop) {
    // With the EventLoop the engines' FTILoop always runs the graph (NRP-Core's slave mode).
    const std::string why = cg ? "DataPackProcessor is cg" : "SimulationLoop is EventLoop";
    if (doc.contains("DataPackProcessingFunctions") && !doc["DataPackProcessingFunctions"].empty())
      warnings->emplace_back(
          "/DataPackProcessingFunctions",
          "ignored: " + why + " (as in NRP-Core, the graph replaces the transceiver functions)");
    if (doc.contains("StatusFunction"))
      warnings->emplace_back("/StatusFunction",
                             "ignored: " + why + " (NRP-Core runs it with tf only)");
  } else if (!event_loop && !config.computational_graph.empty()) {
    warnings->emplace_back("/ComputationalGraph",
                           "ignored: used with DataPackProcessor cg or SimulationLoop EventLoop");
  }
  if (!event_loop && doc.contains("EventLoop"))
    warnings->emplace_back("/EventLoop", "ignored: used with SimulationLoop EventLoop only");
}

}  // namespace convoy::config
