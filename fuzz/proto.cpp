// Fuzzes what arrives from an engine or the coordinator: engine::Request / Reply / DataPack
// parsed from the input, then every datapack in them read as the receiver would (JSON and its
// numpy arrays, camera, any registered protobuf type, large bytes fields in blobs, NRP-Core's
// Gazebo messages from the standard types), with the inline blob reader and with
// transport::ShmBlobReader on a small arena whose offsets and sizes come from the input.
#include "datapack/proto.h"

#include <google/protobuf/stubs/logging.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>

#include "datapack/nrp.h"
#include "datapack/registry.h"
#include "read_datapack.h"
#include "transport/blobs.h"

using namespace convoy;

namespace {

transport::ShmArena* arena = nullptr;

void read_with(const engine::DataPack& dp, const datapack::BlobReader& blobs) {
  const datapack::View view(dp, blobs);
  fuzz::read_datapack(view);
  if (!view.is_proto()) return;
  const datapack::TypeInfo* type = datapack::Registry::global().find(view.proto_type());
  if (!type || !type->prototype) return;
  std::unique_ptr<google::protobuf::Message> m(type->prototype->New());
  try {
    datapack::read_proto(view, m.get());
  } catch (const std::runtime_error&) {
  }
  // NRP-Core's Gazebo messages are also read from their standard types (a python_grpc
  // engine's Gazebo.Camera from a TF's convoy.data.Camera).
  for (const char* gazebo : {"Gazebo.Camera", "Gazebo.Joint", "Gazebo.Link"}) {
    if (datapack::standard_type_of(gazebo) != view.proto_type()) continue;
    std::unique_ptr<google::protobuf::Message> g(
        datapack::Registry::global().require(gazebo).prototype->New());
    try {
      datapack::read_message(view, g.get());
    } catch (const std::runtime_error&) {
    }
  }
}

void read(const engine::DataPack& dp) {
  read_with(dp, datapack::inline_blob_reader());
  read_with(dp, transport::ShmBlobReader(arena));
  read_with(dp, transport::ShmBlobReader(nullptr));
}

template <typename List>
void read_all(const List& datapacks) {
  for (const auto& dp : datapacks) read(dp);
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // Parsing logs every string field that is not UTF-8: millions of lines in a run.
  google::protobuf::SetLogHandler(
      [](google::protobuf::LogLevel, const char*, int, const std::string&) {});
  arena = new transport::ShmArena();
  arena->create("convoy-fuzz", 4096);
  std::memset(arena->data(), 0x5a, arena->size());
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int n = static_cast<int>(size);
  engine::Request request;
  if (request.ParseFromArray(data, n)) {
    read_all(request.step().inputs());
    read_all(request.set_datapacks().datapacks());
  }
  engine::Reply reply;
  if (reply.ParseFromArray(data, n)) {
    read_all(reply.step().outputs());
    read_all(reply.get_datapacks().datapacks());
  }
  engine::DataPack dp;
  if (dp.ParseFromArray(data, n)) read(dp);
  return 0;
}
