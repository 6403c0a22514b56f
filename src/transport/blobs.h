// Large byte payloads of datapacks (engine::Blob): where they are written and read.
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

namespace convoy::transport {

// Blobs at least this large go to shared memory; smaller ones stay inline.
constexpr size_t kShmBlobThreshold = 32 * 1024;

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

// Writes blobs into a datapack.
class BlobWriter {
 public:
  virtual ~BlobWriter() = default;
  // Appends a blob holding `bytes` to `dp`; returns its index.
  virtual uint32_t add(engine::DataPack* dp, std::string_view bytes) = 0;
};

// Reads a datapack's blobs.
class BlobReader {
 public:
  virtual ~BlobReader() = default;
  // The bytes of blob `index` of `dp`; empty view if there is no such blob. `in_shm` tells
  // whether they live in shared memory (valid until the sender's next-but-one message).
  virtual std::string_view get(const engine::DataPack& dp, uint32_t index,
                               bool* in_shm = nullptr) const;

 protected:
  virtual const char* shm_base() const { return nullptr; }
  virtual size_t shm_size() const { return 0; }
};

class InlineBlobWriter final : public BlobWriter {
 public:
  uint32_t add(engine::DataPack* dp, std::string_view bytes) override;
};

// Writes blobs at or above kShmBlobThreshold into an arena, alternating halves.
class ShmBlobWriter final : public BlobWriter {
 public:
  explicit ShmBlobWriter(ShmArena& arena) : arena_(arena) {}
  // Starts the next message. Its first blob in shared memory switches halves and forgets the
  // previous allocations: the halves alternate between messages that carry blobs, so a
  // blob stays valid until two later messages have carried blobs.
  void next_message() { fresh_message_ = true; }
  // Whether the current message has put a blob in shared memory.
  bool wrote_blobs() const { return !fresh_message_; }
  uint32_t add(engine::DataPack* dp, std::string_view bytes) override;

 private:
  ShmArena& arena_;
  int half_ = 1;
  size_t used_ = 0;
  bool fresh_message_ = true;
};

class ShmBlobReader final : public BlobReader {
 public:
  explicit ShmBlobReader(const ShmArena* arena) : arena_(arena) {}

 protected:
  const char* shm_base() const override { return arena_ ? arena_->data() : nullptr; }
  size_t shm_size() const override { return arena_ ? arena_->size() : 0; }

 private:
  const ShmArena* arena_;
};

// The reader and writer in force on this thread: set by whoever handles a message, used by
// the datapack codecs (msgpack ext type 2, the camera's image_blob).
BlobWriter& current_blob_writer();
const BlobReader& current_blob_reader();

class ScopedBlobContext {
 public:
  ScopedBlobContext(BlobWriter* writer, const BlobReader* reader);
  ~ScopedBlobContext();

 private:
  BlobWriter* prev_writer_;
  const BlobReader* prev_reader_;
};

}  // namespace convoy::transport
