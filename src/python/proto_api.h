// The C++ message inside a message of Python's protobuf ("cpp" implementation, Debian's
// python3-protobuf), through the C API its extension module exports (the capsule
// google.protobuf.pyext._message.proto_API). Python's protobuf and Convoy link the same
// libprotobuf, so the pointer can be used directly: datapacks are written from and read into
// Python messages without serializing them through Python bytes, and a large bytes field is
// copied once, straight between the message and a blob.
//
// Both functions return nullptr (with no Python error set) when the object is not such a
// message, or when Python's protobuf has another implementation; callers then go through
// SerializeToString / FromString.
#pragma once

#include <google/protobuf/message.h>
#include <pybind11/pybind11.h>

namespace convoy::python {

const google::protobuf::Message* cpp_message(pybind11::handle message);
// A message no Python object points into yet (no sub-message or repeated field fetched from
// Python): a fresh one, typically. nullptr otherwise.
google::protobuf::Message* mutable_cpp_message(pybind11::handle message);

}  // namespace convoy::python
