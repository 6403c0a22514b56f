// convoy: the coordinator's command line. Also installed as NRPCoreSim, which behaves like
// `convoy run` and takes NRP-Core's options.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/scenario_config.h"
#include "app/simulation.h"
#include "app/view.h"
#include "core/memory.h"
#include "live/address.h"
#include "python/interpreter.h"

namespace {

void usage(const char* prog) {
  std::printf(
      "usage: %s run -c simulation_config.json [-o Key=Value]... [--run-dir DIR] [--quiet]\n"
      "                  [--record] [--record-blobs] [--live [HOST:]PORT [--insecure]]\n"
      "       %s run --scenario FILE.xosc [--world WORLD.sdf] [--scenery KIND] [--ego "
      "FRAGMENT.json|scenario]\n"
      "                [--scenario-param NAME=VALUE]... [--perception KIND] [-o Key=Value]...\n"
      "                [--run-dir DIR]\n"
      "                [--quiet] [--record]\n"
      "       %s replay RUN_DIR [--out DIR] [-c CONFIG] [-o Key=Value]... [--quiet]\n"
      "       %s score RUN_DIR [--out DIR] [-c CONFIG] [-o Key=Value]... [--quiet]\n"
      "       %s campaign SUITE_DIR [--seeds N] [--workers N] [--backend local|slurm] [--out DIR]\n"
      "                [...]  (tools/campaign/campaign.py; --help for its options)\n"
      "       %s view PATH [--port P] [--host H [--insecure]]\n"
      "       NRPCoreSim -c simulation_config.json [-o Key=Value]...\n"
      "\n"
      "  --record            record every datapack that crosses the coordinator into\n"
      "                      RUN_DIR/recording.mcap (MCAP; docs/recording.md)\n"
      "  --record-blobs      --record, with the blobs (camera frames) too\n"
      "  --live [HOST:]PORT  serve the run live to Foxglove or Lichtblick (Foxglove WebSocket\n"
      "                      protocol at ws://HOST:PORT; HOST 127.0.0.1 by default; loopback\n"
      "                      addresses only, unless --insecure); every datapack a channel,\n"
      "                      the camera as JPEG, the log (docs/architecture.md, \"Live server\")\n"
      "  --live-camera-hz HZ with --live: JPEG camera frames per simulated second (default 10)\n"
      "  --live-scene-hz HZ  with --live: /convoy/scene updates per simulated second (default 10)\n"
      "  --insecure          with --live or --server_address: listen beyond the loopback too\n"
      "                      (there is no TLS or token: anyone who reaches it sees the run)\n"
      "  replay RUN_DIR      re-run the functions on the recording (no engines); exit 0 when\n"
      "                      they send what they sent live, 5 when not (RUN_DIR/replay/)\n"
      "  view PATH           serve the web dashboard and the files under PATH (a run folder, a\n"
      "                      campaign folder, a .mcap file) at http://127.0.0.1:8765 (--port,\n"
      "                      --host) until Ctrl-C; prints the URL to open\n"
      "  score RUN_DIR       replay into RUN_DIR/rescore/ and compare the fields the functions\n"
      "                      wrote (driving_score...) with the live ones; exit 5 if one differs\n"
      "\n"
      "  -c, --config FILE   the simulation config (NRP-Core format)\n"
      "  --scenario FILE     run an OpenSCENARIO file with a default config (written into the\n"
      "                      run folder as scenario_config.json; docs/scenarios.md)\n"
      "  --world FILE        with --scenario: the world SDF (without the ego); by default the\n"
      "                      map's shipped world, else one generated from the map and cached\n"
      "                      (convoy-odr world; docs/worlds.md)\n"
      "  --scenery KIND      with --scenario: a generated world's scenery: auto (default:\n"
      "                      urban where the map has sidewalks, else roadside), none,\n"
      "                      roadside or urban\n"
      "  --ego FILE          with --scenario: a config fragment with the user's ego engines\n"
      "  --scenario-param NAME=VALUE  with --scenario: a value of one of the scenario's\n"
      "                      global parameters (repeatable)\n"
      "  --perception KIND   with --scenario: the default ego's perception: ground_truth\n"
      "                      (default) or sensors (detector boxes ranged by a roof LiDAR)\n"
      "  --ego scenario      with --scenario: the scenario moves the ego too, exactly as its\n"
      "                      actions say (as esmini does; no camera, no stack under test)\n"
      "  -o, --param K=V     override a config key; K may be a path like "
      "EngineConfigs/0/EngineTimestep\n"
      "  --run-dir DIR       where to write logs, steps.csv and summary.json\n"
      "                      (default: ./runs/<SimulationName>-<time>-<pid>, or under "
      "$CONVOY_RUNS_DIR)\n"
      "  -q, --quiet         only errors on the terminal\n"
      "  -d, --dir FOLDER    the experiment folder: work there, -c is relative to it\n"
      "  -m, --mode MODE     standalone (default) or server: serve the simulation to a\n"
      "                      Python client (python/nrp_client) at --server_address\n"
      "  --server_address HOST:PORT   where the server listens (loopback addresses only,\n"
      "                      unless --insecure)\n"
      "  --local_socket PATH with -m server: the same calls at a Unix socket too, for a\n"
      "                      client on this machine (framed protobuf; src/transport/local_rpc.h)\n"
      "  --slave             started by a client: ignore Ctrl-C, end when the client ends\n"
      "  --logoutput all|engines|silent   all: this program's output into --logfilename;\n"
      "                      silent: none; engines: (engines log into the run folder anyway)\n"
      "  --logfilename FILE  default .console_output.log\n",
      prog, prog, prog, prog, prog, prog);
}

// The value of the option at argv[*i] (the next argument; *i moves to it); none: exit 2.
std::string next_value(int argc, char** argv, int* i) {
  if (*i + 1 >= argc) {
    std::fprintf(stderr, "error: %s needs a value\n", argv[*i]);
    std::exit(2);
  }
  return argv[++*i];
}

// convoy replay|score RUN_DIR [--out DIR] [-c CONFIG] [-o K=V]... [-q]
int replay_command(const char* prog, bool score, int argc, char** argv) {
  convoy::app::ReplayOptions options;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&] { return next_value(argc, argv, &i); };
    if (a == "--out")
      options.out_dir = value();
    else if (a == "-c" || a == "--config")
      options.config_file = value();
    else if (a == "-o" || a == "--param")
      options.overrides.push_back(value());
    else if (a == "-q" || a == "--quiet")
      options.quiet = true;
    else if (a == "-h" || a == "--help") {
      usage(prog);
      return 0;
    } else if (!a.empty() && a[0] != '-' && options.run_dir.empty())
      options.run_dir = a;
    else {
      std::fprintf(stderr, "error: unknown option '%s'\n", a.c_str());
      usage(prog);
      return 2;
    }
  }
  if (options.run_dir.empty()) {
    std::fprintf(stderr, "error: %s needs a run folder (RUN_DIR)\n", argv[1]);
    return 2;
  }
  return score ? convoy::app::score_run(options) : convoy::app::replay_run(options);
}

// convoy view PATH [--port P] [--host H] [--insecure]
int view_command(const char* prog, int argc, char** argv) {
  convoy::app::ViewOptions options;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    auto value = [&] { return next_value(argc, argv, &i); };
    if (a == "--port") {
      const std::string v = value();
      char* end = nullptr;
      const long port = std::strtol(v.c_str(), &end, 10);
      if (v.empty() || *end || port < 0 || port > 65535) {
        std::fprintf(stderr, "error: --port must be a number from 0 to 65535, got '%s'\n",
                     v.c_str());
        return 2;
      }
      options.port = static_cast<uint16_t>(port);
    } else if (a == "--host") {
      options.host = value();
    } else if (a == "--insecure") {
      options.insecure = true;
    } else if (a == "-h" || a == "--help") {
      usage(prog);
      return 0;
    } else if (!a.empty() && a[0] != '-' && options.path.empty()) {
      options.path = a;
    } else {
      std::fprintf(stderr, "error: unknown option '%s'\n", a.c_str());
      usage(prog);
      return 2;
    }
  }
  if (options.path.empty()) {
    std::fprintf(stderr, "error: view needs a run folder, campaign folder or .mcap file (PATH)\n");
    return 2;
  }
  return convoy::app::view_files(options);
}

// NRP-Core's --logoutput: `all` sends this program's stdout and stderr to `file`, `silent` to
// /dev/null. Returns false (after saying why) when that is impossible.
bool redirect_output(const std::string& mode, const std::string& file) {
  if (mode == "engines") return true;  // each engine logs into the run folder
  if (mode != "all" && mode != "silent") {
    std::fprintf(stderr, "error: --logoutput must be all, engines or silent, got '%s'\n",
                 mode.c_str());
    return false;
  }
  const std::string target = mode == "silent" ? "/dev/null" : file;
  int fd = open(target.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    std::fprintf(stderr, "error: --logfilename %s: %s\n", target.c_str(), std::strerror(errno));
    return false;
  }
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(fd, STDOUT_FILENO);
  dup2(fd, STDERR_FILENO);
  close(fd);
  return true;
}

std::string python_exe() {
  if (const char* p = std::getenv("CONVOY_PYTHON"); p && *p) return p;
  return "/usr/bin/python3";
}

// `convoy campaign ...`: tools/campaign/campaign.py's command line, with this build.
int campaign(int argc, char** argv) {
  const auto repo = convoy::python::package_dir().parent_path();
  std::vector<std::string> args = {python_exe(),
                                   (repo / "tools" / "campaign" / "campaign.py").string()};
  bool has_build = false;
  for (int i = 2; i < argc; ++i) {
    args.push_back(argv[i]);
    if (std::strcmp(argv[i], "--build") == 0 || std::strncmp(argv[i], "--build=", 8) == 0)
      has_build = true;
  }
  if (!has_build) setenv("CONVOY_BIN_DIR", convoy::app::bin_dir().c_str(), 0);
  // The campaign replaces this process, so that a signal to `convoy campaign` (Ctrl-C,
  // SIGTERM, SIGKILL) reaches the campaign itself.
  std::vector<char*> argv_exec;
  for (auto& a : args) argv_exec.push_back(a.data());
  argv_exec.push_back(nullptr);
  std::fflush(nullptr);
  execv(args[0].c_str(), argv_exec.data());
  std::fprintf(stderr, "error: cannot run %s %s: %s\n", args[0].c_str(), args[1].c_str(),
               std::strerror(errno));
  return 2;
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
    if (!std::strcmp(argv[1], "replay") || !std::strcmp(argv[1], "score"))
      return replay_command(prog.c_str(), !std::strcmp(argv[1], "score"), argc, argv);
    if (std::strcmp(argv[1], "campaign") == 0) return campaign(argc, argv);
    if (std::strcmp(argv[1], "view") == 0) return view_command(prog.c_str(), argc, argv);
    if (std::strcmp(argv[1], "run") != 0) {
      std::fprintf(stderr, "error: unknown command '%s'\n", argv[1]);
      usage(prog.c_str());
      return 2;
    }
    i = 2;
  }
  convoy::app::RunOptions options;
  std::string mode = "standalone", dir, log_output, log_filename = ".console_output.log";
  std::string scenario, world, ego, scenery, perception;
  std::vector<std::string> scenario_params;
  std::optional<convoy::python::Interpreter> scenario_python;
  for (; i < argc; ++i) {
    std::string a = argv[i];
    std::string inline_value;  // --key=value
    bool has_inline = false;
    if (a.rfind("--", 0) == 0) {
      if (size_t eq = a.find('='); eq != std::string::npos) {
        inline_value = a.substr(eq + 1);
        a = a.substr(0, eq);
        has_inline = true;
      }
    }
    auto value = [&]() -> std::string {
      return has_inline ? inline_value : next_value(argc, argv, &i);
    };
    if (a == "-c" || a == "--config")
      options.config_file = value();
    else if (a == "-o" || a == "--param")
      options.overrides.push_back(value());
    else if (a == "--run-dir")
      options.run_dir = value();
    else if (a == "--scenario")
      scenario = value();
    else if (a == "--world")
      world = value();
    else if (a == "--ego")
      ego = value();
    else if (a == "--scenery")
      scenery = value();
    else if (a == "--scenario-param")
      scenario_params.push_back(value());
    else if (a == "--perception")
      perception = value();
    else if (a == "-q" || a == "--quiet")
      options.quiet = true;
    else if (a == "--record")
      options.overrides.push_back("Record=true");
    else if (a == "--record-blobs")
      options.overrides.push_back("RecordBlobs=true");
    else if (a == "-d" || a == "--dir")
      dir = value();
    else if (a == "-m" || a == "--mode")
      mode = value();
    else if (a == "--server_address")
      options.server_address = value();
    else if (a == "--slave")
      options.slave = true;
    else if (a == "--insecure")
      options.insecure = true;
    else if (a == "--local_socket")
      options.local_socket = value();
    else if (a == "--live")
      options.live = value();
    else if (a == "--live-camera-hz") {
      const std::string v = value();
      char* end = nullptr;
      options.live_camera_hz = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !(options.live_camera_hz >= 0) || options.live_camera_hz > 1e6) {
        std::fprintf(stderr, "error: --live-camera-hz must be a number >= 0, got '%s'\n",
                     v.c_str());
        return 2;
      }
    } else if (a == "--live-scene-hz") {
      const std::string v = value();
      char* end = nullptr;
      options.live_scene_hz = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !(options.live_scene_hz >= 0) || options.live_scene_hz > 1e6) {
        std::fprintf(stderr, "error: --live-scene-hz must be a number >= 0, got '%s'\n", v.c_str());
        return 2;
      }
    } else if (a == "--logoutput")
      log_output = value();
    else if (a == "--logfilename")
      log_filename = value();
    else if (a == "--cloglevel" || a == "--floglevel" || a == "--logdir" || a == "-p" ||
             a == "--plugins") {
      std::fprintf(stderr, "warning: NRP-Core's option %s is accepted and ignored\n", a.c_str());
      value();
    } else if (a == "-h" || a == "--help") {
      usage(prog.c_str());
      return 0;
    } else {
      std::fprintf(stderr, "error: unknown option '%s'\n", a.c_str());
      usage(prog.c_str());
      return 2;
    }
  }
  if (!dir.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) {
      std::fprintf(stderr, "error: -d %s: not a directory\n", dir.c_str());
      return 2;
    }
    std::filesystem::current_path(dir, ec);
    if (ec) {
      std::fprintf(stderr, "error: -d %s: %s\n", dir.c_str(), ec.message().c_str());
      return 2;
    }
  }
  if (!log_output.empty() && !redirect_output(log_output, log_filename)) return 2;
  if (mode == "server") {
    options.server = true;
    if (options.server_address.empty()) {
      std::fprintf(stderr, "error: -m server needs --server_address HOST:PORT\n");
      return 2;
    }
  } else if (mode != "standalone") {
    std::fprintf(stderr, "error: -m must be standalone or server, got '%s'\n", mode.c_str());
    return 2;
  }
  if (!options.local_socket.empty() && !options.server) {
    std::fprintf(stderr, "error: --local_socket needs -m server\n");
    return 2;
  }
  if (!options.live.empty()) {
    if (options.server) {
      std::fprintf(stderr, "error: --live runs standalone only (not with -m server)\n");
      return 2;
    }
    try {  // the port itself is taken when the run starts (app/live_run.h)
      convoy::live::check_listen_policy(convoy::live::parse_listen_address(options.live),
                                        options.insecure);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
  }
  if (!scenario.empty()) {
    if (!options.config_file.empty()) {
      std::fprintf(stderr, "error: give -c or --scenario, not both\n");
      return 2;
    }
    if (options.server) {
      std::fprintf(stderr, "error: --scenario runs standalone only\n");
      return 2;
    }
    // the interpreter stays up for the run: its functions find the scenario already read
    scenario_python.emplace();
    if (!convoy::app::prepare_scenario({scenario, world, ego, scenery, scenario_params, perception},
                                       options))
      return 2;
  } else if (!world.empty() || !ego.empty() || !scenery.empty() || !scenario_params.empty() ||
             !perception.empty()) {
    std::fprintf(stderr,
                 "error: --world, --scenery, --ego, --scenario-param and --perception go with "
                 "--scenario\n");
    return 2;
  }
  if (options.config_file.empty()) {
    std::fprintf(stderr, "error: no config given (-c simulation_config.json)\n");
    return 2;
  }
  return options.server ? convoy::app::serve_simulation(options)
                        : convoy::app::run_simulation(options);
}
