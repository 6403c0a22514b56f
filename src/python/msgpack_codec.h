// Python objects <-> MessagePack bytes, the wire form of JSON datapacks.
//
// Handles None, bool, int, float, str, bytes, list, tuple, dict and numpy arrays. A numpy
// array travels as MessagePack ext type 1: [u8 len][dtype str][u8 ndim][u64 LE dims...]
// followed by the raw C-order bytes, never as a list of numbers; it decodes to an ndarray.
// Numpy scalars encode as their Python value. Anything else raises TypeError.
#pragma once

#include <Python.h>

#include <string>
#include <string_view>

namespace convoy::python {

constexpr int8_t kNdarrayExtType = 1;

// Appends the encoding of `obj` to `out`. Returns false with a Python exception set on error.
bool msgpack_encode(PyObject* obj, std::string* out);
// Decodes one value; returns a new reference or nullptr with a Python exception set.
PyObject* msgpack_decode(std::string_view bytes);

}  // namespace convoy::python
