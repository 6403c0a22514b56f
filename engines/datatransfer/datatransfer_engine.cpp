// The data-transfer engine server: registers DataTransferEngine (datatransfer_engine.h).
#include "datatransfer_engine.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <utility>

#include "config/simulation_config.h"
#include "datapack/json.h"
#include "datapack/nrp.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "dump_format.h"

namespace convoy::engines {

namespace fs = std::filesystem;
using nlohmann::json;

CONVOY_REGISTER_ENGINE("datatransfer_grpc_engine", DataTransferEngine);

namespace {

constexpr auto kConnectTimeout = std::chrono::seconds(5);
constexpr auto kCloseTimeout = std::chrono::seconds(5);
// Topic segment of NRP-Core's MQTT topics.
constexpr const char* kTopicBase = "nrp_simulation";

std::string quote(const std::string& s) { return "\"" + s + "\""; }

// A numpy dtype whose elements are JSON numbers: kind 'b' (bool), 'i', 'u' or 'f', in this
// machine's (little-endian) byte order. Returns false for others (complex, strings, big-endian).
bool number_dtype(const std::string& dtype, char* kind, size_t* size) {
  if (dtype == "?" || dtype == "b" || dtype == "B") {
    *kind = dtype == "?" ? 'b' : dtype == "b" ? 'i' : 'u';
    *size = 1;
    return true;
  }
  if (dtype.size() < 3 || (dtype[0] != '<' && dtype[0] != '|' && dtype[0] != '=')) return false;
  *kind = dtype[1];
  *size = datapack::dtype_size(dtype);
  return std::strchr("biuf", *kind) != nullptr && *size > 0;
}

json element(char kind, size_t size, const char* p) {
  auto load = [&](auto v) {
    std::memcpy(&v, p, sizeof v);
    return json(v);
  };
  switch (kind) {
    case 'b':
      return json(*p != 0);
    case 'i':
      return size == 1   ? load(int8_t{})
             : size == 2 ? load(int16_t{})
             : size == 4 ? load(int32_t{})
                         : load(int64_t{});
    case 'u':
      return size == 1   ? load(uint8_t{})
             : size == 2 ? load(uint16_t{})
             : size == 4 ? load(uint32_t{})
                         : load(uint64_t{});
    default:
      return size == 4 ? load(float{}) : load(double{});
  }
}

json array_values(const datapack::NdarrayHeader& h, char kind, size_t size, const char*& p,
                  size_t dim) {
  if (dim == h.shape.size()) {
    json v = element(kind, size, p);
    p += size;
    return v;
  }
  json list = json::array();
  for (uint64_t i = 0; i < h.shape[dim]; ++i)
    list.push_back(array_values(h, kind, size, p, dim + 1));
  return list;
}

// The JSON value with its numpy arrays as nested lists, what a file or an MQTT client can read.
// Arrays of other kinds (complex, strings) become {"dtype", "shape"}.
json plain_json(const datapack::View& in, const json& value, int depth = 0) {
  if (value.is_binary()) {
    datapack::NdarrayRef a = datapack::read_ndarray(in, value);
    char kind = 0;
    size_t size = 0;
    if (!number_dtype(a.header.dtype, &kind, &size) || (kind != 'f' && size > 8) ||
        (kind == 'f' && size != 4 && size != 8)) {
      return {{"dtype", a.header.dtype}, {"shape", a.header.shape}};
    }
    const char* p = a.data.data();
    return array_values(a.header, kind, size, p, 0);
  }
  if (depth >= datapack::kMaxJsonDepth) return value;
  if (value.is_array()) {
    json out = json::array();
    for (const auto& v : value) out.push_back(plain_json(in, v, depth + 1));
    return out;
  }
  if (value.is_object()) {
    json out = json::object();
    for (const auto& [k, v] : value.items()) out[k] = plain_json(in, v, depth + 1);
    return out;
  }
  return value;
}

// NRP-Core's name of a Convoy standard message ("Gazebo.Camera" for "convoy.data.Camera"),
// "" for other types: what NRP-Core's engine would receive from the same TF.
std::string nrp_name_of(const std::string& type) {
  const google::protobuf::FileDescriptor* gazebo = datapack::nrp_package_file("Gazebo");
  for (int i = 0; gazebo && i < gazebo->message_type_count(); ++i) {
    const std::string& name = gazebo->message_type(i)->full_name();
    if (datapack::standard_type_of(name) == type) return name;
  }
  return {};
}

// The registered type, or one compiled into this program; nullptr for others.
const datapack::TypeInfo* find_type(const std::string& type) {
  auto& registry = datapack::Registry::global();
  if (const datapack::TypeInfo* info = registry.find(type)) return info;
  try {
    return &registry.add_by_name(type);
  } catch (const std::invalid_argument&) {
    return nullptr;
  }
}

std::string timestamp_folder() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return std::string(buf) + "-" + std::to_string(getpid());
}

}  // namespace

DataTransferEngine::~DataTransferEngine() {
  if (mqtt_) mqtt_->close(std::chrono::milliseconds(0));
}

void DataTransferEngine::warn(const std::string& text) {
  std::fprintf(stderr, "warning: %s\n", text.c_str());
  std::fflush(stderr);
  warnings_.push_back(text);
}

std::vector<std::string> DataTransferEngine::take_warnings() {
  return std::exchange(warnings_, {});
}

std::vector<engine::DataPackId> DataTransferEngine::initialize(const std::string& name,
                                                               const json& config, int64_t) {
  name_ = name;
  auto key_error = [](const std::string& key, const std::string& why) {
    return std::invalid_argument(key + ": " + why);
  };
  broker_text_ = config.at("MQTTBroker").get<std::string>();
  datatransfer::BrokerAddress broker;
  try {
    broker = datatransfer::parse_broker_address(broker_text_);
  } catch (const std::invalid_argument& e) {
    throw key_error("MQTTBroker", e.what() + std::string(", got ") + quote(broker_text_));
  }
  const std::string prefix = config.at("MQTTPrefix").get<std::string>();
  const std::string simulation_id = config.at("simulationID").get<std::string>();
  stream_message_ = config.at("streamDataPackMessage").get<bool>();
  base_ = (prefix.empty() ? "" : prefix + "/") + kTopicBase + "/" + simulation_id;
  if (std::string why = datatransfer::topic_problem(base_ + "/data"); !why.empty()) {
    throw key_error("MQTTPrefix / simulationID", why + ", got the topic " + quote(base_ + "/data"));
  }

  // NRP-Core's packages the engine takes (default "Dump"); Convoy has them all compiled in.
  for (const auto& p : config.value("ProtobufPackages", json::array({"Dump"}))) {
    const std::string package = p.get<std::string>();
    if (!datapack::nrp_package_file(package)) {
      std::string known;
      for (const auto& k : datapack::nrp_packages()) known += (known.empty() ? "" : ", ") + k;
      throw key_error("ProtobufPackages",
                      "unknown package " + quote(package) + " (Convoy has " + known + ")");
    }
    packages_.insert(package);
  }

  const json& dumps = config.at("dumps");
  std::vector<std::string> network_only, nowhere;
  for (size_t i = 0; i < dumps.size(); ++i) {
    const std::string key = "dumps/" + std::to_string(i) + "/name";
    auto dump = std::make_unique<Dump>();
    dump->name = dumps[i].at("name").get<std::string>();
    dump->network = dumps[i].value("network", false);
    dump->file = dumps[i].value("file", false);
    // The coordinator checked these already (x-convoy-file-name); an engine started by someone
    // else checks them itself.
    if (std::string why = config::name_problem(dump->name); !why.empty()) {
      throw key_error(key, why);
    }
    for (const auto& other : dumps_) {
      if (other->name == dump->name) {
        throw key_error(key, quote(dump->name) + " is listed twice; one entry per datapack");
      }
    }
    dump->topic = base_ + "/data/" + dump->name;
    if (dump->network) {
      if (std::string why = datatransfer::topic_problem(dump->topic); !why.empty()) {
        throw key_error(key, why + ", got the topic " + quote(dump->topic));
      }
    }
    if (!dump->network && !dump->file) nowhere.push_back(dump->name);
    if (dump->network && !dump->file) network_only.push_back(dump->name);
    dumps_.push_back(std::move(dump));
  }

  // Files: the folder of this run's dumps, and each file, before the first step.
  if (std::any_of(dumps_.begin(), dumps_.end(), [](const auto& d) { return d->file; })) {
    const std::string data_dir = config.at("dataDirectory").get<std::string>();
    fs::path dir(data_dir);
    if (dir.is_relative()) {
      const char* run_dir = std::getenv("CONVOY_RUN_DIR");
      dir = (run_dir && *run_dir ? fs::path(run_dir) : fs::current_path()) / dir;
    }
    folder_ = dir / timestamp_folder();
    std::error_code ec;
    fs::create_directories(folder_, ec);
    if (ec || !fs::is_directory(folder_)) {
      throw key_error("dataDirectory", "cannot create the folder " + folder_.string() + ": " +
                                           (ec ? ec.message() : "not a folder") + " (got " +
                                           quote(data_dir) + ")");
    }
    for (auto& d : dumps_) {
      if (d->file) open_file(*d);
    }
  }

  mqtt_ = std::make_unique<datatransfer::MqttClient>();
  const std::string client_id = (prefix.empty() ? "" : prefix + "_") + name_;
  if (std::string why = mqtt_->connect(broker, client_id, kConnectTimeout); !why.empty()) {
    std::string text = "MQTT broker " + quote(broker_text_) +
                       " (MQTTBroker) cannot be reached: " + why + "; network streaming is off";
    if (!network_only.empty()) {
      text += ", and the datapacks sent to the network only are dropped:";
      for (const auto& n : network_only) text += " " + n;
    }
    warn(text);
  } else {
    std::fprintf(stderr, "connected to the MQTT broker %s as %s; topics under %s\n",
                 broker_text_.c_str(), client_id.c_str(), base_.c_str());
    mqtt_->publish(base_ + "/welcome", "NRP-core is connected!", true);
    publish_topics();
  }
  if (!nowhere.empty()) {
    std::string text =
        "dumps with neither \"network\" nor \"file\" true (their datapacks are "
        "dropped):";
    for (const auto& n : nowhere) text += " " + n;
    warn(text);
  }

  std::vector<engine::DataPackId> ids;
  for (const auto& d : dumps_) {
    engine::DataPackId id;
    id.set_name(d->name);
    id.set_engine_name(name_);
    ids.push_back(std::move(id));
  }
  return ids;
}

void DataTransferEngine::open_file(Dump& dump) {
  if (dump.out.is_open()) dump.out.close();
  dump.path = folder_ / (dump.name + "-" + std::to_string(resets_) + ".data");
  dump.out.open(dump.path, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!dump.out) {
    throw std::runtime_error("dumps: cannot write " + dump.path.string() + ": " +
                             std::strerror(errno));
  }
  dump.header_type.clear();
}

void DataTransferEngine::publish_topics() {
  json list = json::array();
  for (const auto& d : dumps_) {
    if (d->network) list.push_back({{"topic", d->topic}, {"type", d->type}});
  }
  mqtt_->publish(base_ + "/data", list.dump(), true);
}

void DataTransferEngine::write_line(Dump& dump, const std::string& line) {
  dump.out << line << '\n';
  if (!dump.out) {
    throw std::runtime_error("cannot write " + dump.path.string() + ": " + std::strerror(errno));
  }
}

int64_t DataTransferEngine::step(int64_t duration_ns) {
  time_ns_ += duration_ns;
  for (auto& d : dumps_) {
    if (d->out.is_open()) d->out.flush();
  }
  if (mqtt_ && mqtt_->connected()) {
    mqtt_->publish(base_ + "/time", datatransfer::seconds_text(time_ns_), false);
    if (std::string lost = mqtt_->take_lost_connection(); !lost.empty() && !lost_warned_) {
      lost_warned_ = true;
      warn("lost the connection to the MQTT broker " + quote(broker_text_) + ": " + lost +
           "; reconnecting, messages are queued meanwhile");
    }
  }
  return time_ns_;
}

void DataTransferEngine::set_datapack(const datapack::View& dp) {
  auto it = std::find_if(dumps_.begin(), dumps_.end(),
                         [&](const auto& d) { return d->name == dp.id().name(); });
  if (it == dumps_.end()) {
    std::string known;
    for (const auto& d : dumps_) known += (known.empty() ? "" : ", ") + d->name;
    throw std::invalid_argument("datapack " + quote(dp.id().name()) + " is not listed in the " +
                                "\"dumps\" of engine " + quote(name_) +
                                " (listed: " + (known.empty() ? "none" : known) + ")");
  }
  Dump& dump = **it;
  if (dp.empty()) return;
  const bool to_network = dump.network && mqtt_ && mqtt_->connected();
  if (!to_network && !dump.file) return;

  if (dp.is_json()) {
    const json value = plain_json(dp, datapack::read_json(dp));
    const std::string type(datapack::kJsonType);
    if (to_network) {
      const json& out =
          stream_message_ ? datatransfer::json_datapack_message(dump.name, name_, value) : value;
      publish(dump, type, out.dump(-1, ' ', false, json::error_handler_t::replace));
    }
    dump.type = type;
    if (dump.file) write_line(dump, datatransfer::json_line(value, time_ns_));
    return;
  }
  if (!dp.is_proto()) return;

  // The message, read by the datapack library (large bytes fields from their blobs, in shared
  // memory between local processes); Convoy's standard messages under NRP-Core's names.
  const engine::ProtoPayload& payload = dp.message().proto();
  std::string type = dp.proto_type();
  if (std::string nrp = nrp_name_of(type); !nrp.empty()) type = nrp;
  const datapack::TypeInfo* info = find_type(type);
  std::unique_ptr<google::protobuf::Message> message;
  std::string unknown_bytes;  // a type this program does not know: its bytes, blobs put back
  if (info) {
    check_package(dump, *info);
    message.reset(info->prototype->New());
    datapack::read_message(dp, message.get());
  } else {
    if (!dump.unknown_type_warned) {
      dump.unknown_type_warned = true;
      warn("datapack " + quote(dump.name) + ": protobuf type " + quote(type) +
           " is unknown to this engine; its file gets the serialized message (hex)");
    }
    unknown_bytes = datapack::proto_bytes(dp);
  }

  if (to_network) {
    std::string serialized;
    const std::string* bytes = &payload.data();  // already the message's bytes?
    if (!info) {
      bytes = &unknown_bytes;
    } else if (type != dp.proto_type() || payload.blob_fields_size() > 0) {
      serialized = message->SerializeAsString();
      bytes = &serialized;
    }
    publish(
        dump, type,
        stream_message_ ? datatransfer::datapack_message(dump.name, name_, type, *bytes) : *bytes);
  }
  dump.type = type;

  if (!dump.file) return;
  if (!info) {
    if (dump.header_type != type) {
      write_line(dump, "sim_time," + type + " (serialized, hex)");
      dump.header_type = type;
    }
    write_line(
        dump, datatransfer::seconds_text(time_ns_) + "," + datatransfer::bytes_text(unknown_bytes));
    return;
  }
  if (dump.header_type != type) {
    if (std::string header = datatransfer::proto_header(*message->GetDescriptor());
        !header.empty()) {
      write_line(dump, header);
    }
    dump.header_type = type;
  }
  write_line(dump, datatransfer::proto_line(*message, time_ns_));
}

void DataTransferEngine::publish(Dump& dump, const std::string& type, const std::string& payload) {
  if (type != dump.type) {
    dump.type = type;
    publish_topics();
  }
  if (std::string why = mqtt_->publish(dump.topic, payload, false);
      !why.empty() && !dump.publish_warned) {
    dump.publish_warned = true;
    warn("datapack " + quote(dump.name) + " cannot be published to " + quote(dump.topic) + ": " +
         why);
  }
}

void DataTransferEngine::check_package(const Dump& dump, const datapack::TypeInfo& type) {
  const std::string& package = type.descriptor->file()->package();
  if (datapack::nrp_package_file(package) && !packages_.count(package) &&
      warned_packages_.insert(package).second) {
    warn("datapack " + quote(dump.name) + " has type " + type.name +
         ", but ProtobufPackages does not list package " + quote(package) +
         " (NRP-Core would not carry it; Convoy does)");
  }
}

void DataTransferEngine::reset() {
  time_ns_ = 0;
  ++resets_;
  for (auto& d : dumps_) {
    if (d->file) open_file(*d);
    if (d->network && mqtt_ && mqtt_->connected()) mqtt_->publish(d->topic, "reset", false);
  }
}

void DataTransferEngine::shutdown() {
  for (auto& d : dumps_) {
    if (d->out.is_open()) d->out.close();
  }
  if (!mqtt_ || !mqtt_->connected()) return;
  mqtt_->publish(base_ + "/welcome", "Bye! NRP-core is disconnecting!", true);
  // Clears the retained messages, as NRP-Core does: a late subscriber sees no stale run.
  mqtt_->publish(base_ + "/welcome", "", true);
  mqtt_->publish(base_ + "/data", "", true);
  if (uint64_t left = mqtt_->close(kCloseTimeout); left > 0) {
    warn(std::to_string(left) + " MQTT messages were not acknowledged by the broker " +
         quote(broker_text_) + " within 5 s of shutdown");
  }
}

}  // namespace convoy::engines
