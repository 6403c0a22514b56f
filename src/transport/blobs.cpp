#include "transport/blobs.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace convoy::transport {

ShmArena::~ShmArena() {
  if (base_) munmap(base_, size_);
  if (fd_ >= 0) close(fd_);
}

void ShmArena::create(const std::string& name, size_t size) {
  fd_ = memfd_create(name.c_str(), MFD_CLOEXEC);
  if (fd_ < 0) throw std::runtime_error(std::string("memfd_create: ") + std::strerror(errno));
  if (ftruncate(fd_, static_cast<off_t>(size)) != 0)
    throw std::runtime_error(std::string("ftruncate: ") + std::strerror(errno));
  attach(fd_);
}

void ShmArena::attach(int fd) {
  fd_ = fd;
  struct stat st {};
  if (fstat(fd_, &st) != 0) throw std::runtime_error(std::string("fstat: ") + std::strerror(errno));
  size_ = static_cast<size_t>(st.st_size);
  void* p = mmap(nullptr, size_, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, 0);
  if (p == MAP_FAILED) throw std::runtime_error(std::string("mmap: ") + std::strerror(errno));
  base_ = static_cast<char*>(p);
}

std::span<uint8_t> ShmBlobWriter::reserve(engine::DataPack* dp, size_t size, uint32_t* index) {
  const size_t half_size = arena_.size() / 2;
  if (size < kShmBlobThreshold) {  // small: in the message
    auto* blob = dp->add_blobs();
    *index = static_cast<uint32_t>(dp->blobs_size() - 1);
    std::string* bytes = blob->mutable_inline_();
    bytes->resize(size);
    return {reinterpret_cast<uint8_t*>(bytes->data()), size};
  }
  // The message's first blob in shared memory goes to the other half.
  const size_t aligned = fresh_message_ ? 0 : (used_ + 63) & ~size_t{63};
  const size_t free_bytes = half_size - std::min(aligned, half_size);
  if (size > free_bytes) {
    // Inline, it would make a message as large as the blob: refused, with what to change.
    throw std::length_error("datapack '" + dp->id().name() + "' of engine '" +
                            dp->id().engine_name() + "': a blob of " + std::to_string(size) +
                            " bytes does not fit in the shared-memory arena (" +
                            std::to_string(free_bytes) + " of " + std::to_string(half_size) +
                            " bytes free for this message: half of the arena; CONVOY_SHM_MB "
                            "sets the arena size)");
  }
  if (fresh_message_) {
    fresh_message_ = false;
    half_ ^= 1;
  }
  auto* blob = dp->add_blobs();
  *index = static_cast<uint32_t>(dp->blobs_size() - 1);
  const size_t offset = static_cast<size_t>(half_) * half_size + aligned;
  used_ = aligned + size;
  blob->set_in_shm(true);
  blob->set_shm_offset(offset);
  blob->set_size(size);
  return {reinterpret_cast<uint8_t*>(arena_.data() + offset), size};
}

}  // namespace convoy::transport
