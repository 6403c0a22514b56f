// Protobuf datapacks: any registered message (registry.h) in DataPack.proto.
#pragma once

#include <google/protobuf/message.h>

#include <stdexcept>
#include <string>

#include "datapack/datapack.h"

namespace convoy::datapack {

// Sets the payload (and DataPackId.type) to `message`.
void write_proto(Builder& out, const google::protobuf::Message& message);

// Parses the payload into `message`. Throws std::runtime_error naming the datapack when it
// holds another type, or bytes that do not parse.
void read_proto(const View& in, google::protobuf::Message* message);

template <typename M>
M read_proto(const View& in) {
  M m;
  read_proto(in, &m);
  return m;
}

}  // namespace convoy::datapack
