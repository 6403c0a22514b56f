// python_grpc: runs a user's GrpcEngineScript (NRP-Core's Python GRPC engine).
//
// Config keys: PythonFileName (the script; its class `Script`, or its only GrpcEngineScript
// subclass, is instantiated), ProtobufPackages (NRP-Core's packages the engine exchanges:
// checked by the schema; a datapack of another package gets a warning). Datapacks: whatever
// the script registers with _registerDataPack(name, message class); their data are messages
// of Python's protobuf, written and read through the datapack library (datapack/nrp.h,
// proto.h): large bytes fields in blobs, Gazebo messages as Convoy's standard types. Python's
// messages are read and filled in C++ without passing through Python bytes
// (python/proto_api.h).
#include <cstdio>
#include <set>

#include "datapack/nrp.h"
#include "datapack/registry.h"
#include "engine/engine.h"
#include "python/datapack_convert.h"
#include "python/engine_script.h"

namespace convoy::engines {
namespace {

namespace py = pybind11;

std::string join(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

class PythonGrpcEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    read_packages(config);
    script_.load(name, config, "nrp_core.engines.python_grpc", "GrpcEngineScript");
    py::object& script = script_.script();
    script.attr("_check_type") = py::cpp_function(
        [this](const std::string& datapack, py::handle type) { check_type(datapack, type); });
    return script_.initialize([&] {
      datapacks_ = script.attr("_datapacks");
      types_ = script.attr("_datapack_types");
      std::vector<engine::DataPackId> ids;
      for (auto item : py::dict(types_)) {
        engine::DataPackId id;
        id.set_name(py::str(item.first));
        id.set_engine_name(name);
        std::string type = item.second.attr("DESCRIPTOR").attr("full_name").cast<std::string>();
        std::string_view standard = datapack::standard_type_of(type);
        id.set_type(standard.empty() ? type : std::string(standard));
        ids.push_back(id);
      }
      return ids;
    });
  }

  int64_t step(int64_t duration_ns) override { return script_.step(duration_ns); }

  // A datapack from a transceiver function replaces the engine's message by a new one of the
  // registered class.
  void set_datapack(const datapack::View& dp) override {
    py::str key(dp.id().name());
    PyObject* cls = PyDict_GetItem(types_.ptr(), key.ptr());
    if (!cls) {
      throw std::runtime_error("a transceiver function sent datapack '" + dp.id().name() +
                               "', which engine '" + name_ + "' has not registered");
    }
    try {
      py::object msg = dp.empty() ? py::reinterpret_borrow<py::object>(cls)()
                                  : python::message_from_datapack(dp, cls);
      datapacks_[key] = msg;
    } catch (py::error_already_set& e) {
      throw std::runtime_error("cannot decode datapack '" + dp.id().name() + "': " + e.what());
    }
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    py::str key(id.name());
    PyObject* msg = PyDict_GetItem(datapacks_.ptr(), key.ptr());
    if (!msg || msg == Py_None) return;  // unknown id: empty datapack
    try {
      python::message_to_datapack(msg, out);
    } catch (py::error_already_set& e) {
      throw std::runtime_error("datapack '" + id.name() + "': " + e.what());
    } catch (const std::exception& e) {
      throw std::runtime_error("datapack '" + id.name() + "': " + e.what());
    }
  }

  void reset() override {
    script_.call("reset");
    script_.script().attr("_time_ns") = 0;
  }

  void shutdown() override {
    if (script_.loaded()) script_.call("shutdown");
  }

 private:
  void read_packages(const nlohmann::json& config) {
    // NRP-Core's default (its EngineGRPC schema).
    std::vector<std::string> packages = {"EngineTest"};
    if (auto it = config.find("ProtobufPackages"); it != config.end() && it->is_array()) {
      packages.clear();
      for (const auto& p : *it) packages.push_back(p.get<std::string>());
    }
    for (const auto& p : packages) {
      if (!datapack::nrp_package_file(p)) {
        throw std::runtime_error("ProtobufPackages: unknown package '" + p + "' (Convoy has " +
                                 join(datapack::nrp_packages()) + ")");
      }
      packages_.insert(p);
    }
  }

  // _registerDataPack's check: a type Convoy can carry (compiled in). A type of a package
  // the config does not list gets a warning, once per package.
  void check_type(const std::string& datapack, py::handle type) {
    const std::string full = type.attr("DESCRIPTOR").attr("full_name").cast<std::string>();
    const datapack::TypeInfo* t = nullptr;
    try {
      t = &datapack::Registry::global().add_by_name(full);
    } catch (const std::invalid_argument&) {
      throw py::type_error("engine '" + name_ + "': _registerDataPack('" + datapack + "', " + full +
                           "): protobuf type " + full +
                           " is not compiled into Convoy (NRP-Core's packages " +
                           join(datapack::nrp_packages()) + ")");
    }
    const std::string& package = t->descriptor->file()->package();
    if (datapack::nrp_package_file(package) && !packages_.count(package) &&
        warned_.insert(package).second) {
      std::fprintf(stderr,
                   "warning: engine '%s': datapack '%s' has type %s, but ProtobufPackages does "
                   "not list package '%s' (NRP-Core would not carry it; Convoy does)\n",
                   name_.c_str(), datapack.c_str(), full.c_str(), package.c_str());
    }
  }

  std::string name_;
  std::set<std::string> packages_, warned_;
  python::EngineScript script_;   // first: its interpreter outlives the objects below
  py::object datapacks_, types_;  // the script's dicts (name -> message / class)
};

}  // namespace

CONVOY_REGISTER_ENGINE("python_grpc", PythonGrpcEngine);

}  // namespace convoy::engines
