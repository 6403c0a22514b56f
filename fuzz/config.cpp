// Fuzzes the config loader (src/config): the input is a simulation config's text, then up to
// four `-o` overrides, separated by NUL bytes. A bad config must end in ConfigError; any other
// exception escapes and counts as a crash.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "config/simulation_config.h"
#include "fuzz_input.h"

namespace fs = std::filesystem;
using namespace convoy;

namespace {
fs::path config_file;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fs::path dir = fs::temp_directory_path() / ("convoy-fuzz-config-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::atexit([] {  // the folder goes when the fuzzer ends (libFuzzer exits through exit())
    std::error_code ec;
    fs::remove_all(config_file.parent_path(), ec);
  });
  config_file = dir / "simulation_config.json";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> parts = fuzz::split_nul({reinterpret_cast<const char*>(data), size}, 5);
  {
    std::ofstream out(config_file, std::ios::binary | std::ios::trunc);
    out << parts[0];
  }
  parts.erase(parts.begin());
  try {
    (void)config::load_simulation_config(config_file, parts, CONVOY_FUZZ_SHARE_DIR);
  } catch (const config::ConfigError&) {
  }
  for (const std::string& o : parts) {
    nlohmann::json doc = nlohmann::json::object();
    try {
      config::apply_override(doc, o);
    } catch (const config::ConfigError&) {
    }
  }
  return 0;
}
