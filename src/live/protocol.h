// The Foxglove WebSocket protocol (subprotocol `foxglove.websocket.v1`), as bytes: the
// messages the live server sends and the client requests it reads. No transport here
// (live/server.h carries them), so that the tests can check them byte by byte.
//
// Server -> client: serverInfo, advertise, unadvertise and status as JSON text; messageData
// (opcode 0x01: subscription id, receive time in ns, payload) and time (opcode 0x02) as
// binary, integers little-endian. Client -> server: subscribe and unsubscribe (JSON); with the
// capability clientPublish, advertise and unadvertise of client channels (JSON) and their
// messages (binary, opcode 0x01: client channel id, payload). Anything else a client sends is
// answered with a status error by the server, to that client only.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace convoy::live {

inline constexpr const char* kSubprotocol = "foxglove.websocket.v1";
inline constexpr uint8_t kOpMessageData = 0x01;
inline constexpr uint8_t kOpTime = 0x02;
// Bytes before the payload of a messageData message.
inline constexpr size_t kMessageDataHeaderBytes = 1 + 4 + 8;

// A channel as advertised.
struct ChannelInfo {
  uint32_t id = 0;
  std::string topic;
  std::string encoding;         // "json", "protobuf"
  std::string schema_name;      // "foxglove.Log", "convoy.data.Camera", ...
  std::string schema;           // JSON Schema text, or base64 of a FileDescriptorSet
  std::string schema_encoding;  // "jsonschema", "protobuf"
};

struct ServerInfo {
  std::string name;
  std::string session_id;
  std::map<std::string, std::string> metadata;
  std::vector<std::string> capabilities = {"time"};  // + "clientPublish"
  std::vector<std::string> supported_encodings;      // of client channels: "json"
};

enum class StatusLevel { kInfo = 0, kWarning = 1, kError = 2 };

std::string server_info_json(const ServerInfo& info);
std::string advertise_json(const std::vector<ChannelInfo>& channels);
std::string unadvertise_json(const std::vector<uint32_t>& channel_ids);
std::string status_json(StatusLevel level, std::string_view message);
// The 13 bytes before a messageData payload.
std::string message_data_header(uint32_t subscription_id, uint64_t receive_time_ns);
std::string time_message(uint64_t time_ns);

// A client's request, decoded from a text message.
struct Subscription {
  uint32_t id = 0;
  uint32_t channel_id = 0;
};
// A channel a client publishes on (Client Advertise).
struct ClientChannel {
  uint32_t id = 0;
  std::string topic;
  std::string encoding;
  std::string schema_name;
};
struct ClientRequest {
  enum class Op {
    kSubscribe,
    kUnsubscribe,
    kAdvertise,
    kUnadvertise,
    kUnsupported,
    kInvalid
  } op = Op::kInvalid;
  std::vector<Subscription> subscribe;   // kSubscribe
  std::vector<uint32_t> unsubscribe;     // kUnsubscribe: subscription ids
  std::vector<ClientChannel> advertise;  // kAdvertise
  std::vector<uint32_t> unadvertise;     // kUnadvertise: client channel ids
  std::string error;                     // kInvalid: why; kUnsupported: the op
};
// Never throws: garbage gives kInvalid with a message saying what is wrong.
ClientRequest parse_client_message(std::string_view text);

// A binary message from a client: Client Message Data (opcode 0x01, u32 client channel id,
// payload). `error` says what is wrong otherwise (another opcode, too short).
struct ClientData {
  uint32_t channel_id = 0;
  std::string_view payload;
  std::string error;
};
ClientData parse_client_binary(std::string_view bytes);

// Little-endian readers for the tests and for clients in C++.
uint32_t read_u32_le(std::string_view bytes, size_t at);
uint64_t read_u64_le(std::string_view bytes, size_t at);

}  // namespace convoy::live
