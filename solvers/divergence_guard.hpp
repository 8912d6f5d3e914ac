#pragma once
// The one definition of "diverged" shared by the Simulator and jelly-bench: a non-finite
// position or velocity, a particle faster than max_speed, one farther than max_distance from
// the origin, or (when max_energy is finite) a total energy above max_energy.
#include <limits>
#include <optional>
#include <string>

#include <jelly/core/model.hpp>
#include <jelly/core/state.hpp>

namespace jelly {

struct DivergenceGuard {
  Real max_speed = 500;     // m/s
  Real max_distance = 1e4;  // m
  // Cap on the total energy (kinetic + elastic + gravitational, J); infinite = not checked.
  // jelly-bench sets it to the initial energy plus the work terrains can do plus a tolerance
  // (docs/benchmarking.md); checking it costs one pass over the springs per step.
  Real max_energy = std::numeric_limits<Real>::infinity();

  void validate() const;
  // The reason the state counts as diverged, or nothing. Without the model the energy is not
  // checked. The particles are scanned on up to `threads` threads (the same answer for any
  // count: the first offending particle is named).
  std::optional<std::string> check(const State& state, int threads = 1) const;
  std::optional<std::string> check(const Model& model, const State& state, int threads = 1) const;
};

}  // namespace jelly
