#include "python/interpreter.h"

#include <cstdlib>

#include "python/msgpack_codec.h"

namespace convoy::python {

std::filesystem::path package_dir() {
  if (const char* p = std::getenv("CONVOY_PYTHON_PATH"); p && *p) return p;
  return CONVOY_PYTHON_DIR;
}

Interpreter::Interpreter() {
  // Engines and TFs print progress; flush it line by line into the logs.
  setenv("PYTHONUNBUFFERED", "1", 0);
  // Nested in one that is already up (convoy run --scenario keeps one from making the config
  // to the end of the run): this one only adds the paths.
  if (!Py_IsInitialized()) guard_ = std::make_unique<py::scoped_interpreter>(false);
  // NRP-Core's generated protobuf modules (nrp_protobuf.dump_pb2...), made by the build.
  add_path(CONVOY_PYTHON_GEN_DIR);
  add_path(package_dir());
}

Interpreter::~Interpreter() = default;

void Interpreter::add_path(const std::filesystem::path& dir) { add_python_path(dir); }

void add_python_path(const std::filesystem::path& dir) {
  py::list path = py::module_::import("sys").attr("path");
  py::str entry(dir.string());
  if (!path.contains(entry)) path.insert(0, entry);
}

void set_environment(const std::string& name, const std::string& value, bool overwrite) {
  setenv(name.c_str(), value.c_str(), overwrite ? 1 : 0);
  if (!Py_IsInitialized()) return;
  py::object environ = py::module_::import("os").attr("environ");
  if (overwrite || !environ.contains(name))
    environ[py::str(name)] = py::str(std::getenv(name.c_str()));
}

std::string format_exception(py::error_already_set& e) {
  try {
    py::module_ tb = py::module_::import("traceback");
    py::list lines = tb.attr("format_exception")(e.type(), e.value(), e.trace());
    std::string out;
    for (auto& l : lines) {
      std::string line = l.cast<std::string>();
      // Frames of Python's import machinery say nothing about the user's code.
      if (line.rfind("  File \"<frozen importlib", 0) == 0) continue;
      out += line;
    }
    while (!out.empty() && out.back() == '\n') out.pop_back();
    return out;
  } catch (...) {
    return e.what();
  }
}

py::module_ load_module_from_file(const std::filesystem::path& file) {
  py::module_ util = py::module_::import("importlib.util");
  std::string name = file.stem().string();
  py::object spec = util.attr("spec_from_file_location")(name, file.string());
  if (spec.is_none()) throw std::runtime_error("cannot load Python file " + file.string());
  py::object module = util.attr("module_from_spec")(spec);
  py::module_::import("sys").attr("modules")[py::str(name)] = module;
  spec.attr("loader").attr("exec_module")(module);
  return module.cast<py::module_>();
}

}  // namespace convoy::python
