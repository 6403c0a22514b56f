#include "python/datapack_convert.h"

#include <pybind11/numpy.h>

#include <cstring>
#include <stdexcept>

#include "convoy/datapacks.pb.h"
#include "python/msgpack_codec.h"
#include "transport/blobs.h"

namespace convoy::python {
namespace {

constexpr const char* kCamera = "convoy.data.Camera";
constexpr const char* kJoint = "convoy.data.Joint";
constexpr const char* kLink = "convoy.data.Link";

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

bool type_is(py::handle obj, const char* name) {
  return std::strcmp(Py_TYPE(obj.ptr())->tp_name, name) == 0;
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

py::object proto_data(const engine::DataPack& dp, ImageAccess access) {
  const auto& p = dp.proto();
  const std::string& type = p.type_name();
  const py::module_& m = proto_module();
  if (type == kCamera) {
    data::Camera c;
    if (!c.ParseFromString(p.data())) throw std::runtime_error("corrupt camera datapack");
    py::object image;
    if (c.image_blob() > 0) {
      bool in_shm = false;
      auto bytes = transport::current_blob_reader().get(dp, c.image_blob() - 1, &in_shm);
      image = uint8_array(bytes, in_shm, access);
    } else {
      image = uint8_array(c.image_data(), false, access);
    }
    return m.attr("CameraData")(c.image_height(), c.image_width(), c.image_depth(), image);
  }
  if (type == kJoint) {
    data::Joint j;
    if (!j.ParseFromString(p.data())) throw std::runtime_error("corrupt joint datapack");
    return m.attr("JointData")(j.position(), j.velocity(), j.effort());
  }
  if (type == kLink) {
    data::Link l;
    if (!l.ParseFromString(p.data())) throw std::runtime_error("corrupt link datapack");
    py::array_t<float> rot = float_array(l.rotation(), 4);
    if (l.rotation_size() == 0) rot.mutable_data()[3] = 1.0f;
    return m.attr("LinkData")(float_array(l.position(), 3), rot,
                              float_array(l.linear_velocity(), 3),
                              float_array(l.angular_velocity(), 3));
  }
  throw std::runtime_error("datapack '" + dp.id().name() + "' of engine '" + dp.id().engine_name() +
                           "' holds protobuf type " + type + ", which has no Python class");
}

const char* proto_class(const std::string& type) {
  if (type == kCamera) return "GazeboCameraDataPack";
  if (type == kJoint) return "GazeboJointDataPack";
  if (type == kLink) return "GazeboLinkDataPack";
  return nullptr;
}

// Encodes a CameraData / JointData / LinkData; false if `data` is none of them.
bool encode_proto(py::handle data, engine::DataPack* out) {
  auto* payload = out->mutable_proto();
  if (type_is(data, "CameraData")) {
    data::Camera c;
    c.set_image_height(data.attr("image_height").cast<uint32_t>());
    c.set_image_width(data.attr("image_width").cast<uint32_t>());
    c.set_image_depth(data.attr("image_depth").cast<uint32_t>());
    py::object image = data.attr("image_data");
    py::buffer_info info = py::buffer(image).request();
    std::string_view bytes(static_cast<const char*>(info.ptr),
                           static_cast<size_t>(info.size * info.itemsize));
    if (bytes.size() >= transport::kShmBlobThreshold) {
      c.set_image_blob(transport::current_blob_writer().add(out, bytes) + 1);
    } else {
      c.set_image_data(bytes.data(), bytes.size());
    }
    payload->set_type_name(kCamera);
    c.SerializeToString(payload->mutable_data());
  } else if (type_is(data, "JointData")) {
    data::Joint j;
    j.set_position(data.attr("position").cast<float>());
    j.set_velocity(data.attr("velocity").cast<float>());
    j.set_effort(data.attr("effort").cast<float>());
    payload->set_type_name(kJoint);
    j.SerializeToString(payload->mutable_data());
  } else if (type_is(data, "LinkData")) {
    data::Link l;
    for (float v : float_vector(data.attr("pos"), 3, "link position")) l.add_position(v);
    for (float v : float_vector(data.attr("rot"), 4, "link rotation")) l.add_rotation(v);
    for (float v : float_vector(data.attr("lin_vel"), 3, "link linear velocity"))
      l.add_linear_velocity(v);
    for (float v : float_vector(data.attr("ang_vel"), 3, "link angular velocity"))
      l.add_angular_velocity(v);
    payload->set_type_name(kLink);
    l.SerializeToString(payload->mutable_data());
  } else {
    out->clear_payload();
    return false;
  }
  out->mutable_id()->set_type(payload->type_name());
  return true;
}

}  // namespace

py::object decode_json(const std::string& msgpack, const engine::DataPack* owner) {
  PyObject* v = msgpack_decode(msgpack, owner);
  if (!v) throw py::error_already_set();
  return py::reinterpret_steal<py::object>(v);
}

void encode_json(py::handle value, std::string* out, engine::DataPack* owner) {
  if (!msgpack_encode(value.ptr(), out, owner)) throw py::error_already_set();
}

py::object data_to_python(const engine::DataPack& dp, ImageAccess images) {
  switch (dp.payload_case()) {
    case engine::DataPack::kJsonMsgpack:
      return decode_json(dp.json_msgpack(), &dp);
    case engine::DataPack::kProto:
      return proto_data(dp, images);
    default:
      return py::none();
  }
}

py::object to_python(const engine::DataPack& dp, ImageAccess images) {
  const auto& id = dp.id();
  switch (dp.payload_case()) {
    case engine::DataPack::kJsonMsgpack:
      return json_classes().json(id.name(), id.engine_name(), data_to_python(dp, images));
    case engine::DataPack::kProto: {
      const char* cls = proto_class(dp.proto().type_name());
      py::object data = proto_data(dp, images);
      py::object obj = proto_module().attr(cls)(id.name(), id.engine_name());
      obj.attr("_data") = data;
      return obj;
    }
    default:
      return json_classes().empty(id.name(), id.engine_name(), id.type());
  }
}

void data_from_python(py::handle data, engine::DataPack* out) {
  if (data.is_none()) {
    out->clear_payload();
    return;
  }
  try {
    if (!PyDict_Check(data.ptr()) && encode_proto(data, out)) return;
    out->mutable_id()->set_type("json");
    std::string* bytes = out->mutable_json_msgpack();
    bytes->clear();
    encode_json(data, bytes, out);
  } catch (py::error_already_set& e) {
    throw std::runtime_error("datapack '" + out->id().name() + "' for engine '" +
                             out->id().engine_name() + "': " + e.what());
  } catch (const py::cast_error& e) {
    throw std::runtime_error("datapack '" + out->id().name() + "' for engine '" +
                             out->id().engine_name() + "': wrong field type (" + e.what() + ")");
  }
}

void from_python(py::handle obj, engine::DataPack* out) {
  if (!py::isinstance(obj, json_classes().base)) {
    throw std::runtime_error("returned a " + std::string(Py_TYPE(obj.ptr())->tp_name) +
                             " where a datapack (e.g. JsonDataPack) was expected");
  }
  py::object id = obj.attr("_id");
  auto* pid = out->mutable_id();
  pid->set_name(id.attr("dataPackName").cast<std::string>());
  pid->set_engine_name(id.attr("engineName").cast<std::string>());
  data_from_python(obj.attr("_data"), out);
}

}  // namespace convoy::python
