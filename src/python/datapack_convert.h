// Datapacks between their wire form and nrp_core's Python classes.
//
// JSON data <-> Python values (dicts, lists, numpy arrays). Protobuf data <-> the Python class
// of its registered type (datapack/registry.h): the standard messages convoy.data.Camera /
// Joint / Link become GazeboCameraDataPack / GazeboJointDataPack / GazeboLinkDataPack with
// numpy fields (a camera image is a view on the received frame); any other registered message
// becomes a datapack class of nrp_core.data.nrp_protobuf whose data is a message of Debian's
// Python protobuf, built from the registry's descriptors. Blobs are read and written through
// the View / Builder given.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "datapack/datapack.h"

namespace convoy::python {

namespace py = pybind11;

// JSON data (MessagePack bytes) <-> Python value. Throw py::error_already_set on error.
py::object decode_json(const std::string& msgpack, const datapack::View* owner = nullptr);
void encode_json(py::handle value, std::string* out, datapack::Builder* owner = nullptr);

// How a camera image reaches Python: a read-only view on the received bytes (zero copy,
// valid while the sender keeps them: the coordinator's functions during one cycle) or a copy
// (an engine, which keeps its datapacks across steps).
enum class ImageAccess { kView, kCopy };

// A datapack -> JsonDataPack / a protobuf datapack class, or EmptyDataPack without a payload.
py::object to_python(const datapack::View& datapack, ImageAccess images = ImageAccess::kView);
// Only the data: a JSON value, the protobuf data object, or None if empty.
py::object data_to_python(const datapack::View& datapack, ImageAccess images);

// A Python datapack object -> `out` (id included). Throws std::runtime_error naming the problem.
void from_python(py::handle datapack, datapack::Builder& out);
// Data only (a JSON value or a protobuf data object) into `out`, whose id is set.
void data_from_python(py::handle data, datapack::Builder& out);

// A Python protobuf message of `message_class` read from a protobuf datapack of its type (or,
// for NRP-Core's Gazebo messages, of their standard type: datapack/nrp.h). Throws
// std::runtime_error (datapack errors) or py::error_already_set.
py::object message_from_datapack(const datapack::View& in, py::handle message_class);
// A Python protobuf message into `out` (id set): registered by its full name, Gazebo messages
// as their standard types, large bytes fields into blobs. Throws std::invalid_argument for a
// type Convoy does not know.
void message_to_datapack(py::handle message, datapack::Builder& out);

}  // namespace convoy::python
