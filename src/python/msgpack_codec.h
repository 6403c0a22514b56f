// Python objects <-> MessagePack bytes, the wire form of JSON datapacks (the C++ codec of the
// same bytes is datapack/json.h).
//
// Handles None, bool, int, float, str, bytes, list, tuple, dict and numpy arrays. A numpy
// array travels as a MessagePack ext (datapack/ndarray.h), never as a list of numbers; it
// decodes to an ndarray.
// Numpy scalars encode as their Python value. Anything else raises TypeError.
#pragma once

#include <Python.h>

#include <string>
#include <string_view>

#include "datapack/datapack.h"

namespace convoy::python {

// Appends the encoding of `obj` to `out`. With `blob_owner`, large arrays become blobs of
// that datapack, written by its blob writer; without, they stay inline. Returns false with a
// Python exception set on error.
bool msgpack_encode(PyObject* obj, std::string* out, datapack::Builder* blob_owner = nullptr);
// Decodes one value; returns a new reference or nullptr with a Python exception set. Blobs
// are read from `blob_owner` with its blob reader; arrays are copies.
PyObject* msgpack_decode(std::string_view bytes, const datapack::View* blob_owner = nullptr);

}  // namespace convoy::python
