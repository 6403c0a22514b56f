// The pool's draws: a 64-bit mix of a state (splitmix64) and a shuffle by a seed, so spawning
// and every road user's choices depend only on the seeds given.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace convoy::traffic_pool {

inline uint64_t mix(uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A uniform draw in [lo, hi) from `state`, advancing it.
inline double uniform(uint64_t& state, double lo, double hi) {
  state = mix(state);
  return lo + (hi - lo) * static_cast<double>(state >> 11) * 0x1.0p-53;
}

// Fisher-Yates by `seed`.
template <class T>
void shuffle_by_seed(std::vector<T>& items, uint64_t seed) {
  uint64_t state = seed;
  for (size_t k = items.size(); k > 1; --k) {
    state = mix(state);
    std::swap(items[k - 1], items[state % k]);
  }
}

}  // namespace convoy::traffic_pool
