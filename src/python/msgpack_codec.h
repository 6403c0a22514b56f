// Python objects <-> MessagePack bytes, the wire form of JSON datapacks.
//
// Handles None, bool, int, float, str, bytes, list, tuple, dict and numpy arrays. A numpy
// array travels as a MessagePack ext: [u8 len][dtype str][u8 ndim][u64 LE dims...] followed
// by the raw C-order bytes (type 1) or by the index of a blob holding them (type 2), never as
// a list of numbers; it decodes to an ndarray.
// Numpy scalars encode as their Python value. Anything else raises TypeError.
#pragma once

#include <Python.h>

#include <string>
#include <string_view>

#include "convoy/engine.pb.h"

namespace convoy::python {

constexpr int8_t kNdarrayExtType = 1;      // header + raw bytes
constexpr int8_t kNdarrayBlobExtType = 2;  // header + u32 index of the datapack's blob

// Appends the encoding of `obj` to `out`. With `blob_owner`, large arrays become blobs of
// that datapack (written by transport::current_blob_writer()). Returns false with a Python
// exception set on error.
bool msgpack_encode(PyObject* obj, std::string* out, engine::DataPack* blob_owner = nullptr);
// Decodes one value; returns a new reference or nullptr with a Python exception set. Blobs
// are read from `blob_owner` through transport::current_blob_reader(); arrays are copies.
PyObject* msgpack_decode(std::string_view bytes, const engine::DataPack* blob_owner = nullptr);

}  // namespace convoy::python
