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

std::string_view BlobReader::get(const engine::DataPack& dp, uint32_t index, bool* in_shm) const {
  if (in_shm) *in_shm = false;
  if (index >= static_cast<uint32_t>(dp.blobs_size())) return {};
  const auto& b = dp.blobs(static_cast<int>(index));
  if (!b.in_shm()) return b.inline_();
  const char* base = shm_base();
  if (!base || b.shm_offset() + b.size() > shm_size()) {
    throw std::runtime_error("datapack '" + dp.id().name() +
                             "' refers to shared memory this process cannot read");
  }
  if (in_shm) *in_shm = true;
  return {base + b.shm_offset(), b.size()};
}

uint32_t InlineBlobWriter::add(engine::DataPack* dp, std::string_view bytes) {
  dp->add_blobs()->set_inline_(bytes.data(), bytes.size());
  return static_cast<uint32_t>(dp->blobs_size() - 1);
}

uint32_t ShmBlobWriter::add(engine::DataPack* dp, std::string_view bytes) {
  auto* blob = dp->add_blobs();
  const size_t half_size = arena_.size() / 2;
  const bool big = bytes.size() >= kShmBlobThreshold;
  if (big && fresh_message_ && bytes.size() <= half_size) {
    fresh_message_ = false;  // the message's first blob in shared memory: the other half
    half_ ^= 1;
    used_ = 0;
  }
  const size_t aligned = (used_ + 63) & ~size_t{63};
  if (!big || fresh_message_ || aligned + bytes.size() > half_size) {
    blob->set_inline_(bytes.data(), bytes.size());  // small, or the arena is full
  } else {
    size_t offset = static_cast<size_t>(half_) * half_size + aligned;
    std::memcpy(arena_.data() + offset, bytes.data(), bytes.size());
    used_ = aligned + bytes.size();
    blob->set_in_shm(true);
    blob->set_shm_offset(offset);
    blob->set_size(bytes.size());
  }
  return static_cast<uint32_t>(dp->blobs_size() - 1);
}

namespace {
InlineBlobWriter default_writer;
BlobReader default_reader;
thread_local BlobWriter* tls_writer = &default_writer;
thread_local const BlobReader* tls_reader = &default_reader;
}  // namespace

BlobWriter& current_blob_writer() { return *tls_writer; }
const BlobReader& current_blob_reader() { return *tls_reader; }

ScopedBlobContext::ScopedBlobContext(BlobWriter* writer, const BlobReader* reader)
    : prev_writer_(tls_writer), prev_reader_(tls_reader) {
  if (writer) tls_writer = writer;
  if (reader) tls_reader = reader;
}

ScopedBlobContext::~ScopedBlobContext() {
  tls_writer = prev_writer_;
  tls_reader = prev_reader_;
}

}  // namespace convoy::transport
