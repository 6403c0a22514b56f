// The simulation config (NRP-Core's simulation_config.json): loaded once, validated against
// JSON Schemas, defaults filled, paths made absolute, and parsed into typed structs.
//
// Schemas live in the share directory:
//   <share>/schemas/simulation.schema.json   top-level keys and EngineBase (seed tables A1/A2)
//   <share>/engines/<type>.schema.json       extra keys of one engine type, merged with EngineBase
//   <share>/engines/<alias>.alias            file whose content is the real type name
// Properties marked "x-convoy-path" are resolved against the config file's directory;
// "x-convoy-path-must-exist" makes a missing file an error. Strings marked "x-convoy-file-name"
// (in engine types' schemas) must pass name_problem(), as EngineName does.
//
// Every error reads `<config file>: <JSON pointer>: <message>`, for example
//   simulation_config.json: /EngineConfigs/2/EngineTimestep: must be > 0, got 0
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace convoy::config {

struct EngineConfig {
  std::string name;
  std::string type;            // after alias resolution
  std::string requested_type;  // as written in the file
  std::string proc_cmd;        // EngineProcCmd, empty = engine default
  std::vector<std::string> proc_start_params;
  std::vector<std::string> env_params;    // "KEY=VALUE"
  std::string launch_type = "BasicFork";  // or "EmptyLaunchCommand"
  int64_t timestep_ns = 10'000'000;
  double command_timeout_s = 0;  // <= 0: no timeout
  std::string server_address;    // "" = none
  // ServerTLS (an EmptyLaunchCommand engine reached over TLS) and AuthToken.
  bool server_tls = false;
  std::string tls_ca_file, tls_cert_file, tls_key_file, tls_server_name;
  std::string auth_token;  // "" = none given (then $CONVOY_ENGINE_TOKEN); never logged
  std::string pointer;     // e.g. "/EngineConfigs/1", for error messages
  nlohmann::json json;     // the full engine object, defaults filled, paths absolute
};

struct FunctionConfig {
  std::string name;
  std::filesystem::path file;  // absolute
  bool active = true;
  std::string pointer;  // e.g. "/DataPackProcessingFunctions/0"
};

// One of ExternalProcesses (NRP-Core's process_launcher.json).
struct ExternalProcessConfig {
  std::string cmd;                        // ProcCmd
  std::vector<std::string> start_params;  // ProcStartParams
  std::vector<std::string> env_params;    // ProcEnvParams, "KEY=VALUE"
  std::string launch_type = "BasicFork";  // LaunchCommand/LaunchType, or "EmptyLaunchCommand"
  std::string pointer;                    // "/ExternalProcesses/0"
};

// The EventLoop object (used by SimulationLoop EventLoop).
struct EventLoopConfig {
  double timeout_s = 0;  // 0: no timeout
  double timestep_s = 0.01;
  double timestep_warn_threshold_s = 0.001;
  std::string execution_mode = "AllNodes";  // or "OutputDriven"
};

struct MqttNodeConfig {
  std::string broker = "localhost:1883";
  std::string client_name = "NRP-core-client";
};

struct RosNodeConfig {
  std::string node_name = "nrp_core";
};

struct SimulationConfig {
  std::filesystem::path file, dir;  // absolute
  std::string name, description;
  std::string loop;                   // "FTILoop" or "EventLoop"
  std::string process_launcher_type;  // "Basic"
  std::string datapack_processor;     // "tf" or "cg"
  std::string argument_passing;       // "value" or "reference"
  int64_t timeout_ns = 0;             // 0 = run until interrupted
  bool record = false;                // Record: write recording.mcap (docs/recording.md)
  bool record_blobs = false;          // RecordBlobs: with the blobs (implies record)
  int64_t timestep_ns = 10'000'000;
  std::vector<EngineConfig> engines;
  std::vector<FunctionConfig> functions;  // DataPackProcessingFunctions, in config order
  std::optional<FunctionConfig> status_function;
  std::vector<std::filesystem::path> computational_graph;  // absolute, in config order
  EventLoopConfig event_loop;
  std::optional<MqttNodeConfig> mqtt_node;  // present: MQTTNode was given
  std::optional<RosNodeConfig> ros_node;    // present: ROSNode was given
  std::vector<ExternalProcessConfig> external_processes;
  nlohmann::json json;                // whole config after overrides, defaults, path resolution
  std::vector<std::string> warnings;  // e.g. unknown keys, same format as errors
};

// Limits on hostile or mistaken input, checked before the config is used.
// A config file larger than this is refused before it is read.
constexpr size_t kMaxConfigBytes = size_t{64} << 20;
// More engines than this are refused at load (each is a process with two shared-memory
// arenas and a socket; realistic experiments have a handful).
constexpr size_t kMaxEngines = 1024;
// Names that become part of a file name (logs/<EngineName>.log, the run folder
// <SimulationName>-<date>-<time>-<pid>) are at most this long, so that the file name stays
// under the usual 255-byte limit.
constexpr size_t kMaxNameBytes = 200;

// Why `name` cannot be part of a file name inside the run folder, or "" if it can: it must not
// be empty, longer than kMaxNameBytes, contain '/', '\\', "..", NUL or other control
// characters. Anything else (spaces, non-ASCII) is allowed, as in NRP-Core.
std::string name_problem(const std::string& name);

// A user mistake in the config; what() holds one line per problem.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads `file`, applies `overrides` ("Key=Value", Key a top-level key or a path such as
// "EngineConfigs/0/EngineTimestep" or "EngineConfigs.0.EngineTimestep"; Value parsed as JSON
// when it parses, else taken as a string), validates, fills defaults and resolves paths.
// Throws ConfigError listing every problem found.
SimulationConfig load_simulation_config(const std::filesystem::path& file,
                                        const std::vector<std::string>& overrides,
                                        const std::filesystem::path& share_dir);

// Reads ComputationalGraph, EventLoop, MQTTNode, ROSNode and ExternalProcesses from `doc`
// (validated, defaults filled, paths absolute) into `config`; adds "<pointer>: <message>" to
// `errors` for what the schema cannot check and to `warnings` for keys that are ignored.
void read_graph_keys(const nlohmann::json& doc, SimulationConfig& config,
                     std::vector<std::pair<std::string, std::string>>* errors,
                     std::vector<std::pair<std::string, std::string>>* warnings);

// Applies one "Key=Value" override to `config`. Throws ConfigError on bad syntax.
void apply_override(nlohmann::json& config, const std::string& override_text);

// Converts seconds to nanoseconds, rounded to the nearest nanosecond.
int64_t seconds_to_ns(double seconds);

}  // namespace convoy::config
