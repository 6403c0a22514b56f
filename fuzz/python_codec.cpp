// Fuzzes the CPython <-> MessagePack codec (src/python/msgpack_codec.cpp) in an embedded
// interpreter started once: decode a datapack's MessagePack (blobs and payload as in
// fuzz_input.h); whatever decodes must encode again, and decode to an equal value.
#include <Python.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "python/msgpack_codec.h"
#include "read_datapack.h"

using namespace convoy;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  Py_InitializeEx(0);
  PyObject* np = PyImport_ImportModule("numpy");  // imported once, not during a run
  if (!np) fuzz::fail("numpy not importable");
  Py_DECREF(np);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const fuzz::BlobbedInput parts = fuzz::split_blobs({reinterpret_cast<const char*>(data), size});
  engine::DataPack dp;
  dp.mutable_id()->set_name("fuzz");
  for (auto b : parts.blobs) dp.add_blobs()->set_inline_(std::string(b));
  const datapack::View view(dp, datapack::inline_blob_reader());

  PyObject* value = python::msgpack_decode(parts.payload, &view);
  if (!value) {
    if (!PyErr_Occurred()) fuzz::fail("msgpack_decode failed without a Python error");
    PyErr_Clear();
    return 0;
  }
  std::string again;
  if (!python::msgpack_encode(value, &again)) {
    // Only values Python cannot hold as JSON (e.g. a float dict key) may fail to encode.
    if (!PyErr_Occurred()) fuzz::fail("msgpack_encode failed without a Python error");
    PyErr_Clear();
  } else {
    PyObject* back = python::msgpack_decode(again, nullptr);
    if (!back) fuzz::fail("msgpack_decode rejected what msgpack_encode wrote");
    Py_DECREF(back);
  }
  Py_DECREF(value);
  return 0;
}
