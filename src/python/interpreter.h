// The embedded CPython (Debian's python3) shared by the coordinator and Python engines.
#pragma once

#include <pybind11/embed.h>

#include <filesystem>
#include <memory>
#include <string>

namespace convoy::python {

namespace py = pybind11;

// Starts the interpreter with Convoy's nrp_core package importable; stops it on destruction.
// Within one already running (in this thread), it only makes the package importable.
class Interpreter {
 public:
  Interpreter();
  ~Interpreter();
  Interpreter(const Interpreter&) = delete;
  Interpreter& operator=(const Interpreter&) = delete;

  // Puts `dir` at the front of sys.path (once).
  void add_path(const std::filesystem::path& dir);

 private:
  std::unique_ptr<py::scoped_interpreter> guard_;
};

// Puts `dir` at the front of sys.path (once). Needs the GIL.
void add_python_path(const std::filesystem::path& dir);

// Directory holding the nrp_core package: $CONVOY_PYTHON_PATH, else the build's.
std::filesystem::path package_dir();

// setenv, and os.environ too when the interpreter is up (it copied the environment when it
// started). Needs the GIL when it is up.
void set_environment(const std::string& name, const std::string& value, bool overwrite);

// The pending Python exception as "Traceback ...\nType: message"; clears it.
std::string format_exception(py::error_already_set& e);

// Executes the file as a fresh module named after its stem and returns the module.
py::module_ load_module_from_file(const std::filesystem::path& file);

}  // namespace convoy::python
