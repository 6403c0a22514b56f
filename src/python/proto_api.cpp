#include "python/proto_api.h"

#include <google/protobuf/wrappers.pb.h>

namespace convoy::python {

// The start of PyProto_API as protobuf 3.x declares it (python/google/protobuf/proto_api.h,
// which Debian does not install): a table of virtual functions whose first two entries after
// the destructor read and write the C++ message of a Python message. (Outside an anonymous
// namespace: there GCC knows that no class derives from it and turns the calls into calls
// of __cxa_pure_virtual.)
struct PyProtoApi {
  virtual ~PyProtoApi() = default;
  virtual const google::protobuf::Message* GetMessagePointer(PyObject* msg) const = 0;
  virtual google::protobuf::Message* GetMutableMessagePointer(PyObject* msg) const = 0;
};

namespace {

// The API, when Python's protobuf is the "cpp" implementation and runs on the libprotobuf this
// program links (a message made by another copy of the library must not be touched).
const PyProtoApi* api() {
  static const PyProtoApi* a = []() -> const PyProtoApi* {
    pybind11::module_ impl;
    try {
      impl = pybind11::module_::import("google.protobuf.internal.api_implementation");
      if (impl.attr("Type")().cast<std::string>() != "cpp") return nullptr;
      // The layout above is that of protobuf 3.x (Python 3.x and 4.21); later versions put
      // another function first.
      const auto version =
          pybind11::module_::import("google.protobuf").attr("__version__").cast<std::string>();
      if (!(version.rfind("3.", 0) == 0 || version.rfind("4.21.", 0) == 0)) return nullptr;
    } catch (pybind11::error_already_set&) {
      return nullptr;
    }
    auto* capsule = static_cast<const PyProtoApi*>(
        PyCapsule_Import("google.protobuf.pyext._message.proto_API", 0));
    if (!capsule) {
      PyErr_Clear();
      return nullptr;
    }
    // Same library: Google's own BoolValue, made by Python, has the descriptor of the
    // BoolValue this program links (both come from libprotobuf's generated pool).
    try {
      pybind11::object probe =
          pybind11::module_::import("google.protobuf.wrappers_pb2").attr("BoolValue")();
      const google::protobuf::Message* m = capsule->GetMessagePointer(probe.ptr());
      if (!m || m->GetDescriptor() != google::protobuf::BoolValue::descriptor()) {
        PyErr_Clear();
        return nullptr;
      }
    } catch (pybind11::error_already_set&) {
      return nullptr;
    }
    return capsule;
  }();
  return a;
}

bool is_message(pybind11::handle obj) {
  static PyObject* base = [] {
    try {
      return pybind11::object(pybind11::module_::import("google.protobuf.message").attr("Message"))
          .release()
          .ptr();
    } catch (pybind11::error_already_set&) {
      return static_cast<PyObject*>(nullptr);
    }
  }();
  return base && PyObject_IsInstance(obj.ptr(), base) == 1;
}

}  // namespace

const google::protobuf::Message* cpp_message(pybind11::handle message) {
  const PyProtoApi* a = api();
  if (!a || !is_message(message)) return nullptr;
  const google::protobuf::Message* m = a->GetMessagePointer(message.ptr());
  if (!m) PyErr_Clear();
  return m;
}

google::protobuf::Message* mutable_cpp_message(pybind11::handle message) {
  const PyProtoApi* a = api();
  if (!a || !is_message(message)) return nullptr;
  google::protobuf::Message* m = a->GetMutableMessagePointer(message.ptr());
  if (!m) PyErr_Clear();
  return m;
}

}  // namespace convoy::python
