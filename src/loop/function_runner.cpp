#include "loop/function_runner.h"

#include <stdexcept>

namespace convoy::loop {

std::string LoadedFunction::label() const {
  const char* kind = status ? "status" : preprocessing ? "preprocessing" : "transceiver";
  return std::string(kind) + " function '" + name + "' (" + file.string() + ")";
}

bool FunctionRunner::run_status(const LoadedFunction& fn, const InputSource&,
                                std::vector<engine::DataPack>*) {
  throw std::logic_error("this function runner cannot run " + fn.label());
}

}  // namespace convoy::loop
