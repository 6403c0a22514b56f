// nlohmann::json <-> Python objects, as json.dumps / json.loads would turn them (a reply
// converted here equals the query tool's reply line read with json.loads; NaN becomes None as
// nlohmann's dump writes null).
#pragma once

#include <pybind11/pybind11.h>

#include <nlohmann/json.hpp>

namespace convoy::opendrive::python {

namespace py = pybind11;

// None, bool, int, float, str, list / tuple and dict (str keys); anything else raises
// TypeError naming its type.
nlohmann::json to_json(py::handle value);
py::object from_json(const nlohmann::json& value);

}  // namespace convoy::opendrive::python
