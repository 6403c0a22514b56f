#include "datapack/blobs.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace convoy::datapack {

uint32_t BlobWriter::add(engine::DataPack* dp, std::string_view bytes) {
  uint32_t index = 0;
  std::span<uint8_t> dst = reserve(dp, bytes.size(), &index);
  if (!bytes.empty()) std::memcpy(dst.data(), bytes.data(), bytes.size());
  count_copy(bytes.size());
  return index;
}

std::string_view BlobReader::get(const engine::DataPack& dp, uint32_t index, bool* in_shm) const {
  if (in_shm) *in_shm = false;
  if (index >= static_cast<uint32_t>(dp.blobs_size())) return {};
  const auto& b = dp.blobs(static_cast<int>(index));
  if (!b.in_shm()) return b.inline_();
  const char* base = shm_base();
  if (!base || b.shm_offset() + b.size() > shm_size() || b.shm_offset() + b.size() < b.size()) {
    throw std::runtime_error("datapack '" + dp.id().name() +
                             "' refers to shared memory this process cannot read");
  }
  if (in_shm) *in_shm = true;
  return {base + b.shm_offset(), b.size()};
}

std::span<uint8_t> InlineBlobWriter::reserve(engine::DataPack* dp, size_t size, uint32_t* index) {
  std::string* bytes = dp->add_blobs()->mutable_inline_();
  bytes->resize(size);
  *index = static_cast<uint32_t>(dp->blobs_size() - 1);
  return {reinterpret_cast<uint8_t*>(bytes->data()), size};
}

const BlobReader& inline_blob_reader() {
  static const BlobReader reader;
  return reader;
}

CopyCounter& large_copies() {
  static CopyCounter counter;
  return counter;
}

}  // namespace convoy::datapack
