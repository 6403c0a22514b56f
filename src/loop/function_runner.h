// What the loop needs from the transceiver, preprocessing and status functions: a description
// of each loaded function, where its inputs come from, and something that runs it.
//
// The loop knows functions only through this interface, so it can run without an
// interpreter (python::FunctionRuntime runs them in CPython; tests use a fake).
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"

namespace convoy::loop {

// What an input argument of a function carries.
enum class InputKind {
  kDataPack,   // @EngineDataPack / @PreprocessedDataPack
  kIteration,  // @SimulationIteration: the loop cycle's number, from 0
  kTime,       // @SimulationTime: the simulated time of the cycle, in ns
};

struct FunctionInput {
  std::string keyword;
  std::string datapack;  // datapack name (kDataPack)
  std::string engine;    // engine it is read from (kDataPack)
  bool preprocessed = false;
  InputKind kind = InputKind::kDataPack;
};

// A loaded function as the loop sees it. The code itself stays with the runner that loaded
// it, under `runner_index`.
struct LoadedFunction {
  std::string name;  // the config's Name
  std::filesystem::path file;
  bool preprocessing = false;
  bool status = false;  // the status function (NRP-Core's @StatusFunction): no engine
  std::string engine;   // the engine it is linked to ("" for the status function)
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
  // The loop cycle being run (@SimulationIteration, from 0) and its simulated time
  // (@SimulationTime).
  uint64_t iteration = 0;
  int64_t time_ns = 0;
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
  // Runs the status function: returns its done flag and appends the data it returns
  // (datapacks whose id may be empty) to `observations`.
  virtual bool run_status(const LoadedFunction& fn, const InputSource& src,
                          std::vector<engine::DataPack>* observations);
  // The computational graph (DataPackProcessor "cg"), run instead of the functions when the
  // loop has one (FtiLoop::set_graph): one step after the engines `due_engines` (config order)
  // finished theirs; appends the datapacks its ToEngine nodes send them to `outputs`.
  virtual void run_graph(const std::vector<std::string>& /*due_engines*/,
                         const InputSource& /*src*/, std::vector<engine::DataPack>* /*outputs*/) {}
  // Forgets what the functions kept between cycles (preprocessed datapacks): the simulation
  // was reset.
  virtual void reset() {}
};

}  // namespace convoy::loop
