// Process-wide "please stop" flag, set by the coordinator's SIGINT/SIGTERM handler and
// polled by blocking waits so that a Ctrl-C is honoured even while an engine hangs.
#pragma once

#include <atomic>

namespace convoy {

inline std::atomic<int>& interrupt_signal() {
  static std::atomic<int> sig{0};
  return sig;
}
inline bool interrupted() { return interrupt_signal().load(std::memory_order_relaxed) != 0; }

}  // namespace convoy
