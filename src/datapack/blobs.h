// Large byte payloads of datapacks (engine::Blob): the interfaces that write and read them.
//
// A datapack's payload refers to its blobs by index. Who writes a blob decides where its
// bytes go: inline in the message (remote engines), or into a shared-memory arena between
// the coordinator and an engine it forked (transport/blobs.h). Readers and writers are
// passed explicitly, with the datapack (datapack.h: View, Builder): there is no ambient
// (thread-local) one, so a codec cannot quietly fall back to a slow path.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "convoy/engine.pb.h"

namespace convoy::datapack {

// Blobs at least this large go to shared memory when there is some; smaller ones stay inline.
// Payloads this large are "frame-sized": the copy counter counts their copies.
constexpr size_t kLargeBlobBytes = 32 * 1024;

class BlobWriter {
 public:
  virtual ~BlobWriter() = default;
  // Appends a blob of `size` bytes to `dp` and returns where to write them; its index goes to
  // `index`. The span stays writable until the message is sent. This is how an engine writes
  // a frame straight into its outgoing arena, without a copy.
  virtual std::span<uint8_t> reserve(engine::DataPack* dp, size_t size, uint32_t* index) = 0;
  // Appends a blob holding a copy of `bytes` to `dp`; returns its index.
  uint32_t add(engine::DataPack* dp, std::string_view bytes);
};

class BlobReader {
 public:
  virtual ~BlobReader() = default;
  // The bytes of blob `index` of `dp`; an empty view if there is no such blob. `in_shm` tells
  // whether they live in shared memory: then they stay valid until the sender's next-but-one
  // message that carries blobs (for an engine: at least until its next step has run).
  // Throws if the blob is in shared memory this reader cannot see.
  std::string_view get(const engine::DataPack& dp, uint32_t index, bool* in_shm = nullptr) const;

 protected:
  virtual const char* shm_base() const { return nullptr; }
  virtual size_t shm_size() const { return 0; }
};

// Keeps every blob inline in the message (remote engines, tests).
class InlineBlobWriter final : public BlobWriter {
 public:
  std::span<uint8_t> reserve(engine::DataPack* dp, size_t size, uint32_t* index) override;
};

// Reads inline blobs only.
const BlobReader& inline_blob_reader();

// Copies of frame-sized payloads (>= kLargeBlobBytes) made in this process: by
// BlobWriter::add, by a frame's conversion into a reserved blob, and by a decoder that must
// keep a private copy. It is what the "copies of a frame" figure counts.
struct CopyCounter {
  std::atomic<uint64_t> copies{0};
  std::atomic<uint64_t> bytes{0};
};
CopyCounter& large_copies();
// Counts one copy of `bytes` bytes if they are frame-sized.
inline void count_copy(size_t bytes) {
  if (bytes < kLargeBlobBytes) return;
  auto& c = large_copies();
  c.copies.fetch_add(1, std::memory_order_relaxed);
  c.bytes.fetch_add(bytes, std::memory_order_relaxed);
}

}  // namespace convoy::datapack
