// JSON datapacks: a JSON value as MessagePack (DataPack.json_msgpack), with numpy arrays as
// MessagePack ext values (ndarray.h) whose large bytes sit in blobs. This is the C++ codec;
// Python values go through python/msgpack_codec.h, which writes the same bytes.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string_view>

#include "datapack/datapack.h"
#include "datapack/ndarray.h"

namespace convoy::datapack {

// Deepest nesting of arrays and maps a JSON datapack may have (both codecs, C++ and Python):
// deeper data is refused rather than read recursively off the end of the stack.
inline constexpr int kMaxJsonDepth = 200;

void write_json(Builder& out, const nlohmann::json& value);
// Throws std::runtime_error naming the datapack unless it holds a JSON value.
nlohmann::json read_json(const View& in);

// The JSON text of the datapack's value: read_json(in).dump()'s, written straight from the
// MessagePack bytes when they hold only what JSON has (msgpack_json.cpp), else that way.
std::string json_text(const View& in);
// That text of the MessagePack value `msgpack`; false (and `out` unspecified) when it holds
// binary or extension values, non-ASCII strings, non-string keys, nesting deeper than 63
// levels, or is malformed: the cases left to nlohmann.
bool msgpack_json_text(std::string_view msgpack, std::string* out);

// A numpy array as a JSON value (nlohmann binary with the ext type as subtype): its bytes
// inline when small, else in a blob of `out`.
nlohmann::json ndarray_json(Builder& out, std::string_view dtype, std::span<const uint64_t> shape,
                            std::string_view bytes);

// An array inside a JSON value read with read_json. `data` points into `value` (inline
// bytes) or into the blob (see View for how long that stays valid).
struct NdarrayRef {
  NdarrayHeader header;
  std::string_view data;
  bool in_shm = false;
};
// Throws std::runtime_error unless `value` is a numpy array whose bytes match its shape.
NdarrayRef read_ndarray(const View& in, const nlohmann::json& value);

}  // namespace convoy::datapack
