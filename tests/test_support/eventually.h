// Waiting in tests for what another thread does: eventually(pred) polls `pred` every 10 ms
// for at most `limit` and returns its last answer.
#pragma once

#include <chrono>
#include <thread>

namespace convoy::test_support {

template <typename P>
bool eventually(P pred, std::chrono::milliseconds limit = std::chrono::milliseconds(5000)) {
  const auto step = std::chrono::milliseconds(10);
  for (auto waited = std::chrono::milliseconds(0); waited < limit; waited += step) {
    if (pred()) return true;
    std::this_thread::sleep_for(step);
  }
  return pred();
}

}  // namespace convoy::test_support
