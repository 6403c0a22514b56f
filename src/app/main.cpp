// convoy: the coordinator's command line. Also installed as NRPCoreSim, which behaves like
// `convoy run` and takes NRP-Core's options.
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include "app/simulation.h"
#include "core/memory.h"

namespace {

void usage(const char* prog) {
  std::printf(
      "usage: %s run -c simulation_config.json [-o Key=Value]... [--run-dir DIR] [--quiet]\n"
      "       NRPCoreSim -c simulation_config.json [-o Key=Value]...\n"
      "\n"
      "  -c, --config FILE   the simulation config (NRP-Core format)\n"
      "  -o, --param K=V     override a config key; K may be a path like "
      "EngineConfigs/0/EngineTimestep\n"
      "  --run-dir DIR       where to write logs, steps.csv and summary.json\n"
      "                      (default: ./runs/<SimulationName>-<time>-<pid>, or under "
      "$CONVOY_RUNS_DIR)\n"
      "  -q, --quiet         only errors on the terminal\n",
      prog);
}

}  // namespace

int main(int argc, char** argv) {
  convoy::tune_allocator_for_frames();
  std::string prog = std::filesystem::path(argv[0]).filename().string();
  int i = 1;
  if (prog != "NRPCoreSim") {
    if (argc < 2 || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "--help")) {
      usage(prog.c_str());
      return argc < 2 ? 2 : 0;
    }
    if (std::strcmp(argv[1], "run") != 0) {
      std::fprintf(stderr, "error: unknown command '%s'\n", argv[1]);
      usage(prog.c_str());
      return 2;
    }
    i = 2;
  }
  convoy::app::RunOptions options;
  for (; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "error: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "-c" || a == "--config")
      options.config_file = value();
    else if (a == "-o" || a == "--param")
      options.overrides.push_back(value());
    else if (a == "--run-dir")
      options.run_dir = value();
    else if (a == "-q" || a == "--quiet")
      options.quiet = true;
    else if (a == "-h" || a == "--help") {
      usage(prog.c_str());
      return 0;
    } else {
      std::fprintf(stderr, "error: unknown option '%s'\n", a.c_str());
      usage(prog.c_str());
      return 2;
    }
  }
  if (options.config_file.empty()) {
    std::fprintf(stderr, "error: no config given (-c simulation_config.json)\n");
    return 2;
  }
  return convoy::app::run_simulation(options);
}
