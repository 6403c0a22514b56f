// EngineType "datatransfer_grpc_engine" (NRP-Core's DataTransfer engine; registered in
// datatransfer_engine.cpp): logs the datapacks that transceiver functions send to it into files
// and streams them to an MQTT broker. It provides no datapacks.
//
// Config keys (schema.json; NRP-Core 1.4's names and defaults):
//   MQTTBroker             "localhost:1883"  host:port of the broker (tcp:// or mqtt:// allowed)
//   MQTTPrefix             ""                topics: <MQTTPrefix>/nrp_simulation/<simulationID>/...
//   simulationID           "0"
//   streamDataPackMessage  true              MQTT messages hold whole datapacks, or their data
//   dataDirectory          "data"            relative: in the run folder ($CONVOY_RUN_DIR)
//   dumps                  []                [{name, network (false), file (false)}]
//   ProtobufPackages       ["Dump"]          NRP-Core's packages of the datapacks it takes
//                                            (all are compiled in; another one's: one warning)
// Datapacks read (set_datapack): those named in `dumps`, JSON or any protobuf message. Another
// name is an error naming the datapack and the engine, as in NRP-Core. Protobuf datapacks are
// read by the datapack library (datapack/nrp.h): bytes fields that travelled as blobs are
// whole again, and Convoy's standard messages that are NRP-Core's Gazebo messages
// (convoy.data.Camera / Joint / Link) are dumped and streamed as Gazebo.Camera / Joint / Link,
// as NRP-Core's engine would receive them from the same TF.
//
// Files: <dataDirectory>/<YYYYMMDD-HHMMSS>-<pid>/<name>-<resets>.data, one line per datapack
// received (dump_format.h: Dump.String, Dump.ArrayFloat in NRP-Core's formats; other
// messages one CSV column per field, bytes beyond 1 KiB as "<N bytes>"), the first column the
// engine's time when it received it. The folder name carries the wall-clock time as NRP-Core's
// does; the contents depend on simulated time only.
//
// MQTT (QoS 1, published from libmosquitto's own thread, so the loop never waits for the
// network), under <base> = [<MQTTPrefix>/]nrp_simulation/<simulationID>:
//   <base>/welcome       "NRP-core is connected!" (retained) at start; "Bye! NRP-core is
//                        disconnecting!" at shutdown, after which retained topics are cleared
//   <base>/data          retained JSON list [{"topic", "type"}] of the data topics; "type" is
//                        "" until the first datapack of the topic, then its protobuf type name
//                        or "json"
//   <base>/data/<name>   each datapack: streamDataPackMessage true: a serialized
//                        EngineGrpc.DataPackMessage (proto/nrp_protobuf/engine_grpc.proto),
//                        {"datapackId", "data"} (JSON);
//                        false: the message's bytes, or the JSON text. "reset" on reset.
//   <base>/time          the engine's time in seconds after each step
// A broker that cannot be reached at start (nothing listens, refused, no answer in 5 s): one
// warning naming it (in the engine's log and the coordinator's), then file dumps only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "datapack/registry.h"
#include "engine/engine.h"
#include "mqtt_client.h"

namespace convoy::engines {

class DataTransferEngine final : public Engine {
 public:
  ~DataTransferEngine() override;
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override;
  int64_t step(int64_t duration_ns) override;
  void set_datapack(const datapack::View& datapack) override;
  void get_datapack(const engine::DataPackId&, datapack::Builder&) override {}
  void reset() override;
  void shutdown() override;
  std::vector<std::string> take_warnings() override;

 private:
  struct Dump {
    std::string name;
    bool network = false;
    bool file = false;
    std::string topic;           // <base>/data/<name>
    std::string type;            // type of the last datapack received ("" before the first)
    std::string header_type;     // type whose header the file holds
    std::filesystem::path path;  // current file
    std::ofstream out;
    bool publish_warned = false;
    bool unknown_type_warned = false;
  };

  void warn(const std::string& text);
  void open_file(Dump& dump);
  void publish_topics();
  // Publishes a datapack's payload on its topic (and the topic list when its type changes).
  void publish(Dump& dump, const std::string& type, const std::string& payload);
  // Warns once per package when a datapack's type is in an NRP-Core package that
  // ProtobufPackages does not list.
  void check_package(const Dump& dump, const datapack::TypeInfo& type);
  void write_line(Dump& dump, const std::string& line);

  std::string name_;
  int64_t time_ns_ = 0;
  std::string broker_text_;
  std::string base_;
  bool stream_message_ = true;
  std::filesystem::path folder_;
  int resets_ = 0;
  std::set<std::string> packages_, warned_packages_;
  std::vector<std::unique_ptr<Dump>> dumps_;
  std::unique_ptr<datatransfer::MqttClient> mqtt_;
  bool lost_warned_ = false;
  std::vector<std::string> warnings_;
};

}  // namespace convoy::engines
