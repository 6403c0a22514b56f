// Transceiver and preprocessing functions: loading them from their files and running them.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"
#include "python/interpreter.h"

namespace convoy::python {

struct FunctionInput {
  std::string keyword;
  std::string datapack;  // datapack name
  std::string engine;    // engine it is read from
  bool preprocessed = false;
};

struct LoadedFunction {
  std::string name;  // the config's Name
  std::filesystem::path file;
  bool preprocessing = false;
  std::string engine;  // the engine it is linked to
  std::vector<FunctionInput> inputs;
  py::object callable;
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

class FunctionRuntime {
 public:
  // by_reference: FunctionArgumentsPassingMethod "reference" (see run()).
  explicit FunctionRuntime(bool by_reference) : by_reference_(by_reference) {}

  // Executes the file and returns the functions it declares. Throws UserError.
  std::vector<LoadedFunction> load(const std::string& name, const std::filesystem::path& file);

  // Starts a loop cycle: by-reference inputs are shared within one cycle only.
  void begin_cycle();
  // Runs a transceiver function; appends its datapacks to `outputs`. Throws FunctionError.
  void run_transceiver(const LoadedFunction& fn, const InputSource& src,
                       std::vector<engine::DataPack>* outputs);
  // Runs a preprocessing function; keeps its datapacks in the local cache.
  void run_preprocessing(const LoadedFunction& fn, const InputSource& src);

 private:
  py::object call(const LoadedFunction& fn, const InputSource& src);
  py::object input_object(const FunctionInput& in, const InputSource& src,
                          const LoadedFunction& fn);
  bool by_reference_;
  py::dict preprocessed_;                     // "engine\0name" -> latest datapack object from a PF
  py::dict shared_;                           // by-reference inputs of this cycle
  datapack::InlineBlobWriter inline_writer_;  // for datapacks to engines without a writer
};

}  // namespace convoy::python
