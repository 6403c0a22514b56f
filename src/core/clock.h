// Wall-clock helpers (monotonic) and simulated-time conversions.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdint>

namespace convoy {

using SteadyClock = std::chrono::steady_clock;
using Deadline = SteadyClock::time_point;

inline Deadline deadline_after(double seconds) {
  if (seconds <= 0) return Deadline::max();
  return SteadyClock::now() + std::chrono::nanoseconds(std::llround(seconds * 1e9));
}

inline int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(SteadyClock::now().time_since_epoch())
      .count();
}

inline int64_t seconds_to_ns(double s) { return std::llround(s * 1e9); }

}  // namespace convoy
