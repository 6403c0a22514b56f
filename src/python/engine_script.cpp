#include "python/engine_script.h"

#include <stdexcept>

namespace convoy::python {
namespace {

namespace py = pybind11;

// The script's class: `Script`, or the only subclass of `base` in the module.
py::object find_script_class(py::module_& module, const py::object& base, const char* base_name,
                             const std::filesystem::path& file) {
  if (py::hasattr(module, "Script")) return module.attr("Script");
  py::object found;
  py::object issubclass = py::module_::import("builtins").attr("issubclass");
  py::object isclass = py::module_::import("inspect").attr("isclass");
  for (auto item : py::dict(module.attr("__dict__"))) {
    py::handle v = item.second;
    if (isclass(v).cast<bool>() && !v.is(base) && issubclass(v, base).cast<bool>()) {
      if (found) {
        throw std::runtime_error(file.string() + ": several " + base_name +
                                 " classes; name one Script");
      }
      found = py::reinterpret_borrow<py::object>(v);
    }
  }
  if (!found)
    throw std::runtime_error(file.string() + ": no class Script(" + base_name + ") found");
  return found;
}

}  // namespace

void EngineScript::load(const std::string& engine_name, const nlohmann::json& config,
                        const char* base_module, const char* base_class) {
  interpreter_.emplace();
  file_ = config.value("PythonFileName", "");
  if (file_.empty()) throw std::runtime_error("PythonFileName is not set");
  interpreter_->add_path(file_.parent_path());
  try {
    py::module_ module = load_module_from_file(file_);
    py::object base = py::module_::import(base_module).attr(base_class);
    script_ = find_script_class(module, base, base_class, file_)();
    script_.attr("_name") = engine_name;
    script_.attr("_config") = py::module_::import("json").attr("loads")(config.dump());
    run_loop_ = script_.attr("runLoop");
    advance_ = script_.attr("_advanceTime");
  } catch (py::error_already_set& e) {
    throw_in("initialize", e);
  }
}

int64_t EngineScript::step(int64_t duration_ns) {
  try {
    advance_(duration_ns);
    run_loop_(duration_ns);
    return script_.attr("_time_ns").cast<int64_t>();
  } catch (py::error_already_set& e) {
    throw std::runtime_error("Python error in runLoop:\n" + format_exception(e));
  }
}

void EngineScript::call(const char* method) {
  try {
    script_.attr(method)();
  } catch (py::error_already_set& e) {
    throw std::runtime_error(std::string("Python error in ") + method + ":\n" +
                             format_exception(e));
  }
}

void EngineScript::throw_in(const char* phase, py::error_already_set& e) {
  throw std::runtime_error("Python error in " + file_.filename().string() + " during " + phase +
                           ":\n" + format_exception(e));
}

}  // namespace convoy::python
