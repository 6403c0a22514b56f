// Error types shared by the components. Messages carry the offending value and where it
// came from; the coordinator's main turns them into one message and an exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace convoy {

// A problem with the user's input: config, files, scripts. Exit code 2.
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// An engine failed: it raised, crashed, hung or broke the protocol. Exit code 3.
class EngineError : public std::runtime_error {
 public:
  EngineError(std::string engine, const std::string& message)
      : std::runtime_error(message), engine_(std::move(engine)) {}
  const std::string& engine() const { return engine_; }

 private:
  std::string engine_;
};

// A transceiver or preprocessing function raised or returned something unusable. Exit code 4.
class FunctionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace convoy
