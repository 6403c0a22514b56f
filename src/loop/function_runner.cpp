#include "loop/function_runner.h"

namespace convoy::loop {

std::string LoadedFunction::label() const {
  return std::string(preprocessing ? "preprocessing" : "transceiver") + " function '" + name +
         "' (" + file.string() + ")";
}

}  // namespace convoy::loop
