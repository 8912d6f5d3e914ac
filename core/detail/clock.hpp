#pragma once
// Internal: the wall clock of the solvers' timing statistics.
#include <chrono>

namespace jelly {

using Clock = std::chrono::steady_clock;

// Seconds from `start` to now.
inline double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace jelly
