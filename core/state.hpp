#pragma once
// The dynamic state: time, positions and velocities. Terrains move as prescribed functions of
// time, so t is the whole of their state.
#include <jelly/core/types.hpp>

namespace jelly {

// The dynamic state: time, positions and velocities of every particle.
struct State {
  Real t = 0;  // time (s)
  VecX x;      // [3N] positions (m)
  VecX v;      // [3N] velocities (m/s)
};

}  // namespace jelly
