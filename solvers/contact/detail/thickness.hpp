#pragma once
// The distance each particle keeps from terrains and obstacles: its body's thickness
// (Body::thickness; a cloth's contact radius by default, 0 for a body with volume). Every
// contact path (after the step, inside implicit_euler's solve, in the position-based
// projections, inside force evaluations, vbd's penalty) works with the offset surface: the
// particle's gap to it is the terrain's signed distance less the thickness, and a projection
// puts the particle's centre that far above the surface. A thickness of 0 leaves every result
// bit for bit as without it (d - 0 == d).
#include <algorithm>

#include <jelly/core/model.hpp>

namespace jelly::thickness {

// gap[i] = the thickness of particle i's body (0 for a particle outside every body). Resizes
// `gap` only when the number of particles changed.
inline void fill(const Model& model, VecX& gap) {
  if (gap.size() != model.num_particles()) gap.resize(model.num_particles());
  gap.setZero();
  for (const Body& b : model.bodies)
    gap.segment(b.first_particle, b.num_particles).setConstant(b.thickness);
}

// Calls f(first, last, thickness) for each body's share [first, last) of particles
// [begin, end), in particle order (particles outside every body are left out: no body, no
// contact offset, so they are visited with thickness 0).
template <class F>
void for_ranges(const Model& model, int begin, int end, F&& f) {
  int at = begin;
  for (const Body& b : model.bodies) {
    const int first = std::max(begin, b.first_particle);
    const int last = std::min(end, b.end_particle());
    if (first >= last) continue;
    if (at < first) f(at, first, Real(0));
    f(first, last, b.thickness);
    at = last;
  }
  if (at < end) f(at, end, Real(0));
}

}  // namespace jelly::thickness
