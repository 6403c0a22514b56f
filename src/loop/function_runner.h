// What the loop needs from the transceiver and preprocessing functions: a description of each
// loaded function, where its inputs come from, and something that runs it.
//
// The loop knows functions only through this interface, so it can run without an
// interpreter (python::FunctionRuntime runs them in CPython; tests use a fake).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"

namespace convoy::loop {

struct FunctionInput {
  std::string keyword;
  std::string datapack;  // datapack name
  std::string engine;    // engine it is read from
  bool preprocessed = false;
};

// A loaded function as the loop sees it. The code itself stays with the runner that loaded
// it, under `runner_index`.
struct LoadedFunction {
  std::string name;  // the config's Name
  std::filesystem::path file;
  bool preprocessing = false;
  std::string engine;  // the engine it is linked to
  std::vector<FunctionInput> inputs;
  size_t runner_index = 0;    // the runner's own index of its code
  std::string label() const;  // "transceiver function 'tf_1' (/path/tf_1.py)"
};

// Where a function's inputs come from.
struct InputSource {
  // Returns the latest datapack read from an engine, or nullptr if none yet.
  std::function<const engine::DataPack*(const std::string& engine, const std::string& name)>
      engine_datapack;
  // Whether that datapack came in this loop cycle (NRP-Core's DataPack.isUpdated()); an
  // engine leaves out of its reply a datapack that has not changed (a camera between frames).
  std::function<bool(const std::string& engine, const std::string& name)> updated;
  // Reads the blobs of datapacks from `engine`; writes those of datapacks sent to it.
  std::function<const datapack::BlobReader*(const std::string& engine)> reader_for;
  std::function<datapack::BlobWriter*(const std::string& engine)> writer_for;
};

// Runs loaded functions. Throws FunctionError when a function fails.
class FunctionRunner {
 public:
  virtual ~FunctionRunner() = default;
  // Starts a loop cycle (inputs shared by reference are shared within one cycle only).
  virtual void begin_cycle() = 0;
  // Runs a preprocessing function; its datapacks stay with the runner for later functions.
  virtual void run_preprocessing(const LoadedFunction& fn, const InputSource& src) = 0;
  // Runs a transceiver function; appends the datapacks it returns to `outputs`.
  virtual void run_transceiver(const LoadedFunction& fn, const InputSource& src,
                               std::vector<engine::DataPack>* outputs) = 0;
};

}  // namespace convoy::loop
