#include "python/datapack_convert.h"

#include <stdexcept>

#include "python/msgpack_codec.h"

namespace convoy::python {
namespace {

struct Classes {
  py::object json, empty, base;
};

const Classes& classes() {
  static Classes* c = [] {
    py::module_ m = py::module_::import("nrp_core._datapacks");
    return new Classes{m.attr("JsonDataPack"), m.attr("EmptyDataPack"), m.attr("DataPack")};
  }();
  return *c;
}

}  // namespace

py::object decode_json(const std::string& msgpack) {
  PyObject* v = msgpack_decode(msgpack);
  if (!v) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(v);
}

void encode_json(py::handle value, std::string* out) {
  if (!msgpack_encode(value.ptr(), out)) throw py::error_already_set();
}

py::object to_python(const engine::DataPack& datapack) {
  const auto& id = datapack.id();
  switch (datapack.payload_case()) {
    case engine::DataPack::kJsonMsgpack:
      return classes().json(id.name(), id.engine_name(), decode_json(datapack.json_msgpack()));
    case engine::DataPack::kProto:
      throw std::runtime_error("datapack '" + id.name() + "' of engine '" + id.engine_name() +
                               "' holds protobuf type " + datapack.proto().type_name() +
                               ", which has no Python class");
    default:
      return classes().empty(id.name(), id.engine_name(), id.type());
  }
}

void from_python(py::handle obj, engine::DataPack* out) {
  if (!py::isinstance(obj, classes().base)) {
    throw std::runtime_error("returned a " + std::string(Py_TYPE(obj.ptr())->tp_name) +
                             " where a datapack (e.g. JsonDataPack) was expected");
  }
  py::object id = obj.attr("_id");
  auto* pid = out->mutable_id();
  pid->set_name(id.attr("dataPackName").cast<std::string>());
  pid->set_engine_name(id.attr("engineName").cast<std::string>());
  py::object data = obj.attr("_data");
  if (data.is_none()) {
    out->clear_payload();
    return;
  }
  if (py::isinstance(obj, classes().json)) {
    pid->set_type("json");
    std::string* bytes = out->mutable_json_msgpack();
    bytes->clear();
    try {
      encode_json(data, bytes);
    } catch (py::error_already_set& e) {
      throw std::runtime_error("datapack '" + pid->name() + "' for engine '" +
                               pid->engine_name() + "': " + e.what());
    }
    return;
  }
  throw std::runtime_error("datapack '" + pid->name() + "' has type " +
                           std::string(Py_TYPE(obj.ptr())->tp_name) +
                           ", which cannot be sent to an engine");
}

}  // namespace convoy::python
