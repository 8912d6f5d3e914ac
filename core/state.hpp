#pragma once
// The dynamic state: time, positions and velocities. Terrains move as prescribed functions of
// time, so t is the whole of their state.
#include <jelly/core/types.hpp>

namespace jelly {

struct State {
  Real t = 0;
  VecX x;  // [3N] positions (m)
  VecX v;  // [3N] velocities (m/s)
};

}  // namespace jelly
