// A user's engine script, as NRP-Core's Python engines run it: the python_json engine's
// EngineScript and the python_grpc engine's GrpcEngineScript share this part (the
// interpreter, loading the file, finding the class, stepping, calling methods), and keep
// their datapacks to themselves.
#pragma once

#include <pybind11/pybind11.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "python/interpreter.h"

namespace convoy::python {

class EngineScript {
 public:
  // Starts the interpreter and loads the config's PythonFileName: its class `Script`, or its
  // only subclass of `base_module`.`base_class`, is instantiated with `_name` and `_config`
  // set. The script's `initialize()` is not called yet (see initialize()). Throws
  // std::runtime_error naming the file.
  void load(const std::string& engine_name, const nlohmann::json& config, const char* base_module,
            const char* base_class);

  // Calls the script's initialize(), then `after` (which reads what the script registered).
  // A Python error in either is a std::runtime_error naming the file.
  template <typename F>
  auto initialize(F&& after) {
    try {
      script_.attr("initialize")();
      return after();
    } catch (pybind11::error_already_set& e) {
      throw_in("initialize", e);
    }
  }

  // _advanceTime(duration), runLoop(duration); returns the script's _time_ns.
  int64_t step(int64_t duration_ns);
  // Calls a method without arguments (reset, shutdown), naming it in errors.
  void call(const char* method);
  bool loaded() const { return static_cast<bool>(script_); }
  pybind11::object& script() { return script_; }

 private:
  [[noreturn]] void throw_in(const char* phase, pybind11::error_already_set& e);

  std::optional<Interpreter> interpreter_;  // first: destroyed after the objects below
  std::filesystem::path file_;
  pybind11::object script_, run_loop_, advance_;
};

}  // namespace convoy::python
