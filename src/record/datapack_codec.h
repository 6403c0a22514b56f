// How a datapack is written into a recording (record/recorder.h), and read back for a replay.
//
// Four kinds of message, each on channels of its own (the channel's metadata "kind"):
//  - json: a JSON datapack as JSON text (message_encoding "json"), keys in their order.
//    Doubles are written so that they read back to the same bits (nlohmann's shortest
//    round-trip form). What JSON cannot hold is tagged:
//      {"__ndarray__": {"dtype": "<f4", "shape": [2, 3], "data": BASE64}}   a numpy array
//      {"__ndarray__": {..., "blob": true, "data": BASE64}}    one that travelled as a blob
//      {"__ndarray__": {..., "blob": true, "size": N}}         the same, not recorded
//      {"__bytes__": BASE64}, {"__ext__": [TYPE, BASE64]}      other MessagePack binaries
//      {"__float__": "nan" | "inf" | "-inf"}                   non-finite numbers
//      {"__value__": V}                                        a top-level non-object
//  - protobuf: the serialized message, blobs put back (a camera's pixels in image_data),
//    message_encoding "protobuf" with the FileDescriptorSet of its type as schema.
//  - stub: a datapack whose blobs are not recorded (no --record-blobs), or a protobuf type this
//    program does not know: JSON {"__stub__": {"type", "proto": BASE64 of the message without
//    its blobs, "blob_fields": [[field, index, blob]...], "blob_sizes": [...], "size": total,
//    "message": the rest as JSON when the type is known}}.
//  - empty: the empty datapack, JSON {}.
// A replay reads each back into a datapack with its blobs inline; blobs that were not recorded
// come back as zeros of their size ("placeholders").
#pragma once

#include <string>
#include <string_view>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"

namespace convoy::record {

enum class Kind { kJson, kProtobuf, kStub, kEmpty };
const char* kind_name(Kind kind);
// Throws std::invalid_argument for an unknown name.
Kind kind_from_name(std::string_view name);

struct Encoded {
  Kind kind = Kind::kEmpty;
  std::string type;  // DataPackId.type (json, a protobuf full name, "")
  std::string data;  // the message's bytes
  bool has_blobs = false;
};

// The kind encode() gives `dp`, without encoding it.
Kind kind_of(const engine::DataPack& dp, bool with_blobs);

// Encodes a datapack whose blobs `blobs` reads; `with_blobs`: put the blobs' bytes in.
// Throws std::runtime_error naming the datapack when its payload is malformed.
Encoded encode(const engine::DataPack& dp, const datapack::BlobReader& blobs, bool with_blobs);

// A recorded message back into a datapack named `name` of engine `engine` (blobs inline).
// Adds the number of blobs filled with zeros to `*placeholders`. Throws std::runtime_error.
engine::DataPack decode(Kind kind, const std::string& type, std::string_view data,
                        const std::string& name, const std::string& engine, int* placeholders);

std::string base64_encode(std::string_view bytes);
// Throws std::runtime_error on a character outside the alphabet.
std::string base64_decode(std::string_view text);

}  // namespace convoy::record
