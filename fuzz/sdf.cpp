// Fuzzes the world engine's SDF loading (engines/gazebo_grpc/world_description.cpp
// `load_world`) through libsdformat, which reads files: the input is written to a temporary
// world file. `model://` URIs resolve to tests/world/data/models.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sdf/Console.hh>
#include <stdexcept>

#include "world_description.h"

namespace fs = std::filesystem;

namespace {
fs::path world_file;
}

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  sdf::Console::Instance()->SetQuiet(true);  // one message per bad input otherwise
  setenv("CONVOY_MODEL_PATH", CONVOY_FUZZ_MODEL_PATH, 1);
  fs::path dir = fs::temp_directory_path() / ("convoy-fuzz-sdf-" + std::to_string(getpid()));
  fs::create_directories(dir);
  std::atexit([] {  // the folder goes when the fuzzer ends (libFuzzer exits through exit())
    std::error_code ec;
    fs::remove_all(world_file.parent_path(), ec);
  });
  world_file = dir / "world.sdf";
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  {
    std::ofstream out(world_file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    (void)convoy::world::load_world(world_file);
  } catch (const std::runtime_error&) {
  }
  return 0;
}
