// One datapack on its way in or out of a process, with the blob reader or writer of the
// message that carries it. Engines, the coordinator and the Python bridge all see datapacks
// through these two classes and the typed codecs next to them:
//   json.h     JSON values (MessagePack), numpy arrays inside them (ndarray.h)
//   proto.h    any registered protobuf message (registry.h)
//   camera.h   camera frames, written into and read from blobs without copies
#pragma once

#include <span>
#include <string>
#include <string_view>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"

namespace convoy::datapack {

// The type name of JSON datapacks (DataPackId.type); protobuf datapacks carry their
// message's full name (registry.h).
inline constexpr std::string_view kJsonType = "json";

// A received datapack. Blobs in shared memory are read in place: they stay valid until the
// sender's next-but-one message that carries blobs (for an engine, at least until the end of
// the step that follows the request that brought them).
class View {
 public:
  View(const engine::DataPack& dp, const BlobReader& blobs) : dp_(dp), blobs_(blobs) {}
  const engine::DataPack& message() const { return dp_; }
  const engine::DataPackId& id() const { return dp_.id(); }
  bool empty() const { return dp_.payload_case() == engine::DataPack::PAYLOAD_NOT_SET; }
  bool is_json() const { return dp_.payload_case() == engine::DataPack::kJsonMsgpack; }
  bool is_proto() const { return dp_.payload_case() == engine::DataPack::kProto; }
  // The protobuf type name, or "" for other payloads.
  const std::string& proto_type() const { return dp_.proto().type_name(); }
  std::string_view blob(uint32_t index, bool* in_shm = nullptr) const {
    return blobs_.get(dp_, index, in_shm);
  }
  const BlobReader& blobs() const { return blobs_; }
  // "datapack 'name' of engine 'engine'", for messages.
  std::string describe() const;

 private:
  const engine::DataPack& dp_;
  const BlobReader& blobs_;
};

// A datapack being filled for sending. Its id is set by whoever asked for it.
class Builder {
 public:
  Builder(engine::DataPack* dp, BlobWriter& blobs) : dp_(dp), blobs_(blobs) {}
  engine::DataPack* message() { return dp_; }
  const engine::DataPackId& id() const { return dp_->id(); }
  // No payload: the empty datapack.
  void clear() { dp_->clear_payload(); }
  uint32_t add_blob(std::string_view bytes) { return blobs_.add(dp_, bytes); }
  std::span<uint8_t> reserve_blob(size_t size, uint32_t* index) {
    return blobs_.reserve(dp_, size, index);
  }
  BlobWriter& blobs() { return blobs_; }
  std::string describe() const;

 private:
  engine::DataPack* dp_;
  BlobWriter& blobs_;
};

std::string describe(const engine::DataPackId& id);

}  // namespace convoy::datapack
