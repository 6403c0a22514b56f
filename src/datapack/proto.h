// Protobuf datapacks: any registered message (registry.h) in DataPack.proto.
//
// A large value (>= kLargeBlobBytes) of a top-level `bytes` field (Image.data, BytesValue.value)
// travels as a blob, like a camera frame: into the writer's arena between local processes
// (one copy), inline for remote engines. ProtoPayload.blob_fields says where it goes back.
#pragma once

#include <google/protobuf/message.h>

#include <stdexcept>
#include <string>
#include <string_view>

#include "datapack/datapack.h"

namespace convoy::datapack {

// Sets the payload (and DataPackId.type) to `message`; large bytes values into blobs.
void write_proto(Builder& out, const google::protobuf::Message& message);

// Sets the payload (and DataPackId.type) to `bytes`, a message of type `type` serialized
// already (not checked here: the reader's read_proto names the datapack if they do not parse).
void write_proto_bytes(Builder& out, const std::string& type, std::string_view bytes);

// Parses the payload into `message` (large bytes values copied from their blobs). Throws
// std::runtime_error naming the datapack when it holds another type, bytes that do not
// parse, or blob references that do not fit the message.
void read_proto(const View& in, google::protobuf::Message* message);

// The serialized message of a protobuf datapack with the values that travelled as blobs put
// back, without knowing its type (a program that has not compiled the message in): a
// singular field's value is appended, a repeated field's element replaces the empty value
// left in its place. Parses as read_proto's message would. Throws std::runtime_error naming
// the datapack when the bytes do not parse or a blob is missing.
std::string proto_bytes(const View& in);

template <typename M>
M read_proto(const View& in) {
  M m;
  read_proto(in, &m);
  return m;
}

}  // namespace convoy::datapack
