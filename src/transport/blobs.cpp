#include "transport/blobs.h"

#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

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
  auto* blob = dp->add_blobs();
  *index = static_cast<uint32_t>(dp->blobs_size() - 1);
  const size_t half_size = arena_.size() / 2;
  const bool big = size >= kShmBlobThreshold;
  if (big && fresh_message_ && size <= half_size) {
    fresh_message_ = false;  // the message's first blob in shared memory: the other half
    half_ ^= 1;
    used_ = 0;
  }
  const size_t aligned = (used_ + 63) & ~size_t{63};
  if (!big || fresh_message_ || aligned + size > half_size) {
    std::string* bytes = blob->mutable_inline_();  // small, or the arena is full
    bytes->resize(size);
    return {reinterpret_cast<uint8_t*>(bytes->data()), size};
  }
  const size_t offset = static_cast<size_t>(half_) * half_size + aligned;
  used_ = aligned + size;
  blob->set_in_shm(true);
  blob->set_shm_offset(offset);
  blob->set_size(size);
  return {reinterpret_cast<uint8_t*>(arena_.data() + offset), size};
}

}  // namespace convoy::transport
