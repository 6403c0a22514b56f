// Fuzzes the datapack library's decoders (src/datapack): a JSON datapack's MessagePack with
// its numpy arrays (inline and in blobs), the numpy-array header alone, and a camera message.
// Input: blobs and payload as in fuzz_input.h.
#include <cstddef>
#include <cstdint>

#include "convoy/datapacks.pb.h"
#include "datapack/ndarray.h"
#include "datapack/registry.h"
#include "read_datapack.h"

using namespace convoy;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string_view in(reinterpret_cast<const char*>(data), size);
  const fuzz::BlobbedInput parts = fuzz::split_blobs(in);

  engine::DataPack dp;
  dp.mutable_id()->set_name("fuzz");
  for (auto b : parts.blobs) dp.add_blobs()->set_inline_(std::string(b));
  const datapack::View view(dp, datapack::inline_blob_reader());

  dp.set_json_msgpack(std::string(parts.payload));
  fuzz::read_datapack(view);

  // The payload as a camera message (convoy.data.Camera).
  auto* proto = dp.mutable_proto();
  proto->set_type_name(datapack::type_name<data::Camera>());
  proto->set_data(std::string(parts.payload));
  fuzz::read_datapack(view);

  // The numpy-array header alone: what follows it must lie inside the body.
  datapack::NdarrayHeader header;
  try {
    std::string_view rest = datapack::parse_ndarray_header(parts.payload, &header);
    if (rest.data() < parts.payload.data() ||
        rest.data() + rest.size() != parts.payload.data() + parts.payload.size())
      fuzz::fail("parse_ndarray_header: rest outside the body");
    (void)datapack::dtype_size(header.dtype);
    try {
      (void)datapack::parse_blob_index(rest);
    } catch (const std::runtime_error&) {
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
