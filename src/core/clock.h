// Wall-clock helpers (monotonic) and simulated-time conversions.
#pragma once

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

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

// When this process started, on now_ns()'s clock: the kernel's record of the exec (field 22
// of /proc/self/stat, in clock ticks since boot: 10 ms resolution), so that start-up figures
// include loading the program and its libraries. -1 if unknown.
inline int64_t process_start_ns() {
  static const int64_t start = [] {
    std::FILE* f = std::fopen("/proc/self/stat", "r");
    if (!f) return int64_t{-1};
    char buf[1024];
    size_t n = std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    buf[n] = 0;
    const char* p = std::strrchr(buf, ')');  // the command name may hold spaces
    if (!p) return int64_t{-1};
    unsigned long long ticks = 0;
    // after ") ": state(3) ... starttime(22)
    if (std::sscanf(p + 2,
                    "%*c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %*u %*u %*d %*d %*d %*d %*d "
                    "%*d %llu",
                    &ticks) != 1)
      return int64_t{-1};
    const long hz = sysconf(_SC_CLK_TCK);
    timespec boot{};
    if (hz <= 0 || clock_gettime(CLOCK_BOOTTIME, &boot) != 0) return int64_t{-1};
    const int64_t boot_now = int64_t{boot.tv_sec} * 1'000'000'000 + boot.tv_nsec;
    const int64_t mono_now = now_ns();  // the steady clock is CLOCK_MONOTONIC: no suspend
    const int64_t start_boot = static_cast<int64_t>(ticks) * (1'000'000'000 / hz);
    return mono_now - (boot_now - start_boot);
  }();
  return start;
}

}  // namespace convoy
