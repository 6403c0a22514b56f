// _convoy_odr: the OpenDRIVE library for Python. python/convoy_scenario/roads.py imports it,
// calls set_error_type(ScenarioError) once and wraps Map in its RoadMap (the documented API).
// C++ errors (a missing or malformed map, an unknown road or lane, a bad query) are raised as
// that type with the C++ message; TypeError for arguments of the wrong type stays TypeError.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <exception>
#include <new>

#include "opendrive/python/road_map.h"

namespace py = pybind11;
using convoy::opendrive::python::RoadMap;

namespace {

PyObject* g_error = nullptr;  // a strong reference, set by set_error_type

void set_error_type(py::object type) {
  if (!PyType_Check(type.ptr()) ||
      !PyType_IsSubtype(reinterpret_cast<PyTypeObject*>(type.ptr()),
                        reinterpret_cast<PyTypeObject*>(PyExc_Exception))) {
    throw py::type_error("set_error_type needs an Exception subclass");
  }
  Py_XDECREF(g_error);
  g_error = type.release().ptr();
}

}  // namespace

PYBIND11_MODULE(_convoy_odr, m) {
  m.doc() = "OpenDRIVE maps in-process (use convoy_scenario.roads.RoadMap)";
  g_error = nullptr;  // a module initialised again after the interpreter restarted
  m.def("set_error_type", &set_error_type, py::arg("type"),
        "The exception type raised for the library's errors (RuntimeError until set).");
  py::register_local_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::builtin_exception&) {
      throw;
    } catch (const py::error_already_set&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::exception& e) {
      PyErr_SetString(g_error ? g_error : PyExc_RuntimeError, e.what());
    }
  });

  py::class_<RoadMap>(m, "Map")
      .def(py::init<const std::string&>(), py::arg("path"))
      .def_property_readonly("path", &RoadMap::path)
      .def_property_readonly("warnings", &RoadMap::warnings)
      .def("road_ids", &RoadMap::road_ids)
      .def("road_length", &RoadMap::road_length, py::arg("road"))
      .def("road_junction", &RoadMap::road_junction, py::arg("road"))
      .def("lane_pose", &RoadMap::lane_pose, py::arg("road"), py::arg("lane"), py::arg("s"),
           py::arg("t") = 0.0)
      .def("road_pose", &RoadMap::road_pose, py::arg("road"), py::arg("s"), py::arg("t") = 0.0)
      .def("lane_info", &RoadMap::lane_info, py::arg("road"), py::arg("lane"), py::arg("s"))
      .def("lanes_at", &RoadMap::lanes_at, py::arg("road"), py::arg("s"))
      .def("next_lanes", &RoadMap::next_lanes, py::arg("road"), py::arg("lane"), py::arg("s"))
      .def("prev_lanes", &RoadMap::prev_lanes, py::arg("road"), py::arg("lane"), py::arg("s"))
      .def("locate", &RoadMap::locate, py::arg("x"), py::arg("y"), py::arg("heading") = py::none(),
           py::arg("max_distance") = 5.0, py::arg("lane_types") = py::none())
      .def("route", &RoadMap::route, py::arg("from_"), py::arg("to"), py::arg("ds") = 2.0)
      .def("follow", &RoadMap::follow, py::arg("road"), py::arg("lane"), py::arg("s"),
           py::arg("length"), py::arg("ds") = 2.0)
      .def("query", &RoadMap::query, py::arg("request"));
}
