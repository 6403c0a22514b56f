#include "live/protocol.h"

#include <nlohmann/json.hpp>

namespace convoy::live {

namespace {

using json = nlohmann::json;

void put_le(std::string* out, uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

// A field of `obj` that must be an integer in [0, 2^32). False with `*error` set otherwise.
bool read_id(const json& obj, const char* key, uint32_t* out, std::string* error) {
  auto it = obj.find(key);
  if (it == obj.end()) {
    *error = std::string("missing \"") + key + "\"";
    return false;
  }
  if (!it->is_number_integer() || it->get<int64_t>() < 0 || it->get<int64_t>() > 0xffffffffLL) {
    *error =
        std::string("\"") + key + "\" must be an integer from 0 to 4294967295, got " + it->dump();
    return false;
  }
  *out = static_cast<uint32_t>(it->get<int64_t>());
  return true;
}

ClientRequest invalid(std::string why) {
  ClientRequest r;
  r.op = ClientRequest::Op::kInvalid;
  r.error = std::move(why);
  return r;
}

ClientRequest parse_subscribe(const json& msg) {
  auto it = msg.find("subscriptions");
  if (it == msg.end() || !it->is_array())
    return invalid("subscribe: \"subscriptions\" must be an array");
  ClientRequest r;
  r.op = ClientRequest::Op::kSubscribe;
  for (const auto& s : *it) {
    if (!s.is_object()) return invalid("subscribe: each subscription must be an object");
    Subscription sub;
    std::string error;
    if (!read_id(s, "id", &sub.id, &error) || !read_id(s, "channelId", &sub.channel_id, &error))
      return invalid("subscribe: " + error);
    r.subscribe.push_back(sub);
  }
  return r;
}

ClientRequest parse_unsubscribe(const json& msg) {
  auto it = msg.find("subscriptionIds");
  if (it == msg.end() || !it->is_array())
    return invalid("unsubscribe: \"subscriptionIds\" must be an array");
  ClientRequest r;
  r.op = ClientRequest::Op::kUnsubscribe;
  for (const auto& id : *it) {
    if (!id.is_number_integer() || id.get<int64_t>() < 0 || id.get<int64_t>() > 0xffffffffLL)
      return invalid("unsubscribe: subscription ids must be integers from 0 to 4294967295, got " +
                     id.dump());
    r.unsubscribe.push_back(static_cast<uint32_t>(id.get<int64_t>()));
  }
  return r;
}

// An array of integer ids in [0, 2^32) under `key`.
bool read_ids(const json& msg, const char* key, std::vector<uint32_t>* out, std::string* error) {
  auto it = msg.find(key);
  if (it == msg.end() || !it->is_array()) {
    *error = std::string("\"") + key + "\" must be an array";
    return false;
  }
  for (const auto& id : *it) {
    if (!id.is_number_integer() || id.get<int64_t>() < 0 || id.get<int64_t>() > 0xffffffffLL) {
      *error = std::string("\"") + key + "\" must hold integers from 0 to 4294967295, got " +
               id.dump(-1, ' ', false, json::error_handler_t::replace);
      return false;
    }
    out->push_back(static_cast<uint32_t>(id.get<int64_t>()));
  }
  return true;
}

// A string field of `obj` (optional: "" when absent).
bool read_string(const json& obj, const char* key, bool required, std::string* out,
                 std::string* error) {
  auto it = obj.find(key);
  if (it == obj.end()) {
    if (!required) return true;
    *error = std::string("missing \"") + key + "\"";
    return false;
  }
  if (!it->is_string()) {
    *error = std::string("\"") + key + "\" must be a string";
    return false;
  }
  *out = it->get<std::string>();
  return true;
}

ClientRequest parse_advertise(const json& msg) {
  auto it = msg.find("channels");
  if (it == msg.end() || !it->is_array())
    return invalid("advertise: \"channels\" must be an array");
  ClientRequest r;
  r.op = ClientRequest::Op::kAdvertise;
  for (const auto& c : *it) {
    if (!c.is_object()) return invalid("advertise: each channel must be an object");
    ClientChannel ch;
    std::string error;
    if (!read_id(c, "id", &ch.id, &error) || !read_string(c, "topic", true, &ch.topic, &error) ||
        !read_string(c, "encoding", true, &ch.encoding, &error) ||
        !read_string(c, "schemaName", false, &ch.schema_name, &error))
      return invalid("advertise: " + error);
    r.advertise.push_back(std::move(ch));
  }
  return r;
}

}  // namespace

std::string server_info_json(const ServerInfo& info) {
  json j = {{"op", "serverInfo"},
            {"name", info.name},
            {"capabilities", info.capabilities},
            {"supportedEncodings", info.supported_encodings},
            {"metadata", info.metadata},
            {"sessionId", info.session_id}};
  return j.dump();
}

std::string advertise_json(const std::vector<ChannelInfo>& channels) {
  json list = json::array();
  for (const auto& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", list}}.dump();
}

std::string unadvertise_json(const std::vector<uint32_t>& channel_ids) {
  return json{{"op", "unadvertise"}, {"channelIds", channel_ids}}.dump();
}

std::string status_json(StatusLevel level, std::string_view message) {
  // Replace invalid UTF-8 (a message may quote a client's bytes) rather than throw.
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}}.dump(
      -1, ' ', false, json::error_handler_t::replace);
}

std::string message_data_header(uint32_t subscription_id, uint64_t receive_time_ns) {
  std::string out;
  out.reserve(kMessageDataHeaderBytes);
  out.push_back(static_cast<char>(kOpMessageData));
  put_le(&out, subscription_id, 4);
  put_le(&out, receive_time_ns, 8);
  return out;
}

std::string time_message(uint64_t time_ns) {
  std::string out;
  out.push_back(static_cast<char>(kOpTime));
  put_le(&out, time_ns, 8);
  return out;
}

ClientRequest parse_client_message(std::string_view text) {
  json msg = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (msg.is_discarded()) return invalid("not a JSON message");
  if (!msg.is_object())
    return invalid("a message must be a JSON object, got " + std::string(msg.type_name()));
  auto op = msg.find("op");
  if (op == msg.end() || !op->is_string()) return invalid("a message needs a string \"op\"");
  const auto name = op->get<std::string>();
  if (name == "subscribe") return parse_subscribe(msg);
  if (name == "unsubscribe") return parse_unsubscribe(msg);
  if (name == "advertise") return parse_advertise(msg);
  if (name == "unadvertise") {
    ClientRequest r;
    r.op = ClientRequest::Op::kUnadvertise;
    if (!read_ids(msg, "channelIds", &r.unadvertise, &r.error))
      return invalid("unadvertise: " + r.error);
    return r;
  }
  ClientRequest r;
  r.op = ClientRequest::Op::kUnsupported;
  r.error = name;
  return r;
}

ClientData parse_client_binary(std::string_view bytes) {
  ClientData d;
  if (bytes.empty()) {
    d.error = "empty binary message";
  } else if (static_cast<uint8_t>(bytes[0]) != kOpMessageData) {
    d.error = "binary message with unknown opcode " +
              std::to_string(static_cast<uint8_t>(bytes[0])) +
              " (clients may send 1: message data)";
  } else if (bytes.size() < 5) {
    d.error = "client message data of " + std::to_string(bytes.size()) +
              " bytes: needs an opcode and a 4-byte channel id";
  } else {
    d.channel_id = read_u32_le(bytes, 1);
    d.payload = bytes.substr(5);
  }
  return d;
}

uint32_t read_u32_le(std::string_view b, size_t at) {
  uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(b.at(at + i));
  return v;
}

uint64_t read_u64_le(std::string_view b, size_t at) {
  uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<uint8_t>(b.at(at + i));
  return v;
}

}  // namespace convoy::live
