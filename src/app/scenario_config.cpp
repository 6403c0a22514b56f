#include "app/scenario_config.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>

#include "python/interpreter.h"

namespace convoy::app {

namespace fs = std::filesystem;
namespace py = pybind11;

namespace {

// The run folder of a scenario run: the one given, else a new one under ./runs.
bool make_run_dir(const std::string& scenario, RunOptions& options) {
  std::error_code ec;
  if (options.run_dir.empty()) {
    fs::path base = fs::current_path() / "runs";
    if (const char* b = std::getenv("CONVOY_RUNS_DIR"); b && *b) base = b;
    char stamp[32];
    std::time_t t = std::time(nullptr);
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&t));
    options.run_dir = base / ("scenario_" + fs::path(scenario).stem().string() + "-" + stamp + "-" +
                              std::to_string(getpid()));
  }
  fs::create_directories(options.run_dir, ec);
  if (ec) {
    std::fprintf(stderr, "error: cannot create the run folder %s: %s\n", options.run_dir.c_str(),
                 ec.message().c_str());
    return false;
  }
  options.run_dir = fs::absolute(options.run_dir);
  return true;
}

// make_config.main(args) in the embedded interpreter: its exit code (it prints its errors).
int run_make_config(const std::vector<std::string>& args) {
  try {
    py::list argv;
    for (const auto& a : args) argv.append(a);
    py::module_ mc = py::module_::import("convoy_scenario.make_config");
    py::object rc = mc.attr("main")(argv);
    std::fflush(stdout);
    py::module_::import("sys").attr("stdout").attr("flush")();
    py::module_::import("sys").attr("stderr").attr("flush")();
    return rc.is_none() ? 0 : rc.cast<int>();
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_SystemExit)) {  // argparse's exit: it has said why
      py::object code = e.value().attr("code");
      return code.is_none() ? 0 : (py::isinstance<py::int_>(code) ? code.cast<int>() : 2);
    }
    std::fprintf(stderr, "error: make_config: %s\n", python::format_exception(e).c_str());
    return 2;
  }
}

}  // namespace

bool prepare_scenario(const ScenarioRequest& r, RunOptions& options) {
  std::error_code ec;
  if (!fs::is_regular_file(r.scenario, ec)) {
    std::fprintf(stderr, "error: --scenario %s: no such file\n", r.scenario.c_str());
    return false;
  }
  if (!make_run_dir(r.scenario, options)) return false;
  const fs::path config = options.run_dir / "scenario_config.json";
  std::vector<std::string> args = {fs::absolute(r.scenario).string(), "--out", config.string(),
                                   "--bin-dir", bin_dir().string()};
  if (!r.world.empty()) args.insert(args.end(), {"--world", fs::absolute(r.world).string()});
  if (!r.ego.empty())
    args.insert(args.end(), {"--ego", r.ego == "scenario" ? r.ego : fs::absolute(r.ego).string()});
  if (!r.scenery.empty()) args.insert(args.end(), {"--scenery", r.scenery});
  for (const auto& p : r.params) args.insert(args.end(), {"--param", p});
  if (!r.perception.empty()) args.insert(args.end(), {"--perception", r.perception});
  if (run_make_config(args) != 0) {
    std::fprintf(stderr, "error: --scenario %s: no config could be made (run folder %s)\n",
                 r.scenario.c_str(), options.run_dir.c_str());
    return false;
  }
  options.config_file = config;
  return true;
}

}  // namespace convoy::app
