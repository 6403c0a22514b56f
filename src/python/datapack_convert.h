// Datapacks between their wire form (engine::DataPack) and nrp_core's Python classes.
//
// JSON data <-> Python values (dicts, lists, numpy arrays); the standard protobuf messages
// (convoy.data.Camera / Joint / Link) <-> GazeboCameraDataPack / GazeboJointDataPack /
// GazeboLinkDataPack. Blobs are read and written through the thread's current blob
// reader / writer (transport/blobs.h).
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "convoy/engine.pb.h"

namespace convoy::python {

namespace py = pybind11;

// JSON data (MessagePack bytes) <-> Python value. Throw py::error_already_set on error.
py::object decode_json(const std::string& msgpack, const engine::DataPack* owner = nullptr);
void encode_json(py::handle value, std::string* out, engine::DataPack* owner = nullptr);

// How a camera image reaches Python: a read-only view on the received bytes (zero copy,
// valid while the sender keeps them: the coordinator's functions during one cycle) or a copy
// (an engine, which keeps its datapacks across steps).
enum class ImageAccess { kView, kCopy };

// engine::DataPack -> JsonDataPack / Gazebo*DataPack, or EmptyDataPack without a payload.
py::object to_python(const engine::DataPack& datapack, ImageAccess images = ImageAccess::kView);
// Only the data: a dict (JSON), a CameraData / JointData / LinkData, or None if empty.
py::object data_to_python(const engine::DataPack& datapack, ImageAccess images);

// A Python datapack object -> engine::DataPack. Throws std::runtime_error naming the problem.
void from_python(py::handle datapack, engine::DataPack* out);
// Data only (a JSON value or a CameraData / JointData / LinkData) into `out`, whose id is set.
void data_from_python(py::handle data, engine::DataPack* out);

}  // namespace convoy::python
