// What the data-transfer engine writes: the lines of its file dumps and the payloads of its MQTT
// messages, from a datapack's JSON value or protobuf message. No I/O here (unit-tested in
// tests/datatransfer).
//
// File lines follow NRP-Core's DataTransfer engine, one line per datapack received, the first
// column the engine's simulated time in seconds:
//   Dump.String       <t>,<string_stream>
//   Dump.ArrayFloat   <t>,0,<v>,<v>...                 (dims not of size 2: one row)
//                     <t>,\n0,<v>...\n1,<v>...         (dims [rows, cols]: one line per row,
//                                                      missing values left out)
//   other messages    sim_time,<field>,<field>...      (a header, before the first row)
//                     <t>,<value>,<value>...           (one column per field, in field order)
//   JSON              <t>,<the value as compact JSON>
// Differences from NRP-Core, all in favour of exact, parseable files:
//   - times and floating-point values are printed exactly and shortest (0.01, not 0.010000);
//   - repeated fields are "[v v v]" (NRP-Core's engine stops at a repeated field: it cannot log
//     NrpGenericProto's arrays or Gazebo.Link), message fields protobuf's one-line text form
//     (NRP-Core: an error);
//   - bytes are hex up to kMaxBytesInFile bytes, "<N bytes>" beyond (NRP-Core writes the raw
//     bytes, line breaks included, into the file: a camera frame is ~1 MB of binary per
//     line); long strings inside message fields are cut at the same length;
//   - strings with ',', '"' or a line break are quoted as in CSV.
#pragma once

#include <google/protobuf/message.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace convoy::datatransfer {

// The longest bytes value written into a file (as hex); longer ones are "<N bytes>". The data
// are in the MQTT messages whatever their size.
inline constexpr size_t kMaxBytesInFile = 1024;

// Seconds, exactly and without trailing zeros: 10000000 -> "0.01", 2000000000 -> "2".
std::string seconds_text(int64_t ns);

// A float or double, shortest text that reads back to the same value.
std::string number_text(double value);
std::string number_text(float value);

// A CSV cell: `text`, quoted when it holds ',', '"', '\r' or '\n'.
std::string csv_cell(std::string_view text);

// A bytes value in a file: hex, or "<N bytes>" beyond kMaxBytesInFile.
std::string bytes_text(std::string_view bytes);

// The header line of a message type's dumps ("sim_time,position,velocity,effort"), or "" for
// the types with a format of their own (Dump.String, Dump.ArrayFloat).
std::string proto_header(const google::protobuf::Descriptor& type);
// The line(s) of one message received at `time_ns`.
std::string proto_line(const google::protobuf::Message& message, int64_t time_ns);
// The line of a JSON value received at `time_ns`.
std::string json_line(const nlohmann::json& value, int64_t time_ns);

// The bytes of an NRP-Core EngineGrpc.DataPackMessage (proto/nrp_protobuf/engine_grpc.proto)
// holding a message of type `type_name` serialized as `data`: dataPackId {dataPackName,
// dataPackType = type_name, engineName}, data: Any {"type.googleapis.com/<type_name>", data}.
std::string datapack_message(std::string_view name, std::string_view engine_name,
                             std::string_view type_name, std::string_view data);

// The MQTT form of a JSON datapack with streamDataPackMessage:
// {"datapackId": {"dataPackName", "engineName", "dataPackType": "json"}, "data": value}.
nlohmann::json json_datapack_message(std::string_view name, std::string_view engine_name,
                                     const nlohmann::json& value);

}  // namespace convoy::datatransfer
