// Transceiver, preprocessing and status functions: loading them from their files and running
// them.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "convoy/engine.pb.h"
#include "datapack/blobs.h"
#include "loop/function_runner.h"
#include "python/interpreter.h"

namespace convoy::python {

using loop::FunctionInput;
using loop::InputSource;
using loop::LoadedFunction;

// Runs functions in the embedded interpreter; keeps their Python callables.
class FunctionRuntime final : public loop::FunctionRunner {
 public:
  // by_reference: FunctionArgumentsPassingMethod "reference" (see run()).
  explicit FunctionRuntime(bool by_reference) : by_reference_(by_reference) {}

  // Executes the file and returns the transceiver and preprocessing functions it declares
  // (their runner_index points to this runtime's callables). Throws UserError.
  std::vector<LoadedFunction> load(const std::string& name, const std::filesystem::path& file);
  // Executes the file of the config's StatusFunction, which must declare one @StatusFunction
  // and nothing else. Throws UserError.
  LoadedFunction load_status(const std::string& name, const std::filesystem::path& file);

  // Starts a loop cycle: by-reference inputs are shared within one cycle only.
  void begin_cycle() override;
  // Runs a transceiver function; appends its datapacks to `outputs`. Throws FunctionError.
  void run_transceiver(const LoadedFunction& fn, const InputSource& src,
                       std::vector<engine::DataPack>* outputs) override;
  // Runs a preprocessing function; keeps its datapacks in the local cache.
  void run_preprocessing(const LoadedFunction& fn, const InputSource& src) override;
  // Runs the status function: (done, [RawData or datapacks]). Throws FunctionError.
  bool run_status(const LoadedFunction& fn, const InputSource& src,
                  std::vector<engine::DataPack>* observations) override;
  void reset() override;

 private:
  std::vector<LoadedFunction> execute(const std::string& name, const std::filesystem::path& file);
  py::object call(const LoadedFunction& fn, const InputSource& src);
  py::object input_object(const FunctionInput& in, const InputSource& src,
                          const LoadedFunction& fn);
  bool by_reference_;
  std::vector<py::object> callables_;         // by LoadedFunction::runner_index
  py::dict preprocessed_;                     // "engine\0name" -> latest datapack object from a PF
  py::dict shared_;                           // by-reference inputs of this cycle
  datapack::InlineBlobWriter inline_writer_;  // for datapacks to engines without a writer
};

}  // namespace convoy::python
