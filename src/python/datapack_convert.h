// Datapacks between their wire form (engine::DataPack) and nrp_core's Python classes.
#pragma once

#include <pybind11/pybind11.h>

#include <string>

#include "convoy/engine.pb.h"

namespace convoy::python {

namespace py = pybind11;

// JSON data (MessagePack bytes) <-> Python value. Throw py::error_already_set on error.
py::object decode_json(const std::string& msgpack);
void encode_json(py::handle value, std::string* out);

// engine::DataPack -> JsonDataPack, or EmptyDataPack when it has no payload.
py::object to_python(const engine::DataPack& datapack);
// A Python datapack object -> engine::DataPack. Throws std::runtime_error naming the problem.
void from_python(py::handle datapack, engine::DataPack* out);

}  // namespace convoy::python
