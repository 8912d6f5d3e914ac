#pragma once
// The one definition of "diverged" shared by the Simulator and jelly-bench: a non-finite
// position or velocity, a particle faster than max_speed, or one farther than max_distance from
// the origin.
#include <optional>
#include <string>

#include <jelly/core/state.hpp>

namespace jelly {

struct DivergenceGuard {
  Real max_speed = 500;     // m/s
  Real max_distance = 1e4;  // m

  void validate() const;
  // The reason the state counts as diverged, or nothing.
  std::optional<std::string> check(const State& state) const;
};

}  // namespace jelly
