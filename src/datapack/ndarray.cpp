#include "datapack/ndarray.h"

#include <charconv>
#include <cstdint>
#include <stdexcept>

namespace convoy::datapack {

namespace {
template <typename Out>
void put_header(Out* out, std::string_view dtype, std::span<const uint64_t> shape) {
  if (dtype.size() > 255 || shape.size() > 255)
    throw std::runtime_error("numpy array header: dtype or rank too long");
  out->push_back(static_cast<uint8_t>(dtype.size()));
  out->insert(out->end(), dtype.begin(), dtype.end());
  out->push_back(static_cast<uint8_t>(shape.size()));
  for (uint64_t d : shape)
    for (int b = 0; b < 8; ++b) out->push_back(static_cast<uint8_t>(d >> (8 * b)));
}
template <typename Out>
void put_index(Out* out, uint32_t index) {
  for (int b = 3; b >= 0; --b) out->push_back(static_cast<uint8_t>(index >> (8 * b)));
}
}  // namespace

uint64_t NdarrayHeader::count() const {
  uint64_t n = 1;
  for (uint64_t d : shape) {
    if (d != 0 && n > UINT64_MAX / d) return UINT64_MAX;  // a forged shape: matches no data
    n *= d;
  }
  return n;
}

void append_ndarray_header(std::string* out, std::string_view dtype,
                           std::span<const uint64_t> shape) {
  put_header(out, dtype, shape);
}
void append_ndarray_header(std::vector<uint8_t>* out, std::string_view dtype,
                           std::span<const uint64_t> shape) {
  put_header(out, dtype, shape);
}
void append_blob_index(std::string* out, uint32_t index) { put_index(out, index); }
void append_blob_index(std::vector<uint8_t>* out, uint32_t index) { put_index(out, index); }

std::string_view parse_ndarray_header(std::string_view body, NdarrayHeader* header) {
  auto bad = [] { return std::runtime_error("bad numpy array header"); };
  const auto* b = reinterpret_cast<const uint8_t*>(body.data());
  const auto* e = b + body.size();
  if (e - b < 2) throw bad();
  const size_t dlen = *b++;
  if (static_cast<size_t>(e - b) < dlen + 1) throw bad();
  header->dtype.assign(reinterpret_cast<const char*>(b), dlen);
  b += dlen;
  const size_t ndim = *b++;
  if (static_cast<size_t>(e - b) < ndim * 8) throw bad();
  header->shape.resize(ndim);
  for (size_t i = 0; i < ndim; ++i) {
    uint64_t d = 0;
    for (int k = 7; k >= 0; --k) d = (d << 8) | b[k];
    header->shape[i] = d;
    b += 8;
  }
  return {reinterpret_cast<const char*>(b), static_cast<size_t>(e - b)};
}

uint32_t parse_blob_index(std::string_view rest) {
  if (rest.size() != 4) throw std::runtime_error("bad numpy array blob reference");
  const auto* b = reinterpret_cast<const uint8_t*>(rest.data());
  return (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | b[3];
}

size_t dtype_size(std::string_view dtype) {
  if (dtype == "B" || dtype == "b" || dtype == "?") return 1;
  if (dtype.size() < 3 || std::string_view("<>|=").find(dtype[0]) == std::string_view::npos)
    return 0;
  const char kind = dtype[1];
  if (std::string_view("biufcSU").find(kind) == std::string_view::npos) return 0;
  size_t n = 0;
  auto [p, ec] = std::from_chars(dtype.data() + 2, dtype.data() + dtype.size(), n);
  if (ec != std::errc() || p != dtype.data() + dtype.size() || n == 0 || n > 64) return 0;
  return kind == 'U' ? 4 * n : n;  // "<U3": three UCS-4 characters
}

bool is_uint8(std::string_view dtype) {
  return dtype == "|u1" || dtype == "<u1" || dtype == "u1" || dtype == "B";
}

}  // namespace convoy::datapack
