#include "python/datapack_convert.h"

#include <pybind11/embed.h>
#include <pybind11/numpy.h>

#include <cstring>
#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "convoy/datapacks.pb.h"
#include "datapack/camera.h"
#include "datapack/json.h"
#include "datapack/nrp.h"
#include "datapack/proto.h"
#include "datapack/registry.h"
#include "python/msgpack_codec.h"
#include "python/neighbour_views.h"
#include "python/proto_api.h"

// What Python sees of the datapack registry (nrp_core.data.nrp_protobuf builds its classes
// from it).
PYBIND11_EMBEDDED_MODULE(_convoy_datapack, m) {
  using convoy::datapack::Registry;
  // Python class name -> type name. Where two types share a class name, the one named at
  // registration wins (GazeboCameraDataPack is convoy.data.Camera, not Gazebo.Camera).
  m.def("types", [] {
    pybind11::dict out;
    for (const auto* t : Registry::global().all()) {
      pybind11::str cls(t->python_class);
      if (!t->named_class && out.contains(cls)) continue;
      out[cls] = t->name;
    }
    for (const auto* t : Registry::global().all())
      if (t->named_class) out[pybind11::str(t->python_class)] = t->name;
    return out;
  });
  // The same for RawData classes: here the type with the default (NRP-Core) name wins
  // (GazeboCameraRawData holds a Gazebo.Camera, as in NRP-Core).
  m.def("raw_types", [] {
    pybind11::dict out;
    for (const auto* t : Registry::global().all()) {
      pybind11::str cls(t->python_class);
      if (t->named_class && out.contains(cls)) continue;
      out[cls] = t->name;
    }
    for (const auto* t : Registry::global().all())
      if (!t->named_class) out[pybind11::str(t->python_class)] = t->name;
    return out;
  });
  // The .proto file a type comes from ("nrp_protobuf/dump.proto").
  m.def("proto_file", [](const std::string& type) {
    return Registry::global().add_by_name(type).descriptor->file()->name();
  });
  m.def("python_class",
        [](const std::string& type) { return Registry::global().add_by_name(type).python_class; });
  m.def("file_descriptor_set", [](const std::string& type) {
    return pybind11::bytes(Registry::global().file_descriptor_set(type));
  });
  convoy::python::add_neighbour_views(m);  // convoy_traffic.neighbours' views
}

namespace convoy::python {
namespace {

using datapack::Builder;
using datapack::View;

struct JsonClasses {
  py::object json, empty, base;
};

const JsonClasses& json_classes() {
  static JsonClasses* c = [] {
    py::module_ m = py::module_::import("nrp_core._datapacks");
    return new JsonClasses{m.attr("JsonDataPack"), m.attr("EmptyDataPack"), m.attr("DataPack")};
  }();
  return *c;
}

// Imported on first use: it needs numpy, which JSON-only experiments need not load.
const py::module_& proto_module() {
  static py::module_* m = new py::module_(py::module_::import("nrp_core.data.nrp_protobuf"));
  return *m;
}

py::object uint8_array(std::string_view bytes, bool in_shm, ImageAccess access) {
  static py::object* frombuffer_fn =
      new py::object(py::module_::import("numpy").attr("frombuffer"));
  const py::object& frombuffer = *frombuffer_fn;
  if (in_shm && access == ImageAccess::kView) {
    py::object view = py::reinterpret_steal<py::object>(PyMemoryView_FromMemory(
        const_cast<char*>(bytes.data()), static_cast<Py_ssize_t>(bytes.size()), PyBUF_READ));
    return frombuffer(view, "uint8");
  }
  // A private copy, which numpy then wraps without copying again.
  py::bytearray owned(bytes.data(), bytes.size());
  datapack::count_copy(bytes.size());
  return frombuffer(owned, "uint8");
}

std::vector<float> float_vector(py::handle value, size_t n, const char* what) {
  std::vector<float> out;
  for (auto v : value) out.push_back(v.cast<float>());
  if (out.size() != n) {
    throw std::runtime_error(std::string(what) + " needs " + std::to_string(n) + " numbers, got " +
                             std::to_string(out.size()));
  }
  return out;
}

// A float32 array of n values, zero where the message has fewer.
py::array_t<float> float_array(const google::protobuf::RepeatedField<float>& values, size_t n) {
  py::array_t<float> arr(static_cast<py::ssize_t>(n));
  float* out = arr.mutable_data();
  for (size_t i = 0; i < n; ++i)
    out[i] = i < static_cast<size_t>(values.size()) ? values.Get(static_cast<int>(i)) : 0.0f;
  return arr;
}

// The standard messages have converters of their own, with numpy fields and the report's
// attribute names (nrp_core.data.nrp_protobuf's CameraData, JointData, LinkData).
py::object camera_to_python(const View& in, ImageAccess access) {
  const datapack::CameraImage img = datapack::read_camera(in);
  return proto_module().attr("CameraData")(img.height, img.width, img.depth,
                                           uint8_array(img.pixels, img.in_shm, access));
}

void camera_from_python(py::handle data, Builder& out) {
  py::buffer_info info = py::buffer(data.attr("image_data")).request();
  std::string_view bytes(static_cast<const char*>(info.ptr),
                         static_cast<size_t>(info.size * info.itemsize));
  datapack::write_camera(out, data.attr("image_height").cast<uint32_t>(),
                         data.attr("image_width").cast<uint32_t>(),
                         data.attr("image_depth").cast<uint32_t>(), bytes);
}

py::object joint_to_python(const View& in, ImageAccess) {
  const auto j = datapack::read_proto<data::Joint>(in);
  return proto_module().attr("JointData")(j.position(), j.velocity(), j.effort());
}

void joint_from_python(py::handle data, Builder& out) {
  data::Joint j;
  j.set_position(data.attr("position").cast<float>());
  j.set_velocity(data.attr("velocity").cast<float>());
  j.set_effort(data.attr("effort").cast<float>());
  datapack::write_proto(out, j);
}

// LinkData(pos, rot, lin_vel, ang_vel) without its __init__, whose np.asarray keeps these
// float32 arrays as they are: the same object, for a fraction of the cost of every read.
py::object link_to_python(const View& in, ImageAccess) {
  static py::object* link_class = new py::object(proto_module().attr("LinkData"));
  static py::object* new_object =
      new py::object(py::module_::import("builtins").attr("object").attr("__new__"));
  const auto l = datapack::read_proto<data::Link>(in);
  py::array_t<float> rot = float_array(l.rotation(), 4);
  if (l.rotation_size() == 0) rot.mutable_data()[3] = 1.0f;
  py::object link = (*new_object)(*link_class);
  link.attr("pos") = float_array(l.position(), 3);
  link.attr("rot") = rot;
  link.attr("lin_vel") = float_array(l.linear_velocity(), 3);
  link.attr("ang_vel") = float_array(l.angular_velocity(), 3);
  return link;
}

void link_from_python(py::handle data, Builder& out) {
  data::Link l;
  for (float v : float_vector(data.attr("pos"), 3, "link position")) l.add_position(v);
  for (float v : float_vector(data.attr("rot"), 4, "link rotation")) l.add_rotation(v);
  for (float v : float_vector(data.attr("lin_vel"), 3, "link linear velocity"))
    l.add_linear_velocity(v);
  for (float v : float_vector(data.attr("ang_vel"), 3, "link angular velocity"))
    l.add_angular_velocity(v);
  datapack::write_proto(out, l);
}

struct Converter {
  const char* data_class;  // tp_name of the Python data object
  py::object (*to_data)(const View&, ImageAccess);
  void (*from_data)(py::handle, Builder&);
};

const std::unordered_map<std::string, Converter>& converters() {
  static const auto* table = new std::unordered_map<std::string, Converter>{
      {datapack::type_name<data::Camera>(), {"CameraData", camera_to_python, camera_from_python}},
      {datapack::type_name<data::Joint>(), {"JointData", joint_to_python, joint_from_python}},
      {datapack::type_name<data::Link>(), {"LinkData", link_to_python, link_from_python}},
  };
  return *table;
}

const Converter* converter_for_data(py::handle data) {
  const char* tp = Py_TYPE(data.ptr())->tp_name;
  for (const auto& [type, c] : converters())
    if (std::strcmp(tp, c.data_class) == 0) return &c;
  return nullptr;
}

// Every other registered message: a class of nrp_core.data.nrp_protobuf whose data is a
// Python protobuf message (built from the registry by _datapack_class).
const py::object& generic_class(const std::string& type) {
  static auto* classes = new std::unordered_map<std::string, py::object>;
  auto it = classes->find(type);
  if (it == classes->end())
    it = classes->emplace(type, proto_module().attr("_datapack_class")(type)).first;
  return it->second;
}

py::object proto_data(const View& in, ImageAccess access) {
  const std::string& type = in.proto_type();
  if (auto it = converters().find(type); it != converters().end())
    return it->second.to_data(in, access);
  try {
    const py::object& cls = generic_class(type).attr("_message");
    return message_from_datapack(in, cls);
  } catch (py::error_already_set& e) {
    throw std::runtime_error(in.describe() + " holds protobuf type " + type +
                             ", which Python cannot decode: " + e.what());
  }
}

// A Python protobuf message (it has a DESCRIPTOR): its full name names a registered type.
bool encode_generic(py::handle data, Builder& out) {
  if (!PyObject_HasAttrString(reinterpret_cast<PyObject*>(Py_TYPE(data.ptr())), "DESCRIPTOR") ||
      !py::hasattr(data, "SerializeToString"))
    return false;
  message_to_datapack(data, out);
  return true;
}

// nrp_core._datapacks.SerializedMessage (ProtobufDataPack.from_bytes): its bytes as they are.
bool encode_serialized(py::handle data, Builder& out) {
  static py::object* serialized =
      new py::object(py::module_::import("nrp_core._datapacks").attr("SerializedMessage"));
  if (Py_TYPE(data.ptr()) != reinterpret_cast<PyTypeObject*>(serialized->ptr())) return false;
  const py::object payload = data.attr("payload");
  if (!PyBytes_Check(payload.ptr()))
    throw std::invalid_argument("serialized message: the payload must be bytes, not " +
                                std::string(Py_TYPE(payload.ptr())->tp_name));
  const std::string type =
      data.attr("message_class").attr("DESCRIPTOR").attr("full_name").cast<std::string>();
  datapack::Registry::global().add_by_name(type);
  datapack::write_proto_bytes(
      out, type,
      std::string_view(PyBytes_AS_STRING(payload.ptr()),
                       static_cast<size_t>(PyBytes_GET_SIZE(payload.ptr()))));
  return true;
}

}  // namespace

py::object message_from_datapack(const View& in, py::handle message_class) {
  const engine::ProtoPayload& payload = in.message().proto();
  const bool other_type =  // a Gazebo message's standard type, or a wrong one
      in.proto_type() != message_class.attr("DESCRIPTOR").attr("full_name").cast<std::string>();
  // Small messages: Python parses the bytes itself (the cheapest way for a few fields).
  if (!other_type && payload.blob_fields_size() == 0 &&
      payload.data().size() < datapack::kLargeBlobBytes)
    return message_class.attr("FromString")(py::bytes(payload.data()));
  // Large ones are parsed straight into the new message's C++ object (bytes fields copied
  // once, from their blobs).
  py::object msg = message_class();
  if (google::protobuf::Message* m = mutable_cpp_message(msg)) {
    datapack::read_message(in, m);
    return msg;
  }
  const datapack::TypeInfo& t = datapack::Registry::global().add_by_name(
      msg.attr("DESCRIPTOR").attr("full_name").cast<std::string>());
  std::unique_ptr<google::protobuf::Message> tmp(t.prototype->New());
  datapack::read_message(in, tmp.get());
  return message_class.attr("FromString")(py::bytes(tmp->SerializeAsString()));
}

void message_to_datapack(py::handle message, Builder& out) {
  if (const google::protobuf::Message* m = cpp_message(message)) {
    datapack::Registry::global().add_by_name(m->GetDescriptor()->full_name());
    datapack::write_message(out, *m);
    return;
  }
  const std::string type = message.attr("DESCRIPTOR").attr("full_name").cast<std::string>();
  const datapack::TypeInfo& t = datapack::Registry::global().add_by_name(type);
  std::unique_ptr<google::protobuf::Message> tmp(t.prototype->New());
  if (!tmp->ParseFromString(message.attr("SerializeToString")().cast<std::string>()))
    throw std::runtime_error("cannot re-read a " + type + " message");
  datapack::write_message(out, *tmp);
}

py::object decode_json(const std::string& msgpack, const View* owner) {
  PyObject* v = msgpack_decode(msgpack, owner);
  if (!v) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(v);
}

void encode_json(py::handle value, std::string* out, Builder* owner) {
  if (!msgpack_encode(value.ptr(), out, owner)) throw py::error_already_set();
}

py::object data_to_python(const View& in, ImageAccess images) {
  if (in.is_json()) return decode_json(in.message().json_msgpack(), &in);
  if (in.is_proto()) return proto_data(in, images);
  return py::none();
}

py::object to_python(const View& in, ImageAccess images) {
  const auto& id = in.id();
  if (in.is_json())
    return json_classes().json(id.name(), id.engine_name(), data_to_python(in, images));
  if (in.is_proto()) {
    const std::string& type = in.proto_type();
    py::object data = proto_data(in, images);
    py::object cls;
    if (const auto* t = datapack::Registry::global().find(type); t && converters().count(type))
      cls = proto_module().attr(t->python_class.c_str());
    else
      cls = generic_class(type);
    // The class's own constructor would make default data for `data` to replace.
    static py::object* received =
        new py::object(py::module_::import("nrp_core._datapacks").attr("_received"));
    return (*received)(cls, id.name(), id.engine_name(), data);
  }
  return json_classes().empty(id.name(), id.engine_name(), id.type());
}

void data_from_python(py::handle data, Builder& out) {
  if (data.is_none()) {
    out.clear();
    return;
  }
  try {
    if (!PyDict_Check(data.ptr())) {
      if (encode_serialized(data, out)) return;
      if (const Converter* c = converter_for_data(data)) {
        c->from_data(data, out);
        return;
      }
      if (encode_generic(data, out)) return;
    }
    auto* dp = out.message();
    dp->mutable_id()->set_type(std::string(datapack::kJsonType));
    std::string* bytes = dp->mutable_json_msgpack();
    bytes->clear();
    encode_json(data, bytes, &out);
  } catch (py::error_already_set& e) {
    throw std::runtime_error(out.describe() + ": " + e.what());
  } catch (const py::cast_error& e) {
    throw std::runtime_error(out.describe() + ": wrong field type (" + e.what() + ")");
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(out.describe() + ": " + e.what());
  }
}

void from_python(py::handle obj, Builder& out) {
  if (!py::isinstance(obj, json_classes().base)) {
    throw std::runtime_error("returned a " + std::string(Py_TYPE(obj.ptr())->tp_name) +
                             " where a datapack (e.g. JsonDataPack) was expected");
  }
  py::object id = obj.attr("_id");
  auto* pid = out.message()->mutable_id();
  pid->set_name(id.attr("dataPackName").cast<std::string>());
  pid->set_engine_name(id.attr("engineName").cast<std::string>());
  data_from_python(obj.attr("_data"), out);
}

}  // namespace convoy::python
