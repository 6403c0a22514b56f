// python_json: runs a user's EngineScript (NRP-Core's Python JSON engine).
//
// Config keys: PythonFileName (the script; its class `Script`, or its only EngineScript
// subclass, is instantiated). Datapacks: whatever the script registers with
// _registerDataPack; their data are JSON values (numpy arrays allowed).
#pragma once

#include "engine/engine.h"
#include "python/datapack_convert.h"
#include "python/engine_script.h"

namespace convoy::engines {

namespace py = pybind11;

// Also the base of engines that run a shipped script (engines/scenario).
class PythonJsonEngine : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    script_.load(name, config, "nrp_core.engines.python_json", "EngineScript");
    return script_.initialize([&] {
      std::vector<engine::DataPackId> ids;
      for (auto item : py::dict(script_.script().attr("_datapacks"))) {
        engine::DataPackId id;
        id.set_name(py::str(item.first));
        id.set_engine_name(name);
        id.set_type("json");
        ids.push_back(id);
      }
      return ids;
    });
  }

  int64_t step(int64_t duration_ns) override { return script_.step(duration_ns); }

  void set_datapack(const datapack::View& dp) override {
    py::dict datapacks = script_.script().attr("_datapacks");
    py::str key(dp.id().name());
    if (!datapacks.contains(key)) {
      throw std::runtime_error("a transceiver function sent datapack '" + dp.id().name() +
                               "', which engine '" + name_ + "' has not registered");
    }
    try {
      // Copies of images: the engine keeps its datapacks across steps.
      datapacks[key] = python::data_to_python(dp, python::ImageAccess::kCopy);
    } catch (py::error_already_set& e) {
      throw std::runtime_error("cannot decode datapack '" + dp.id().name() + "': " + e.what());
    }
  }

  void get_datapack(const engine::DataPackId& id, datapack::Builder& out) override {
    py::dict datapacks = script_.script().attr("_datapacks");
    py::str key(id.name());
    if (!datapacks.contains(key)) return;  // unknown id: empty datapack
    py::object data = datapacks[key];
    // A datapack object (e.g. a GazeboCameraDataPack) sends its data. (Dicts, the common
    // case, skip the attribute probes, which cost an exception each.)
    if (!PyDict_Check(data.ptr()) && py::hasattr(data, "_id") && py::hasattr(data, "_data"))
      data = data.attr("_data");
    python::data_from_python(data, out);
  }

  // As NRP-Core's python_json server: the script's reset(), then its clock back to 0.
  void reset() override {
    script_.call("reset");
    script_.script().attr("_time_ns") = 0;
  }

  void shutdown() override {
    if (script_.loaded()) script_.call("shutdown");
  }

 protected:
  std::string name_;
  python::EngineScript script_;
};

}  // namespace convoy::engines
