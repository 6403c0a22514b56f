// scenario: executes an OpenSCENARIO storyboard in lock-step (docs/scenarios.md, "The scenario
// engine"). It is the python_json engine running the shipped script
// python/convoy_scenario/engine.py on the config's keys (schema.json); a ScenarioError ends
// the run with its one-line message (file, element, line) instead of a Python traceback.
#include <filesystem>
#include <string>

#include "../python_json/python_json_engine.h"
#include "python/interpreter.h"

namespace convoy::engines {
namespace {

// The message of a convoy_scenario ScenarioError (or ScenarioRuntimeError) in a formatted
// Python error, or "" when it is another error.
std::string scenario_message(const std::string& what) {
  for (const std::string tag : {"ScenarioRuntimeError: ", "ScenarioError: "}) {
    size_t at = what.rfind(tag);
    if (at == std::string::npos) continue;
    std::string msg = what.substr(at + tag.size());
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    return msg;
  }
  return "";
}

class ScenarioEngine final : public PythonJsonEngine {
 public:
  std::vector<engine::DataPackId> initialize(const std::string& name, const nlohmann::json& config,
                                             int64_t timestep_ns) override {
    nlohmann::json c = config;
    c["PythonFileName"] = (python::package_dir() / "convoy_scenario" / "engine_script.py").string();
    try {
      return PythonJsonEngine::initialize(name, c, timestep_ns);
    } catch (const std::runtime_error& e) {
      rethrow(e);
    }
  }

  int64_t step(int64_t duration_ns) override {
    try {
      return PythonJsonEngine::step(duration_ns);
    } catch (const std::runtime_error& e) {
      rethrow(e);
    }
  }

 private:
  [[noreturn]] static void rethrow(const std::runtime_error& e) {
    std::string msg = scenario_message(e.what());
    if (msg.empty()) throw;
    throw std::runtime_error(msg);
  }
};

CONVOY_REGISTER_ENGINE("scenario", ScenarioEngine);

}  // namespace
}  // namespace convoy::engines
