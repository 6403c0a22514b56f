// python_json: runs a user's EngineScript (NRP-Core's Python JSON engine).
//
// Config keys: PythonFileName (the script; its class `Script`, or its only EngineScript
// subclass, is instantiated). Datapacks: whatever the script registers with
// _registerDataPack; their data are JSON values (numpy arrays allowed).
#include <optional>

#include "engine/engine.h"
#include "python/datapack_convert.h"
#include "python/interpreter.h"

namespace convoy::engines {
namespace {

namespace py = pybind11;

class PythonJsonEngine final : public Engine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    name_ = name;
    interpreter_.emplace();
    std::filesystem::path file = config.value("PythonFileName", "");
    if (file.empty()) throw std::runtime_error("PythonFileName is not set");
    interpreter_->add_path(file.parent_path());
    try {
      py::module_ module = python::load_module_from_file(file);
      py::object base = py::module_::import("nrp_core.engines.python_json").attr("EngineScript");
      py::object cls = find_script_class(module, base, file);
      script_ = cls();
      script_.attr("_name") = name;
      script_.attr("_config") = py::module_::import("json").attr("loads")(config.dump());
      script_.attr("initialize")();
      run_loop_ = script_.attr("runLoop");
      advance_ = script_.attr("_advanceTime");
      std::vector<engine::DataPackId> ids;
      for (auto item : py::dict(script_.attr("_datapacks"))) {
        engine::DataPackId id;
        id.set_name(py::str(item.first));
        id.set_engine_name(name);
        id.set_type("json");
        ids.push_back(id);
      }
      return ids;
    } catch (py::error_already_set& e) {
      throw std::runtime_error("Python error in " + file.filename().string() +
                               " during initialize:\n" + python::format_exception(e));
    }
  }

  int64_t step(int64_t duration_ns) override {
    try {
      advance_(duration_ns);
      run_loop_(duration_ns);
      return script_.attr("_time_ns").cast<int64_t>();
    } catch (py::error_already_set& e) {
      throw std::runtime_error("Python error in runLoop:\n" + python::format_exception(e));
    }
  }

  void set_datapack(const datapack::View& dp) override {
    py::dict datapacks = script_.attr("_datapacks");
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
    py::dict datapacks = script_.attr("_datapacks");
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
    call("reset");
    script_.attr("_time_ns") = 0;
  }

  void shutdown() override {
    if (script_) call("shutdown");
  }

 private:
  void call(const char* method) {
    try {
      script_.attr(method)();
    } catch (py::error_already_set& e) {
      throw std::runtime_error(std::string("Python error in ") + method + ":\n" +
                               python::format_exception(e));
    }
  }

  static py::object find_script_class(py::module_& module, py::object& base,
                                      const std::filesystem::path& file) {
    if (py::hasattr(module, "Script")) return module.attr("Script");
    py::object found;
    py::object issubclass = py::module_::import("builtins").attr("issubclass");
    py::object isclass = py::module_::import("inspect").attr("isclass");
    for (auto item : py::dict(module.attr("__dict__"))) {
      py::handle v = item.second;
      if (isclass(v).cast<bool>() && !v.is(base) && issubclass(v, base).cast<bool>()) {
        if (found)
          throw std::runtime_error(file.string() +
                                   ": several EngineScript classes; name one Script");
        found = py::reinterpret_borrow<py::object>(v);
      }
    }
    if (!found) throw std::runtime_error(file.string() + ": no class Script(EngineScript) found");
    return found;
  }

  std::string name_;
  std::optional<python::Interpreter> interpreter_;
  py::object script_, run_loop_, advance_;
};

}  // namespace

CONVOY_REGISTER_ENGINE("python_json", PythonJsonEngine);

}  // namespace convoy::engines
