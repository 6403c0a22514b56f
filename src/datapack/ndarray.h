// The numpy-array form used inside JSON datapacks, in one place.
//
// An array is a MessagePack ext value whose body is a header
//   [u8 n][dtype string, n bytes][u8 ndim][ndim x u64 little-endian dims]
// followed either by the raw C-order bytes (ext type 1) or by the big-endian u32 index of the
// datapack's blob holding them (ext type 2, for large arrays). Arrays never travel as lists of
// numbers.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace convoy::datapack {

constexpr int8_t kNdarrayExtType = 1;      // header + raw bytes
constexpr int8_t kNdarrayBlobExtType = 2;  // header + u32 index of the datapack's blob

struct NdarrayHeader {
  std::string dtype;  // numpy's dtype.str: "|u1", "<f4", ...
  std::vector<uint64_t> shape;
  uint64_t count() const;  // elements
};

// Appends the header.
void append_ndarray_header(std::string* out, std::string_view dtype,
                           std::span<const uint64_t> shape);
void append_ndarray_header(std::vector<uint8_t>* out, std::string_view dtype,
                           std::span<const uint64_t> shape);
// Parses the header at the start of an ext body; returns the rest of the body (the raw bytes,
// or the blob index). Throws std::runtime_error("bad numpy array header") when malformed.
std::string_view parse_ndarray_header(std::string_view body, NdarrayHeader* header);

// The blob index that follows the header in an ext type 2 body.
void append_blob_index(std::string* out, uint32_t index);
void append_blob_index(std::vector<uint8_t>* out, uint32_t index);
// Throws std::runtime_error unless `rest` is exactly one index.
uint32_t parse_blob_index(std::string_view rest);

// Bytes per element of a dtype string ("<f4" -> 4); 0 when unknown or not plain data.
// Only plain data travels: booleans, integers, floats, complex numbers and fixed-size byte
// or unicode strings ("?", "b", "B" or "|b1", "<i4", "<u2", "<f8", "<c16", "|S5", "<U3").
// Object arrays ("|O8") and structured or void types are refused: their bytes would be
// pointers or records that a receiver must never build from data off the wire.
size_t dtype_size(std::string_view dtype);
// Whether a dtype is one byte unsigned ("|u1", "<u1", "u1", "B").
bool is_uint8(std::string_view dtype);

}  // namespace convoy::datapack
