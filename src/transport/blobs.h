// Shared-memory blobs (datapack/blobs.h) between the coordinator and the engines it forks.
//
// Between the coordinator and an engine it forked, blobs go through two shared-memory
// arenas (memfd), one written by each side; the messages carry only offsets. Each arena is
// split in two halves used alternately by the messages that carry blobs, so that the data of
// the last such message stays valid while the next one is written (the coordinator's
// datapack pool keeps the latest datapacks of every engine; an engine leaves an unchanged
// datapack out of a reply only when the reply carries no blob). Remote engines carry blobs
// inline.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"

namespace convoy::transport {

constexpr size_t kShmBlobThreshold = datapack::kLargeBlobBytes;

// A shared-memory region mapped in this process.
class ShmArena {
 public:
  ShmArena() = default;
  ~ShmArena();
  ShmArena(const ShmArena&) = delete;
  ShmArena& operator=(const ShmArena&) = delete;

  // Creates a new anonymous arena of `size` bytes (pages are only used once written).
  void create(const std::string& name, size_t size);
  // Maps an arena received as a file descriptor (takes ownership of fd).
  void attach(int fd);
  int fd() const { return fd_; }
  char* data() const { return base_; }
  size_t size() const { return size_; }

 private:
  int fd_ = -1;
  char* base_ = nullptr;
  size_t size_ = 0;
};

// Writes blobs at or above kShmBlobThreshold into an arena, alternating halves. The large
// blobs of one message must fit together in half the arena: reserve() throws
// std::length_error, naming the datapack, for one that does not (it does not fall back to the
// message, which would then be as large as the blob).
class ShmBlobWriter final : public datapack::BlobWriter {
 public:
  explicit ShmBlobWriter(ShmArena& arena) : arena_(arena) {}
  // Starts the next message. Its first blob in shared memory switches halves and forgets the
  // previous allocations: the halves alternate between messages that carry blobs, so a
  // blob stays valid until two later messages have carried blobs.
  void next_message() { fresh_message_ = true; }
  // Whether the current message has put a blob in shared memory.
  bool wrote_blobs() const { return !fresh_message_; }
  std::span<uint8_t> reserve(engine::DataPack* dp, size_t size, uint32_t* index) override;

 private:
  ShmArena& arena_;
  int half_ = 1;
  size_t used_ = 0;
  bool fresh_message_ = true;
};

class ShmBlobReader final : public datapack::BlobReader {
 public:
  explicit ShmBlobReader(const ShmArena* arena) : arena_(arena) {}

 protected:
  const char* shm_base() const override { return arena_ ? arena_->data() : nullptr; }
  size_t shm_size() const override { return arena_ ? arena_->size() : 0; }

 private:
  const ShmArena* arena_;
};

}  // namespace convoy::transport
